"""``timeline.png`` and ``timeline.svg``: what each robot did over time, with faults marked, drawn with matplotlib
from the recorded trial.

A robot whose controller returned a motivation trace (``Command.trace``: ALLIANCE, L-ALLIANCE) gets one row per
behaviour set, in the style of the action-selection figures of Parker's thesis (Figs 3-9, 3-10, 3-13): a bar
where the set is active, and over it the set's motivation m(t) with the threshold theta dashed, impatience resets
(triangles), changes of impatience rate (ticks) and acquiescence (crosses, labelled psi or lambda) marked. Any
other robot (wander, scripted) gets a single row coloured by its active behaviour (dead and absent in greys);
over a robot's behaviour-set rows, periods where it is dead or not yet in the arena are shaded.
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from teamsim.plots import pyplot, save_figure
from teamsim.recording import MotivationSeries

# Distinct colours for behaviours, in order of first appearance; idle, dead and absent are fixed greys.
_PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf",
            "#7f7f7f"]
_FIXED = {"idle": "#e1e1e1", "absent": "#f5f5f5", "dead": "#3c3c3c"}
_RED, _GREY, _RESET, _RATE = "#ff0000", "#969696", "#7828a0", "#e68c00"  # faults, theta, impatience reset, rate
GAP = 0.3  # between robots, in rows
ROW_INCHES = 0.36
WIDTH = 11.5  # in
MARGIN = 0.08  # of a row, above and below its bar
THETA_HEIGHT = 0.6  # theta is drawn at this fraction of a set row's height; higher motivations are clipped


def behaviour_colours(names) -> dict[str, str]:
    """A colour per name (behaviour or behaviour set), in order of first appearance."""
    colours, k = {}, 0
    for name in dict.fromkeys(names):
        if name in _FIXED:
            colours[name] = _FIXED[name]
        else:
            colours[name] = _PALETTE[k % len(_PALETTE)]
            k += 1
    return colours


def _runs(values: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index ranges over which ``values`` is constant."""
    changes = np.flatnonzero(values[1:] != values[:-1]) + 1
    return list(zip(np.r_[0, changes].tolist(), np.r_[changes, len(values)].tolist()))


def draw_timeline(times: np.ndarray, behaviours: np.ndarray, robot_names: list[str], faults: list[dict],
                  motivation: Mapping[str, MotivationSeries] | None = None):
    """A matplotlib figure: per robot one row coloured by behaviour, or (with a motivation series) one row per
    behaviour set with active bars, m(t), theta and the events; faults as labelled red lines. Rows run down from
    y = 0, one unit each; time is x, in seconds."""
    motivation = motivation or {}
    names = behaviours.T.ravel().tolist() if behaviours.size else []
    colours = behaviour_colours(names + [s for series in motivation.values() for s in series.sets])
    heights = [len(motivation[r].sets) if r in motivation else 1 for r in robot_names]
    tops = np.cumsum([0.0] + [h + GAP for h in heights[:-1]])
    bottom = float(tops[-1] + heights[-1]) if robot_names else 1.0
    end = float(times[-1]) if len(times) > 1 else 1.0

    plt = pyplot()
    longest = max((_width(name, 8) for name in colours), default=0.0)
    columns = int(max(1, min(8, (WIDTH - 1) * 72 // (longest + 40))))  # colour keys a row: as many as fit, up to 8
    key_rows = max(-(-len(colours) // columns) + bool(motivation), 1)
    fig, (axes, key) = plt.subplots(2, 1, figsize=(WIDTH, 1.1 + ROW_INCHES * bottom + 0.22 * key_rows),
                                    height_ratios=[ROW_INCHES * bottom + 0.5, 0.22 * key_rows], layout="constrained")
    title = "active behaviour"
    if motivation:
        title += "; behaviour sets: active (bars), motivation m(t) (curves), threshold theta (dashed)"
    axes.set_title(title, loc="left", fontsize=10)
    set_ticks, set_labels = [], []
    for row, (name, top, height) in enumerate(zip(robot_names, tops, heights)):
        if name in motivation:
            _draw_sets(axes, name, motivation[name], top, end, colours)
            _shade_absence(axes, times, behaviours[:, row], top, height, end)
            set_ticks += [top + k + 0.5 for k in range(height)]
            set_labels += motivation[name].sets
        else:
            column = behaviours[:, row]
            for start, stop in _runs(column):
                t1 = times[stop] if stop < len(times) else end
                axes.broken_barh([(times[start], t1 - times[start])], (top + MARGIN, 1 - 2 * MARGIN),
                                 color=colours[column[start]], gid=f"behaviour/{name}")
    for fault in faults:
        if fault["robot"] in robot_names and fault["time"] <= end:
            k = robot_names.index(fault["robot"])
            axes.vlines(fault["time"], tops[k], tops[k] + heights[k], color=_RED, lw=2, gid="fault")
            axes.text(fault["time"], tops[k] + 0.05, f" {fault['kind']}", color=_RED, fontsize=7, va="top")
    axes.set(xlim=(0, end), ylim=(bottom, 0), xlabel="time (s)")
    axes.set_yticks(set_ticks, set_labels, fontsize=8)
    robots = axes.secondary_yaxis("left")
    robots.set_yticks(tops + np.array(heights) / 2, robot_names, fontsize=10)
    robots.tick_params(length=0, pad=4 + max([_width(label, 8) for label in set_labels], default=0))
    for spine in (*axes.spines.values(), robots.spines["left"]):
        spine.set_visible(spine is axes.spines["bottom"])
    axes.tick_params(axis="y", length=0)
    _legend(key, colours, bool(motivation), columns)
    return fig


def _draw_sets(axes, robot: str, series: MotivationSeries, top: float, end: float, colours: dict) -> None:
    """One robot's behaviour-set rows: active bars, theta, m(t) and the events."""
    times, levels, active = series.columns()
    span = 1 - 2 * MARGIN

    def y_of(row: int, m):
        return top + row + 1 - MARGIN - np.minimum(np.asarray(m) * THETA_HEIGHT * span / series.threshold, span)

    # The trace pauses while the controller does not run (a dead or removed robot).
    step = float(np.median(np.diff(times))) if len(times) > 1 else end
    breaks = np.flatnonzero(np.diff(times) > 1.5 * step) + 1
    periods = list(_periods(times, active, breaks, step))
    for k, name in enumerate(series.sets):
        y = top + k
        axes.hlines(y + 1 - MARGIN, 0, end, color="#d2d2d2", lw=0.8)
        axes.broken_barh([(t0, t1 - t0) for value, t0, t1 in periods if value == k], (y + MARGIN, span),
                         color=colours[name], alpha=0.4, lw=0, gid=f"active/{robot}/{name}")
        axes.hlines(y_of(k, series.threshold), 0, end, color=_GREY, lw=0.8, linestyles=(0, (4, 4)))
        if len(times):
            axes.plot(np.insert(times, breaks, np.nan), np.insert(y_of(k, levels[:, k]), breaks, np.nan),
                      color=colours[name], lw=1, gid=f"motivation/{robot}/{name}")
    for kind, marker, colour, where in (("impatience_reset", "v", _RESET, MARGIN + 0.12),
                                        ("impatience", "|", _RATE, 1 - MARGIN - 0.1),
                                        ("acquiescence", "x", _RED, 0.35)):
        chosen = [(time, k, detail) for time, k, event, detail in series.events if event == kind]
        if chosen:
            axes.plot([t for t, _, _ in chosen], [top + k + where for _, k, _ in chosen], ls="none", marker=marker,
                      color=colour, ms=6, mew=2 if marker != "v" else 1, gid=f"{kind}/{robot}")
        if kind == "acquiescence":
            for time, k, detail in chosen:
                axes.text(time, top + k + where, "  psi" if detail == "psi" else "  lambda", color=_RED, fontsize=7,
                          va="center")


def _periods(times: np.ndarray, values: np.ndarray, breaks: np.ndarray, step: float):
    """(value, start, end) of each run of constant ``values``, split where the trace pauses (at ``breaks``): the
    last tick before a pause, or the end, lasts one control period ``step``."""
    for first, stop in zip(np.r_[0, breaks].tolist(), np.r_[breaks, len(times)].tolist()):
        for a, b in _runs(values[first:stop]):
            yield values[first + a], times[first + a], times[first + b] if first + b < stop else times[stop - 1] + step


def _shade_absence(axes, times: np.ndarray, column: np.ndarray, top: float, height: int, end: float) -> None:
    """Shade the robot's rows where it is dead or not in the arena (its controller does not run)."""
    for start, stop in _runs(column):
        state = column[start]
        if state in ("dead", "absent"):
            t1 = times[stop] if stop < len(times) else end
            axes.broken_barh([(times[start], t1 - times[start])], (top, height), color=_FIXED[state], alpha=0.45,
                             lw=0, gid=state)
            axes.text(times[start], top + height - 0.1, f" {state}", fontsize=7,
                      color="white" if state == "dead" else "black")


def _legend(key, colours: dict, motivation: bool, columns: int) -> None:
    """Under the plot: a colour key per behaviour (or set), and with motivation a row of the event markers."""
    from matplotlib.lines import Line2D  # noqa: PLC0415
    from matplotlib.patches import Patch  # noqa: PLC0415

    key.axis("off")
    swatches = [Patch(facecolor=colour, edgecolor="black", lw=0.6, label=name) for name, colour in colours.items()]
    shown = key.legend(handles=swatches, loc="upper left", ncol=columns, fontsize=8, frameon=False,
                       borderaxespad=0, handlelength=1.2)
    if motivation:
        key.add_artist(shown)
        markers = [Line2D([], [], ls="none", marker=marker, mew=width, color=colour, label=label)
                   for marker, width, colour, label in (("v", 1, _RESET, "impatience reset (teammate first heard)"),
                                                        ("|", 2, _RATE, "impatience rate changes (slow/fast)"),
                                                        ("x", 2, _RED, "acquiescence (psi or lambda)"))]
        key.legend(handles=markers, loc="lower left", ncol=3, fontsize=8, frameon=False, borderaxespad=0)


def _width(text: str, size: float) -> float:
    """The width of ``text`` in points at font size ``size``."""
    from matplotlib.textpath import TextPath  # noqa: PLC0415

    return TextPath((0, 0), text, size=size).get_extents().width


def write_timeline(path: Path, times, behaviours, robot_names, faults,
                   motivation: Mapping[str, MotivationSeries] | None = None) -> None:
    """The timeline as ``path`` (PNG) and beside it the same stem ``.svg``."""
    save_figure(draw_timeline(np.asarray(times), np.asarray(behaviours), robot_names, faults, motivation), Path(path))

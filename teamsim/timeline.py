"""``timeline.png``: what each robot did over time, with faults marked, drawn with OpenCV from the recorded trial.

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

import cv2
import numpy as np

from teamsim.files import write_atomic
from teamsim.recording import MotivationSeries

_FONT = cv2.FONT_HERSHEY_SIMPLEX
# Distinct colours (BGR) for behaviours, in order of first appearance; idle, dead and absent are fixed greys.
_PALETTE = [(180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214), (189, 103, 148), (75, 86, 140),
            (194, 119, 227), (34, 189, 188), (207, 190, 23), (127, 127, 127)]
_FIXED = {"idle": (225, 225, 225), "absent": (245, 245, 245), "dead": (60, 60, 60)}
_BLACK, _RED, _GREY = (0, 0, 0), (0, 0, 255), (150, 150, 150)
_RESET, _RATE = (160, 40, 120), (0, 140, 230)  # impatience reset, impatience rate change
ROW, SET_ROW, TOP, WIDTH, GAP = 34, 36, 40, 1000, 8
THETA_HEIGHT = 0.6  # theta is drawn at this fraction of a set row's height; higher motivations are clipped


def behaviour_colours(names) -> dict[str, tuple[int, int, int]]:
    """A colour per name (behaviour or behaviour set), in order of first appearance."""
    colours, k = {}, 0
    for name in dict.fromkeys(names):
        if name in _FIXED:
            colours[name] = _FIXED[name]
        else:
            colours[name] = _PALETTE[k % len(_PALETTE)]
            k += 1
    return colours


def _text(image, text: str, x: int, y: int, scale: float = 0.45, colour=_BLACK) -> None:
    cv2.putText(image, text, (x, y), _FONT, scale, colour, 1, cv2.LINE_AA)


def _text_width(text: str, scale: float) -> int:
    return cv2.getTextSize(text, _FONT, scale, 1)[0][0]


def _runs(values: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index ranges over which ``values`` is constant."""
    changes = np.flatnonzero(values[1:] != values[:-1]) + 1
    return list(zip(np.r_[0, changes].tolist(), np.r_[changes, len(values)].tolist()))


def _lighter(colour, amount: float = 0.6) -> tuple[int, int, int]:
    return tuple(int(round(c + (255 - c) * amount)) for c in colour)


def draw_timeline(times: np.ndarray, behaviours: np.ndarray, robot_names: list[str], faults: list[dict],
                  motivation: Mapping[str, MotivationSeries] | None = None) -> np.ndarray:
    """A BGR image: per robot one row coloured by behaviour, or (with a motivation series) one row per behaviour
    set with active bars, m(t), theta and the events; faults as labelled red lines."""
    motivation = motivation or {}
    names = behaviours.T.ravel().tolist() if behaviours.size else []
    colours = behaviour_colours(names + [s for series in motivation.values() for s in series.sets])
    robot_col = max([_text_width(n, 0.5) for n in robot_names] + [40]) + 16
    set_labels = [s for r in robot_names if r in motivation for s in motivation[r].sets]
    left = robot_col + (max(_text_width(s, 0.4) for s in set_labels) + 12 if set_labels else 0)
    rows = [(ROW if r not in motivation else SET_ROW * len(motivation[r].sets)) for r in robot_names]
    tops = TOP + np.cumsum([0] + [h + GAP for h in rows[:-1]]).astype(int)
    axis_y = int(tops[-1] + rows[-1] + 4) if robot_names else TOP
    legend = _legend_layout(list(colours), WIDTH)
    legend_rows = (legend[-1][1] + 1 if legend else 0) + (1 if motivation else 0)
    image = np.full((axis_y + 40 + 22 * legend_rows, left + WIDTH + 20, 3), 255, np.uint8)
    end = float(times[-1]) if len(times) > 1 else 1.0

    def x_of(t: float) -> int:
        return left + int(round(WIDTH * min(t, end) / end))

    title = "active behaviour"
    if motivation:
        title += "; behaviour sets: active (bars), motivation m(t) (curves), threshold theta (dashed)"
    _text(image, title, left, 24, 0.5)
    for row, (name, top, height) in enumerate(zip(robot_names, tops, rows)):
        _text(image, name, 8, int(top) + min(height, ROW) // 2 + 5, 0.5)
        if name in motivation:
            _draw_sets(image, motivation[name], int(top), left, end, x_of, colours)
            _shade_absence(image, times, behaviours[:, row], int(top), height, end, x_of)
        else:
            column = behaviours[:, row]
            for start, stop in _runs(column):
                t1 = times[stop] if stop < len(times) else end
                cv2.rectangle(image, (x_of(times[start]), int(top) + 4), (x_of(t1), int(top) + height - 4),
                              colours[column[start]], -1)
    cv2.line(image, (left, axis_y), (left + WIDTH, axis_y), _BLACK, 1)
    step = _nice_step(end)
    for t in np.arange(0.0, end + 1e-9, step):
        cv2.line(image, (x_of(t), axis_y), (x_of(t), axis_y + 5), _BLACK, 1)
        _text(image, f"{t:g}", x_of(t) - 8, axis_y + 18, 0.4)
    _text(image, "s", left + WIDTH + 12, axis_y + 18, 0.4)
    for fault in faults:
        if fault["robot"] in robot_names and fault["time"] <= end:
            k = robot_names.index(fault["robot"])
            x, y = x_of(fault["time"]), int(tops[k])
            cv2.line(image, (x, y), (x, y + rows[k]), _RED, 2)
            _text(image, fault["kind"], x + 3, y + 12, 0.35, _RED)
    for (name, colour), (offset, line) in zip(colours.items(), legend):
        x, y = left + offset, axis_y + 32 + 22 * line
        cv2.rectangle(image, (x, y - 10), (x + 14, y + 2), colour, -1)
        cv2.rectangle(image, (x, y - 10), (x + 14, y + 2), _BLACK, 1)
        _text(image, name, x + 20, y)
    if motivation:
        _marker_legend(image, left, axis_y + 32 + 22 * (legend_rows - 1))
    return image


def _draw_sets(image: np.ndarray, series: MotivationSeries, top: int, left: int, end: float, x_of,
               colours: dict) -> None:
    """One robot's behaviour-set rows: label, active bars, theta, m(t) and the events."""
    times = np.frombuffer(series.times, dtype=float)
    levels = series.level_array()
    active = np.frombuffer(series.active, dtype=np.int32)
    scale = THETA_HEIGHT * (SET_ROW - 6) / series.threshold

    def y_of(row: int, m) -> np.ndarray:
        bottom = top + row * SET_ROW + SET_ROW - 3
        return np.round(bottom - np.minimum(m * scale, SET_ROW - 6)).astype(np.int32)

    xs = np.array([x_of(t) for t in times], dtype=np.int32)
    # The trace stops when the controller does (a dead robot): the last step lasts one control period.
    last = times[-1] + (times[-1] - times[-2]) if len(times) > 1 else end
    for k, name in enumerate(series.sets):
        y = top + k * SET_ROW
        _text(image, name, left - 6 - _text_width(name, 0.4), y + SET_ROW // 2 + 4, 0.4)
        cv2.line(image, (left, y + SET_ROW - 3), (x_of(end), y + SET_ROW - 3), (210, 210, 210), 1)
        light = _lighter(colours[name])
        for start, stop in _runs(active):
            if active[start] == k:
                t1 = times[stop] if stop < len(times) else last
                cv2.rectangle(image, (xs[start], y + 3), (x_of(t1), y + SET_ROW - 3), light, -1)
        theta_y = int(y_of(k, series.threshold))
        for x in range(left, x_of(end), 8):
            cv2.line(image, (x, theta_y), (min(x + 4, x_of(end)), theta_y), _GREY, 1)
        if len(times):
            curve = np.stack([xs, y_of(k, levels[:, k])], axis=1)
            cv2.polylines(image, [curve], False, colours[name], 1, cv2.LINE_AA)
    for time, k, kind, detail in series.events:
        x, y = x_of(time), top + k * SET_ROW
        if kind == "impatience_reset":
            cv2.fillPoly(image, [np.array([(x - 4, y + 3), (x + 4, y + 3), (x, y + 9)], np.int32)], _RESET)
        elif kind == "impatience":
            cv2.line(image, (x, y + SET_ROW - 8), (x, y + SET_ROW - 1), _RATE, 2)
        elif kind == "acquiescence":
            cv2.line(image, (x - 4, y + 5), (x + 4, y + 13), _RED, 2)
            cv2.line(image, (x - 4, y + 13), (x + 4, y + 5), _RED, 2)
            _text(image, "psi" if detail == "psi" else "lambda", x + 6, y + 13, 0.35, _RED)


def _shade_absence(image: np.ndarray, times: np.ndarray, column: np.ndarray, top: int, height: int, end: float,
                   x_of) -> None:
    """Hatch the robot's rows where it is dead or not in the arena (its controller does not run)."""
    for start, stop in _runs(column):
        if column[start] in ("dead", "absent"):
            x0, x1 = x_of(times[start]), x_of(times[stop] if stop < len(times) else end)
            overlay = image[top:top + height, x0:x1]
            overlay[:] = (overlay * 0.55 + np.array(_FIXED[column[start]]) * 0.45).astype(np.uint8)
            _text(image, str(column[start]), x0 + 3, top + height - 5, 0.35, (255, 255, 255) if
                  column[start] == "dead" else _BLACK)


def _legend_layout(names: list[str], width: int) -> list[tuple[int, int]]:
    """(x offset, line) of each colour key: entries on a 165 px grid, wider ones taking more cells, wrapping at
    ``width``."""
    places, x, line = [], 0, 0
    for name in names:
        cells = 165 * -(-(_text_width(name, 0.45) + 30) // 165)
        if x and x + cells > width:
            x, line = 0, line + 1
        places.append((x, line))
        x += cells
    return places


def _marker_legend(image: np.ndarray, x: int, y: int) -> None:
    cv2.fillPoly(image, [np.array([(x, y - 9), (x + 8, y - 9), (x + 4, y - 3)], np.int32)], _RESET)
    _text(image, "impatience reset (teammate first heard)", x + 14, y)
    x += 300
    cv2.line(image, (x + 4, y - 10), (x + 4, y + 2), _RATE, 2)
    _text(image, "impatience rate changes (slow/fast)", x + 14, y)
    x += 270
    cv2.line(image, (x, y - 9), (x + 8, y - 1), _RED, 2)
    cv2.line(image, (x, y - 1), (x + 8, y - 9), _RED, 2)
    _text(image, "acquiescence (psi or lambda)", x + 14, y)


def _nice_step(span: float) -> float:
    raw = span / 10
    magnitude = 10 ** np.floor(np.log10(raw)) if raw > 0 else 1.0
    return float(min((m * magnitude for m in (1, 2, 5, 10) if m * magnitude >= raw), default=magnitude))


def write_timeline(path: Path, times, behaviours, robot_names, faults,
                   motivation: Mapping[str, MotivationSeries] | None = None) -> None:
    image = draw_timeline(np.asarray(times), np.asarray(behaviours), robot_names, faults, motivation)
    ok, png = cv2.imencode(".png", image)
    if ok:
        write_atomic(path, png.tobytes())

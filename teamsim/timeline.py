"""``timeline.png``: each robot's active behaviour over time, with faults marked, in the style of the
behaviour traces in Parker's thesis (e.g. Fig. 3-11). Drawn with OpenCV from the recorded trajectory.
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from teamsim.recording import write_atomic

_FONT = cv2.FONT_HERSHEY_SIMPLEX
# Distinct colours (BGR) for behaviours, in order of first appearance; idle, dead and absent are fixed greys.
_PALETTE = [(180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214), (189, 103, 148), (75, 86, 140),
            (194, 119, 227), (34, 189, 188), (207, 190, 23), (127, 127, 127)]
_FIXED = {"idle": (225, 225, 225), "absent": (245, 245, 245), "dead": (60, 60, 60)}
LEFT, ROW, TOP, WIDTH = 110, 34, 40, 1000


def behaviour_colours(behaviours: np.ndarray) -> dict[str, tuple[int, int, int]]:
    colours, k = {}, 0
    for name in dict.fromkeys(behaviours.T.ravel().tolist()):
        if name in _FIXED:
            colours[name] = _FIXED[name]
        else:
            colours[name] = _PALETTE[k % len(_PALETTE)]
            k += 1
    return colours


def draw_timeline(times: np.ndarray, behaviours: np.ndarray, robot_names: list[str],
                  faults: list[dict]) -> np.ndarray:
    """A BGR image: one row per robot, coloured by behaviour; faults as labelled ticks."""
    colours = behaviour_colours(behaviours) if behaviours.size else {}
    legend_rows = (len(colours) + 5) // 6
    height = TOP + ROW * len(robot_names) + 40 + 22 * legend_rows
    image = np.full((height, LEFT + WIDTH + 20, 3), 255, np.uint8)
    end = float(times[-1]) if len(times) > 1 else 1.0

    def x_of(t: float) -> int:
        return LEFT + int(round(WIDTH * t / end))

    cv2.putText(image, "active behaviour", (LEFT, 24), _FONT, 0.55, (0, 0, 0), 1, cv2.LINE_AA)
    for row, name in enumerate(robot_names):
        y = TOP + row * ROW
        cv2.putText(image, name, (8, y + ROW // 2 + 5), _FONT, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
        column = behaviours[:, row]
        changes = np.flatnonzero(column[1:] != column[:-1]) + 1
        for start, stop in zip(np.r_[0, changes], np.r_[changes, len(column)]):
            t1 = times[stop] if stop < len(times) else end
            cv2.rectangle(image, (x_of(times[start]), y + 4), (x_of(t1), y + ROW - 4), colours[column[start]], -1)
    axis_y = TOP + ROW * len(robot_names) + 4
    cv2.line(image, (LEFT, axis_y), (LEFT + WIDTH, axis_y), (0, 0, 0), 1)
    step = _nice_step(end)
    for t in np.arange(0.0, end + 1e-9, step):
        cv2.line(image, (x_of(t), axis_y), (x_of(t), axis_y + 5), (0, 0, 0), 1)
        cv2.putText(image, f"{t:g}", (x_of(t) - 8, axis_y + 18), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(image, "s", (LEFT + WIDTH + 6, axis_y + 18), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    for fault in faults:
        if fault["robot"] in robot_names and fault["time"] <= end:
            y = TOP + robot_names.index(fault["robot"]) * ROW
            x = x_of(fault["time"])
            cv2.line(image, (x, y), (x, y + ROW), (0, 0, 255), 2)
            cv2.putText(image, fault["kind"], (x + 3, y + 12), _FONT, 0.35, (0, 0, 255), 1, cv2.LINE_AA)
    for k, (name, colour) in enumerate(colours.items()):
        x, y = LEFT + (k % 6) * 165, axis_y + 32 + 22 * (k // 6)
        cv2.rectangle(image, (x, y - 10), (x + 14, y + 2), colour, -1)
        cv2.rectangle(image, (x, y - 10), (x + 14, y + 2), (0, 0, 0), 1)
        cv2.putText(image, name, (x + 20, y), _FONT, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    return image


def _nice_step(span: float) -> float:
    raw = span / 10
    magnitude = 10 ** np.floor(np.log10(raw)) if raw > 0 else 1.0
    return float(min((m * magnitude for m in (1, 2, 5, 10) if m * magnitude >= raw), default=magnitude))


def write_timeline(path: Path, times, behaviours, robot_names, faults) -> None:
    ok, png = cv2.imencode(".png", draw_timeline(np.asarray(times), np.asarray(behaviours), robot_names, faults))
    if ok:
        write_atomic(path, png.tobytes())

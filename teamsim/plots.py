"""Plots for reports, drawn with OpenCV (no plotting library to install): grouped bar charts and line charts."""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from teamsim.files import write_atomic

_FONT = cv2.FONT_HERSHEY_SIMPLEX
_COLOURS = [(180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214), (189, 103, 148), (75, 86, 140),
            (194, 119, 227), (127, 127, 127)]


def grouped_bars(path: Path, title: str, groups: list[str], series: dict[str, list[float]], y_label: str,
                 y_max: float | None = None, width: int = 1100, height: int = 420) -> None:
    """One cluster of bars per group, one bar per series (NaN bars are left out), with a legend."""
    image, y_of = _canvas(title, y_label, _top(series, y_max), width, height)
    plot_w = width - LEFT - RIGHT
    cluster = plot_w / max(len(groups), 1)
    bar = cluster * 0.8 / max(len(series), 1)
    for g, group in enumerate(groups):
        x0 = LEFT + g * cluster + cluster * 0.1
        for s, vs in enumerate(series.values()):
            value = vs[g]
            if np.isfinite(value):
                x = int(x0 + s * bar)
                cv2.rectangle(image, (x, y_of(value)), (int(x + bar) - 1, y_of(0)), _COLOURS[s % len(_COLOURS)], -1)
        cv2.putText(image, group, (int(x0), height - BOTTOM + 18), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.line(image, (LEFT, y_of(0)), (width - RIGHT, y_of(0)), (0, 0, 0), 1)
    _legend(image, series)
    _write(path, image)


def line_chart(path: Path, title: str, x: list[float], series: dict[str, list[float]], x_label: str, y_label: str,
               y_max: float | None = None, marks: list[tuple[float, str]] = (), width: int = 1100,
               height: int = 420) -> None:
    """One line per series over ``x``; ``marks`` are (x, label) events drawn as labelled vertical lines."""
    image, y_of = _canvas(title, y_label, _top(series, y_max), width, height)
    x_max = max([*x, *(t for t, _ in marks), 1e-9])

    def x_of(value: float) -> int:
        return int(LEFT + (width - LEFT - RIGHT) * value / x_max)

    for k, (t, label) in enumerate(marks):
        cv2.line(image, (x_of(t), TOP), (x_of(t), y_of(0)), (160, 160, 160), 1)
        cv2.putText(image, label, (x_of(t) + 3, TOP + 12 + 14 * (k % 6)), _FONT, 0.35, (90, 90, 90), 1, cv2.LINE_AA)
    for s, values in enumerate(series.values()):
        points = np.array([(x_of(a), y_of(b)) for a, b in zip(x, values)], np.int32)
        if len(points) > 1:
            cv2.polylines(image, [points], False, _COLOURS[s % len(_COLOURS)], 2, cv2.LINE_AA)
    cv2.line(image, (LEFT, y_of(0)), (width - RIGHT, y_of(0)), (0, 0, 0), 1)
    for k in range(6):
        value = x_max * k / 5
        cv2.putText(image, f"{value:.4g}", (x_of(value) - 10, y_of(0) + 16), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(image, x_label, (width // 2, y_of(0) + 34), _FONT, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    _legend(image, series)
    _write(path, image)


LEFT, RIGHT, TOP, BOTTOM = 70, 20, 40, 70


def _top(series: dict[str, list[float]], y_max: float | None) -> float:
    values = np.array([v for vs in series.values() for v in vs], float)
    return y_max or (float(np.nanmax(values)) * 1.1 if np.isfinite(values).any() else 1.0)


def _canvas(title: str, y_label: str, y_max: float, width: int, height: int):
    """A white image with the title and the y axis's grid; and the y-to-pixel map."""
    image = np.full((height, width, 3), 255, np.uint8)
    plot_h = height - TOP - BOTTOM

    def y_of(value: float) -> int:
        return int(TOP + plot_h * (1 - min(value, y_max) / y_max))

    cv2.putText(image, title, (LEFT, 26), _FONT, 0.6, (0, 0, 0), 1, cv2.LINE_AA)
    for k in range(6):
        value = y_max * k / 5
        cv2.line(image, (LEFT, y_of(value)), (width - RIGHT, y_of(value)), (225, 225, 225), 1)
        cv2.putText(image, f"{value:.3g}", (8, y_of(value) + 4), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(image, y_label, (8, TOP - 8), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    return image, y_of


def _legend(image: np.ndarray, series: dict) -> None:
    height = image.shape[0]
    for s, name in enumerate(series):
        x = LEFT + s * 130
        cv2.rectangle(image, (x, height - 28), (x + 14, height - 16), _COLOURS[s % len(_COLOURS)], -1)
        cv2.putText(image, name, (x + 20, height - 17), _FONT, 0.45, (0, 0, 0), 1, cv2.LINE_AA)


def _write(path: Path, image: np.ndarray) -> None:
    ok, png = cv2.imencode(".png", image)
    if ok:
        write_atomic(Path(path), png.tobytes())

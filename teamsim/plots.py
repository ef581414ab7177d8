"""Plots for study reports, drawn with OpenCV (no plotting library to install): grouped bar charts."""
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
    left, right, top, bottom = 70, 20, 40, 70
    image = np.full((height, width, 3), 255, np.uint8)
    values = np.array([v for vs in series.values() for v in vs], float)
    y_max = y_max or (float(np.nanmax(values)) * 1.1 if np.isfinite(values).any() else 1.0)
    plot_h, plot_w = height - top - bottom, width - left - right

    def y_of(value: float) -> int:
        return int(top + plot_h * (1 - min(value, y_max) / y_max))

    cv2.putText(image, title, (left, 26), _FONT, 0.6, (0, 0, 0), 1, cv2.LINE_AA)
    for k in range(6):
        value = y_max * k / 5
        cv2.line(image, (left, y_of(value)), (width - right, y_of(value)), (225, 225, 225), 1)
        cv2.putText(image, f"{value:.3g}", (8, y_of(value) + 4), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(image, y_label, (8, top - 8), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cluster = plot_w / max(len(groups), 1)
    bar = cluster * 0.8 / max(len(series), 1)
    for g, group in enumerate(groups):
        x0 = left + g * cluster + cluster * 0.1
        for s, vs in enumerate(series.values()):
            value = vs[g]
            if np.isfinite(value):
                x = int(x0 + s * bar)
                cv2.rectangle(image, (x, y_of(value)), (int(x + bar) - 1, y_of(0)), _COLOURS[s % len(_COLOURS)], -1)
        cv2.putText(image, group, (int(x0), height - bottom + 18), _FONT, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.line(image, (left, y_of(0)), (width - right, y_of(0)), (0, 0, 0), 1)
    for s, name in enumerate(series):
        x = left + s * 130
        cv2.rectangle(image, (x, height - 28), (x + 14, height - 16), _COLOURS[s % len(_COLOURS)], -1)
        cv2.putText(image, name, (x + 20, height - 17), _FONT, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    ok, png = cv2.imencode(".png", image)
    if ok:
        write_atomic(Path(path), png.tobytes())

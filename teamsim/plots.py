"""Figures for reports and runs, drawn with matplotlib and written as PNG and SVG side by side (the same stem):
``pyplot()`` and ``save_figure`` for any figure, ``grouped_bars`` and ``line_chart`` for the common ones.

matplotlib is imported only when a figure is drawn (it costs half a second), never with ``teamsim.tasks`` or the CLI.
"""
from __future__ import annotations

from io import BytesIO
from pathlib import Path

import numpy as np

from teamsim.files import write_atomic

DPI = 110


def pyplot():
    """matplotlib's pyplot on the Agg backend (headless), imported on first use."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    matplotlib.rcParams["svg.hashsalt"] = "teamsim"  # the same SVG for the same figure
    import matplotlib.pyplot as plt  # noqa: PLC0415

    return plt


def save_figure(fig, path: Path) -> None:
    """``fig`` as ``path`` (PNG) and ``path`` with suffix ``.svg``, each written atomically; the figure is closed."""
    path = Path(path)
    try:
        for suffix, options in ((".png", {}), (".svg", {"metadata": {"Date": None}})):
            buffer = BytesIO()
            fig.savefig(buffer, format=suffix[1:], dpi=DPI, **options)
            write_atomic(path.with_suffix(suffix), buffer.getvalue())
    finally:
        pyplot().close(fig)


def grouped_bars(path: Path, title: str, groups: list[str], series: dict[str, list[float]], y_label: str,
                 y_max: float | None = None) -> None:
    """One cluster of bars per group, one bar per series (NaN bars are left out), with a legend below."""
    fig, axes = pyplot().subplots(figsize=(10, 3.8))
    bar = 0.8 / max(len(series), 1)
    x = np.arange(len(groups))
    for s, (name, values) in enumerate(series.items()):
        values = np.asarray(values, float)
        shown = np.isfinite(values)
        axes.bar(x[shown] - 0.4 + bar * (s + 0.5), values[shown], bar, label=name, color=f"C{s % 10}")
    axes.set_xticks(x, groups)
    axes.set_xlim(-0.5, len(groups) - 0.5)
    _finish(fig, axes, title, y_label, y_max, len(series))
    save_figure(fig, path)


def line_chart(path: Path, title: str, x: list[float], series: dict[str, list[float]], x_label: str, y_label: str,
               y_max: float | None = None, marks: list[tuple[float, str]] = ()) -> None:
    """One line per series over ``x``; ``marks`` are (x, label) events drawn as labelled vertical lines."""
    fig, axes = pyplot().subplots(figsize=(10, 3.8))
    for k, (t, label) in enumerate(marks):
        axes.axvline(t, color="0.63", lw=1)
        axes.annotate(label, (t, 1), xycoords=("data", "axes fraction"), xytext=(3, -10 - 11 * (k % 6)),
                      textcoords="offset points", fontsize=7, color="0.35")
    for s, (name, values) in enumerate(series.items()):
        axes.plot(x, values, color=f"C{s % 10}", lw=2, label=name)
    axes.set_xlim(0, max([*x, *(t for t, _ in marks), 1e-9]))
    axes.set_xlabel(x_label)
    _finish(fig, axes, title, y_label, y_max, len(series))
    save_figure(fig, path)


def _finish(fig, axes, title: str, y_label: str, y_max: float | None, entries: int) -> None:
    """Title, the y axis from 0 (to ``y_max`` if given) with a light grid, the legend in a row below."""
    axes.set_title(title, loc="left")
    axes.set_ylabel(y_label)
    axes.set_ylim(0, y_max)
    axes.grid(axis="y", color="0.88")
    axes.set_axisbelow(True)
    axes.spines[["top", "right"]].set_visible(False)
    if entries:
        axes.legend(loc="upper left", bbox_to_anchor=(0, -0.12), ncol=min(entries, 8), frameon=False)
    fig.tight_layout()

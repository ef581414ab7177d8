"""The janitorial mission's pictures: the floor as the tools left it (the video side panel, drawn with OpenCV at every
panel period, and ``floor.png`` with ``floor.svg``, the same content drawn with matplotlib at the end).

The floor raster from the ground truth (:mod:`teamsim.tasks.worlds.janitorial`): cleaned reachable floor green,
reachable floor still to clean pale red, obstacles black, out of reach grey; furniture outlined brown (filled
cream once dusted), cans as discs in their frequency's colour (grey once emptied), robots as labelled dots. The
3-D video shows only bodies, so this is where the floor's cleaning, the dusting and the emptied cans show.
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from teamsim.plots import pyplot, save_figure

_FONT = cv2.FONT_HERSHEY_SIMPLEX
CLEANED, DIRTY, SOLID, UNREACHABLE = (120, 200, 120), (170, 170, 240), (30, 30, 30), (205, 205, 205)  # BGR
SCALE = 80  # pixels per metre


def floor_image(info: dict, colours: dict[str, tuple], robots: dict[str, np.ndarray], time: float) -> np.ndarray:
    """BGR image of the room's state; ``colours`` maps frequencies to RGBA, ``robots`` names to (x, y)."""
    floor = info["floor"]
    raster = np.full(floor.shape + (3,), UNREACHABLE, np.uint8)
    raster[floor.reachable & floor.cleaned] = CLEANED
    raster[floor.reachable & ~floor.cleaned] = DIRTY
    raster[floor.occupied] = SOLID
    width, height = (int(round(s * SCALE)) for s in floor.size)
    image = cv2.resize(np.ascontiguousarray(np.flipud(raster.transpose(1, 0, 2))), (width, height),
                       interpolation=cv2.INTER_NEAREST)

    def pixel(x: float, y: float) -> tuple[int, int]:
        return int(round((x + floor.size[0] / 2) * SCALE)), int(round((floor.size[1] / 2 - y) * SCALE))

    furniture = info["furniture"]
    for (x, y, hx, hy, yaw), done in zip(furniture.boxes, furniture.done_at):
        c, s = np.cos(yaw), np.sin(yaw)
        corners = np.array([pixel(x + c * u - s * v, y + s * u + c * v) for u, v in
                            ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))], np.int32)
        if done is not None:
            cv2.fillPoly(image, [corners], (190, 225, 240))
        cv2.polylines(image, [corners], True, (40, 80, 140), 2)
    for can in info["cans"].cans:
        if time < can.appears:
            continue
        r, g, b = (int(255 * v) for v in colours[can.frequency][:3])
        colour = (150, 150, 150) if can.emptied_at is not None else (b, g, r)
        cv2.circle(image, pixel(can.x, can.y), int(can.radius * SCALE), colour, -1)
    for name, (x, y) in robots.items():
        cv2.circle(image, pixel(x, y), 6, (0, 0, 0), -1)
        cv2.putText(image, name, (pixel(x, y)[0] + 7, pixel(x, y)[1] - 5), _FONT, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    hud = np.full((26, width, 3), 255, np.uint8)
    cleaned = 100 * floor.share_cleaned()
    emptied = sum(c.emptied_at is not None for c in info["cans"].cans)
    dusted = sum(d is not None for d in furniture.done_at)
    cv2.putText(hud, f"t = {time:.0f} s  floor {cleaned:.0f} %  cans {emptied}/{len(info['cans'].cans)}  "
                     f"dusted {dusted}/{len(furniture.done_at)}", (6, 18), _FONT, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
    return np.vstack([hud, image])


def write_floor(path: Path, info: dict, colours: dict[str, tuple], robots: dict[str, np.ndarray],
                time: float) -> None:
    """``floor.png`` and ``floor.svg``: what :func:`floor_image` shows, drawn with matplotlib in metres."""
    plt = pyplot()
    from matplotlib.patches import Circle, Polygon  # noqa: PLC0415  (with pyplot, only when drawing)

    floor, furniture, cans = info["floor"], info["furniture"], info["cans"].cans
    raster = np.full(floor.shape + (3,), UNREACHABLE, np.uint8)
    raster[floor.reachable & floor.cleaned] = CLEANED
    raster[floor.reachable & ~floor.cleaned] = DIRTY
    raster[floor.occupied] = SOLID
    half_x, half_y = floor.size[0] / 2, floor.size[1] / 2
    fig, axes = plt.subplots(figsize=(max(4.0, floor.size[0] * 0.7), max(3.0, floor.size[1] * 0.7) + 0.4))
    axes.imshow(np.flipud(raster.transpose(1, 0, 2))[:, :, ::-1], extent=(-half_x, half_x, -half_y, half_y),
                interpolation="nearest")
    for (x, y, hx, hy, yaw), done in zip(furniture.boxes, furniture.done_at):
        c, s = np.cos(yaw), np.sin(yaw)
        corners = [(x + c * u - s * v, y + s * u + c * v) for u, v in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))]
        axes.add_patch(Polygon(corners, closed=True, facecolor="#f0e1be" if done is not None else "none",
                               edgecolor="#8c5028", linewidth=1.5))
    for can in cans:
        if time >= can.appears:
            colour = "#969696" if can.emptied_at is not None else colours[can.frequency][:3]
            axes.add_patch(Circle((can.x, can.y), can.radius, color=colour))
    for name, (x, y) in robots.items():
        axes.plot([x], [y], "o", color="black", markersize=5)
        axes.annotate(name, (x, y), xytext=(4, 4), textcoords="offset points", fontsize=8)
    emptied = sum(c.emptied_at is not None for c in cans)
    dusted = sum(d is not None for d in furniture.done_at)
    axes.set_title(f"t = {time:.0f} s   floor {100 * floor.share_cleaned():.0f} % cleaned   cans {emptied}/"
                   f"{len(cans)}   dusted {dusted}/{len(furniture.done_at)}", fontsize=9)
    axes.set_xlabel("x, m")
    axes.set_ylabel("y, m")
    save_figure(fig, path)

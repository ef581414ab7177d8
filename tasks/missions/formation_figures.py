"""Pictures of the ``formation`` mission: the video's side panel (OpenCV, drawn every second: the line around its
leader) and ``formation.png`` + ``.svg`` (matplotlib): the paths from above beside the formation error fe_t over
time."""
from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np

from teamsim.plots import pyplot, save_figure

PANEL = 480  # px, the side panel's height and width
PANEL_SPAN = 12.0  # m of floor across the panel, centred on the leader
ROUTE_BGR, GREY, BLACK = (30, 180, 230), (150, 150, 150), (0, 0, 0)
TAB10 = ((0.12, 0.47, 0.71), (1.0, 0.5, 0.05), (0.17, 0.63, 0.17), (0.84, 0.15, 0.16), (0.58, 0.4, 0.74),
         (0.55, 0.34, 0.29), (0.89, 0.47, 0.76), (0.5, 0.5, 0.5), (0.74, 0.74, 0.13), (0.09, 0.75, 0.81))


def _box_corners(box) -> np.ndarray:
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [box.half_x, box.half_y]
    return local @ np.array([[c, s], [-s, c]]) + [box.x, box.y]


def colours(names) -> dict[str, tuple[float, float, float]]:
    """A distinct colour (RGB in [0, 1]) per robot, in order."""
    return {n: TAB10[k % len(TAB10)] for k, n in enumerate(names)}


def panel_image(scenario, info: dict, places: dict, time: float) -> np.ndarray:
    """BGR image: the PANEL_SPAN m around the leader from above, north up: the route, obstacles, each robot
    (filled) and its proper place given the leader's pose (ring of the same colour), and fe_t."""
    half = np.array(scenario.arena.size) / 2
    centre = np.array(info["tracks"][info["line"].leader][-1][:2])
    if np.any(np.abs(centre) > half) and places:  # the leader taken out of the arena: centre on the line
        centre = np.mean([p for p, _ in places.values()], axis=0)
    scale = PANEL / PANEL_SPAN
    image = np.full((PANEL, PANEL, 3), 255, np.uint8)

    def px(point) -> tuple[int, int]:
        x, y = (np.asarray(point, float) - centre) * scale
        return int(PANEL / 2 + x), int(PANEL / 2 - y)

    cv2.rectangle(image, px(-half), px(half), BLACK, 2)
    for box in scenario.arena.boxes:
        cv2.fillPoly(image, [np.array([px(p) for p in _box_corners(box)], np.int32)], GREY)
    cv2.polylines(image, [np.array([px(p) for p in info["route"]], np.int32)], False, ROUTE_BGR, 2, cv2.LINE_AA)
    radius = max(2, int(0.25 * scale))
    palette = {n: tuple(int(255 * c) for c in rgb[::-1]) for n, rgb in colours(info["tracks"]).items()}
    for name, (_, place) in places.items():
        if name != info["line"].leader:
            cv2.circle(image, px(place), radius, palette[name], 2, cv2.LINE_AA)
    for name, track in info["tracks"].items():
        at = px(track[-1][:2])
        cv2.circle(image, at, radius, palette[name], -1, cv2.LINE_AA)
        cv2.putText(image, name, (at[0] + radius, at[1] - radius), cv2.FONT_HERSHEY_SIMPLEX, 0.6, BLACK, 2,
                    cv2.LINE_AA)
    fe = info["errors"][-1] if info["errors"] else 0.0
    for row, text in enumerate((f"strategy {scenario.task.strategy}   t = {time:.0f} s", f"fe_t = {fe:.2f} m",
                                "filled: robot, ring: its place")):
        cv2.putText(image, text, (10, 24 + 22 * row), cv2.FONT_HERSHEY_SIMPLEX, 0.6, BLACK, 1, cv2.LINE_AA)
    return image


def write_formation(path: Path, scenario, info: dict) -> None:
    """``formation.png`` and ``.svg``: the paths from above (route dashed, obstacles grey) and fe_t per second."""
    plt = pyplot()
    fig, (top, curve) = plt.subplots(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [1, 1.3]})
    for box in scenario.arena.boxes:
        top.add_patch(plt.Polygon(_box_corners(box), color="0.6"))
    route = info["route"]
    top.plot(route[:, 0], route[:, 1], "--", color="goldenrod", lw=1.5, label="route")
    for (name, track), colour in zip(info["tracks"].items(), colours(info["tracks"]).values()):
        if track:
            xy = np.array(track)[:, :2]
            xy[np.any(np.abs(xy) > np.array(scenario.arena.size) / 2, axis=1)] = np.nan  # removed: off the map
            top.plot(xy[:, 0], xy[:, 1], color=colour, lw=1.2, label=name)
    half = np.array(scenario.arena.size) / 2
    top.set(xlim=(-half[0], half[0]), ylim=(-half[1], half[1]), aspect="equal", xlabel="x (m)", ylabel="y (m)",
            title="paths from above")
    top.legend(fontsize=7, loc="best")
    curve.plot(range(len(info["errors"])), info["errors"], color="tab:blue")
    curve.set(xlabel="time (s)", ylabel="fe_t (m)", title=f"formation error, strategy {scenario.task.strategy}")
    curve.grid(alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path)

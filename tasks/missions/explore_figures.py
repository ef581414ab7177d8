"""The explore mission's pictures: ``map.png``, the manager's final global map with each environment's status, the
bogs found and each robot's path, and ``coverage.png``, the explored share over time with the team's events marked
(matplotlib, each also as ``.svg``); the video's side panel, the same map drawn with OpenCV."""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from teamsim.controllers.exploration.territory import Territory
from teamsim.plots import line_chart, pyplot, save_figure

CELL_PX = 5  # pixels per map cell
STATUS_BGR = {"E": (60, 160, 60), "PE": (0, 140, 255), "UE": (40, 40, 200), "assigned": (200, 120, 0)}
ROBOT_BGR = [(180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214), (189, 103, 148), (75, 86, 140),
             (194, 119, 227), (127, 127, 127)]
BOG_BGR = (30, 70, 140)
STATUS_RGB = {"E": "#3ca03c", "PE": "#ff8c00", "UE": "#c82828", "assigned": "#0078c8"}  # STATUS_BGR's
BOG_RGB = "#8c461e"
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def map_image(probabilities: np.ndarray, territory: Territory, status, boggy, trails: dict, bogs=()) -> np.ndarray:
    """BGR picture of the map (white free, black occupied, grey unexplored), world y up."""
    shade = (255 * (1.0 - probabilities)).astype(np.uint8)
    image = cv2.cvtColor(np.flipud(shade), cv2.COLOR_GRAY2BGR)
    image = cv2.resize(image, None, fx=CELL_PX, fy=CELL_PX, interpolation=cv2.INTER_NEAREST)
    size = image.shape[0]

    def px(x: float, y: float) -> tuple[int, int]:
        x0, y0 = territory.origin
        return (int((x - x0) / territory.resolution * CELL_PX),
                int(size - (y - y0) / territory.resolution * CELL_PX))

    for bog in bogs:  # the true bogs, outlined
        cv2.rectangle(image, px(bog.x - bog.half_x, bog.y + bog.half_y), px(bog.x + bog.half_x, bog.y - bog.half_y),
                      BOG_BGR, 2)
    for k, points in enumerate(trails.values()):
        if len(points) > 1:
            cv2.polylines(image, [np.array([px(x, y) for x, y in points], np.int32)], False,
                          ROBOT_BGR[k % len(ROBOT_BGR)], 2, cv2.LINE_AA)
    for e in range(territory.environments):
        (x_lo, y_lo), (x_hi, y_hi) = territory.bounds(e)
        colour = STATUS_BGR.get(status[e], (0, 0, 0))
        cv2.rectangle(image, px(x_lo, y_hi), px(x_hi, y_lo), colour, 2)
        label = f"{e} {status[e]}" + (" bog" if boggy[e] else "")
        cv2.putText(image, label, (px(x_lo, y_hi)[0] + 5, px(x_lo, y_hi)[1] + 16), _FONT, 0.45, colour, 1,
                    cv2.LINE_AA)
    return image


def write_map(path: Path, probabilities: np.ndarray, territory: Territory, status, boggy, trails: dict,
              bogs=()) -> None:
    """The map (white free, black occupied, grey unexplored; world y up, in metres), the true bogs outlined, each
    robot's path, and each environment outlined in its status's colour and labelled, with a key on the right."""
    plt = pyplot()
    rows, cols = probabilities.shape
    x0, y0 = territory.origin
    side = 8.0 * cols / max(rows, cols)
    fig, axes = plt.subplots(figsize=(side + 2.2, 8.0 * rows / max(rows, cols) + 0.3), layout="constrained")
    axes.imshow(1.0 - probabilities, cmap="gray", vmin=0, vmax=1, origin="lower", interpolation="nearest",
                extent=(x0, x0 + cols * territory.resolution, y0, y0 + rows * territory.resolution))
    for bog in bogs:
        axes.add_patch(plt.Rectangle((bog.x - bog.half_x, bog.y - bog.half_y), 2 * bog.half_x, 2 * bog.half_y,
                                     fill=False, ec=BOG_RGB, lw=2))
    for k, (name, points) in enumerate(trails.items()):
        xy = np.array(points).reshape(-1, 2)
        axes.plot(xy[:, 0], xy[:, 1], color=f"C{k % len(ROBOT_BGR)}", lw=2, label=name)
    for e in range(territory.environments):
        (x_lo, y_lo), (x_hi, y_hi) = territory.bounds(e)
        colour = STATUS_RGB.get(status[e], "black")
        axes.add_patch(plt.Rectangle((x_lo, y_lo), x_hi - x_lo, y_hi - y_lo, fill=False, ec=colour, lw=2))
        axes.annotate(f"{e} {status[e]}" + (" bog" if boggy[e] else ""), (x_lo, y_hi), xytext=(4, -4),
                      textcoords="offset points", va="top", fontsize=8, color=colour)
    for label, status_key in (("explored (E)", "E"), ("partly (PE)", "PE"), ("unexplored (UE)", "UE")):
        axes.plot([], [], color=STATUS_RGB[status_key], lw=3, label=label)
    axes.plot([], [], color=BOG_RGB, lw=3, label="true bog")
    axes.set(xlabel="x (m)", ylabel="y (m)", aspect="equal")
    axes.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
    save_figure(fig, path)


def panel_image(global_info, territory: Territory, trails: dict, roles: dict, time: float) -> np.ndarray:
    """The video's side panel (RGB): the manager's map with statuses and paths, and a HUD of each robot's roles
    and current environment."""
    image = map_image(global_info.global_map, territory, global_info.status, global_info.boggy, trails)
    hud = np.full((24 + 20 * (len(roles) + 1), image.shape[1], 3), 255, np.uint8)
    share = global_info.explored_share()
    cv2.putText(hud, f"manager's map  t = {time:.0f} s  explored {100 * share:.1f} %", (8, 18), _FONT, 0.5,
                (0, 0, 0), 1, cv2.LINE_AA)
    for k, (name, held) in enumerate(roles.items()):
        record = global_info.records.get(name)
        where = f" in E{record.environment}" if record is not None and record.environment is not None else ""
        text = f"{name}: {' + '.join(held) or 'no role'}{where}"
        cv2.putText(hud, text, (8, 40 + 20 * k), _FONT, 0.45, ROBOT_BGR[k % len(ROBOT_BGR)], 1, cv2.LINE_AA)
    return cv2.cvtColor(np.vstack([hud, image]), cv2.COLOR_BGR2RGB)


def write_coverage(path: Path, samples: list[tuple[float, float]], events: list[dict]) -> None:
    """Explored share (%) over time, with feedback removals, bogs and faults marked."""
    times = [t for t, _ in samples]
    shares = [100 * s for _, s in samples]
    marks = [(e["t"], f"{e['event']} {e.get('robot', '')}".strip()) for e in events]
    line_chart(path, "explored share over time", times, {"explored %": shares}, "time, s", "explored, %",
               y_max=100.0, marks=marks)

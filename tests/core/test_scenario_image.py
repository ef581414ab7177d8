"""Image worlds: a black-and-white occupancy PNG at a given resolution drives ``navigate`` to the same trial as the
equivalent list of boxes."""
from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
import yaml

from teamsim.cli import main
from teamsim.runner import mission_of
from teamsim.scenario import Arena, OccupancyImage, image_boxes, load
from teamsim.tasks.missions.navigate import nav_world_of

RESOLUTION = 0.125  # m per pixel: box edges on the pixel grid are exact in binary
SIZE = 8.0
# Boxes with edges on the pixel grid, apart from each other: (x, y, half_x, half_y)
BOXES = [(-1.0, 1.5, 0.5, 0.75), (1.25, -0.5, 0.75, 0.25), (0.5, 2.5, 0.25, 0.5), (-2.0, -2.0, 0.5, 0.5)]


def draw(path, boxes) -> None:
    """The boxes as an occupancy image covering the arena: black occupied, white free; row 0 is the top."""
    pixels = round(SIZE / RESOLUTION)
    image = np.full((pixels, pixels), 255, np.uint8)
    for x, y, hx, hy in boxes:
        c0, c1 = round((x - hx + SIZE / 2) / RESOLUTION), round((x + hx + SIZE / 2) / RESOLUTION)
        r0, r1 = round((SIZE / 2 - (y + hy)) / RESOLUTION), round((SIZE / 2 - (y - hy)) / RESOLUTION)
        image[r0:r1, c0:c1] = 0
    cv2.imwrite(str(path), image)


def scenario(arena: dict, method: str) -> dict:
    return {"mission": "navigate", "seed": 3, "duration": 15.0, "arena": {"size": [SIZE, SIZE], **arena},
            "robots": {"red": {"kind": "diffdrive", "pose": [-3.0, 3.0, -0.785], "options": {"radius": 0.35},
                               "controller": {"method": method}}},
            "task": {"goal": [3.0, -3.0], "time_limit": 15.0}}


def test_an_image_gives_back_the_boxes_drawn_in_it(tmp_path):
    draw(tmp_path / "map.png", BOXES)
    arena = Arena(size=(SIZE, SIZE), image=OccupancyImage(str(tmp_path / "map.png"), RESOLUTION))
    got = sorted((b.x, b.y, b.half_x, b.half_y) for b, _ in image_boxes(arena))
    assert got == sorted(BOXES)
    # An L shape is two boxes that cover it exactly; the image may sit anywhere inside the arena.
    draw(tmp_path / "l.png", [(0.0, 0.0, 1.0, 0.25), (-0.75, 0.75, 0.25, 0.5)])
    arena = Arena(size=(SIZE, SIZE), image=OccupancyImage(str(tmp_path / "l.png"), RESOLUTION, origin=(-4.0, -4.0)))
    boxes = [b for b, _ in image_boxes(arena)]
    assert sum(4 * b.half_x * b.half_y for b in boxes) == pytest.approx(2 * 0.5 + 0.5 * 1.0)
    assert len(boxes) == 2


def test_an_image_that_does_not_fit_is_refused(capsys, tmp_path):
    draw(tmp_path / "map.png", BOXES)
    data = scenario({"image": {"file": "map.png", "resolution": 0.25}}, "FRC")
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    assert main(["scenario", "show", "navigate", "--scenario", str(tmp_path / "s.yaml")]) == 2
    assert ("arena.image: 64 x 64 px at 0.25 m/px is 16 x 16 m from (-8, -8); it must lie inside the arena"
            in capsys.readouterr().err)


@pytest.mark.parametrize("method", ["FRC", "HRDK"])
def test_png_world_drives_navigate_like_the_box_list(capsys, tmp_path, method):
    draw(tmp_path / "map.png", BOXES)
    listed = scenario({"boxes": [{"x": x, "y": y, "half_x": hx, "half_y": hy} for x, y, hx, hy in BOXES]}, method)
    pictured = scenario({"image": {"file": "map.png", "resolution": RESOLUTION}}, method)
    mission = mission_of("navigate")
    maps = [nav_world_of(load(d, mission, tmp_path)) for d in (listed, pictured)]
    assert (maps[0].occupancy == maps[1].occupancy).all() and maps[0].occupancy.any()
    summaries = []
    for name, data in (("listed", listed), ("pictured", pictured)):
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
        code = main(["run", "navigate", "--scenario", str(tmp_path / f"{name}.yaml"), "--out", str(tmp_path),
                     "--run-id", name])
        assert code in (0, 1), capsys.readouterr().err
        run = tmp_path / "navigate" / name
        summaries.append((json.loads((run / "summary.json").read_text()), (run / "events.jsonl").read_bytes()))
    (a, events_a), (b, events_b) = summaries
    assert a["metrics"] == b["metrics"] and a["metrics"]["path_length"] > 1.0
    assert a["final_state_sha256"] == b["final_state_sha256"]
    assert events_a == events_b

"""A mission's side panel in the live video: [rendered view | panel], scaled to the view's height, one size a run."""
from __future__ import annotations

import numpy as np
import pytest
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.wander import WanderMission

from teamsim.gl import RenderBackendError, require_rendering
from tests.core.test_video import decode
from tests.helpers import wander_config

try:
    require_rendering()
except RenderBackendError as exc:
    pytest.skip(str(exc), allow_module_level=True)

# Only now: teamsim.video needs offscreen GL when imported.
from teamsim import video
from teamsim.runner import run_trial

RED, BLUE = (255, 0, 0), (0, 0, 255)


def solid(colour, height: int, width: int) -> np.ndarray:
    return np.full((height, width, 3), colour, np.uint8)


class PanelMission(WanderMission):
    """wander, with a red panel until 0.5 s, none (keep the last) until 1 s, then a blue one; each the same array
    at every frame it is shown, as a mission whose map has not changed returns it."""

    def __init__(self):
        self.red, self.blue = solid(RED, 40, 61), solid(BLUE, 40, 61)

    def video_panel(self, world) -> np.ndarray | None:
        if world.time < 0.5:
            return self.red
        return None if world.time < 1.0 else self.blue


def test_the_panel_is_beside_the_view_and_sent_only_when_it_changes(tmp_path, monkeypatch):
    monkeypatch.setitem(MISSIONS, "wander", PanelMission())
    made = []

    class Recorded(video.VideoProcess):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(video, "VideoProcess", Recorded)
    cfg = wander_config(tmp_path, params={"robots": 2}, seed=2, duration=2.0, run_id="p")
    cfg.video.enabled = True
    cfg.video.width, cfg.video.height = 160, 120
    result = run_trial(cfg)
    assert result.status == "completed" and result.summary["error"] is None
    meta, frames = decode(result.run_dir / "video.mp4")
    # The 61x40 panel at the view's height is 183 px wide; one column more makes the frame's width even.
    assert meta["size"] == (160 + 184, 120) and len(frames) == 61
    assert made[0].panels_sent == 2  # red once, blue once: not at each of the 61 frames

    def panel_colour(frame):
        return frame[10:-10, 160 + 10:-10].reshape(-1, 3).mean(axis=0)

    np.testing.assert_allclose(panel_colour(frames[0]), RED, atol=30)
    np.testing.assert_allclose(panel_colour(frames[24]), RED, atol=30)  # t = 0.8 s: None kept the red panel
    np.testing.assert_allclose(panel_colour(frames[-1]), BLUE, atol=30)
    assert np.abs(frames[-1][:, :150].astype(int) - BLUE).sum(axis=2).mean() > 100  # the view is not the panel


def test_a_later_panel_of_another_shape_fits_the_first_ones_slot():
    side = video.SidePanel(view_width=160, height=120)
    view = np.zeros((120, 160, 3), np.uint8)
    side.update(solid(RED, 60, 60))  # a square: 120 px wide at the view's height
    assert side.beside(view).shape == (120, 280, 3)
    side.update(solid(BLUE, 30, 60))  # twice as wide as high: 120 x 60, centred on black
    frame = side.beside(view)
    assert frame.shape == (120, 280, 3)
    assert (frame[30:90, 160:] == BLUE).all()
    assert (frame[:30, 160:] == 0).all() and (frame[90:, 160:] == 0).all()


def test_before_the_first_panel_the_slot_is_a_black_square_of_even_frame_width():
    side = video.SidePanel(view_width=160, height=121)
    frame = side.beside(np.full((121, 160, 3), 200, np.uint8))
    assert frame.shape == (121, 160 + 122, 3)  # 121 would leave the frame's width odd
    assert (frame[:, 160:] == 0).all() and (frame[:, :160] == 200).all()
    side.update(solid(RED, 10, 10))
    assert side.beside(np.zeros((121, 160, 3), np.uint8)).shape == (121, 282, 3)


@pytest.mark.parametrize("image", [np.zeros((10, 10, 3), np.float32), np.zeros((10, 10), np.uint8),
                                   np.zeros((0, 10, 3), np.uint8)])
def test_a_panel_not_rgb_uint8_is_refused(image):
    with pytest.raises(ValueError, match="RGB uint8 image"):
        video.SidePanel(160, 120).update(image)

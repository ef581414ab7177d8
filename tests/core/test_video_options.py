"""Video options (issue 30): --video-size, the perspective camera, a HUD drawn crisp, small objects marked."""
from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from tests.core.test_video import decode
from tests.helpers import wander_config

from teamsim.cli import main
from teamsim.config import ConfigError, TrialConfig, VideoConfig, apply_setting, validate
from teamsim.faults import Fault
from teamsim.gl import RenderBackendError, require_rendering

try:
    require_rendering()
except RenderBackendError as exc:
    pytest.skip(str(exc), allow_module_level=True)

# Only now: teamsim.video needs offscreen GL when imported.
from teamsim import video  # noqa: E402
from teamsim.runner import run_trial  # noqa: E402
from teamsim.tasks import MISSIONS  # noqa: E402
from teamsim.world import World  # noqa: E402


@pytest.mark.parametrize("text, size", [("640x480", (640, 480)), ("1280x720", (1280, 720)), ("1280X720", (1280, 720)),
                                        ("64x48", (64, 48)), ("3840x2160", (3840, 2160))])
def test_video_size_parses(text, size):
    assert VideoConfig.parse_size(text) == size


BAD_SIZES = [("0x0", "out of range"), ("abc", "is not WIDTHxHEIGHT"), ("100000x10", "out of range"),
             ("641x480", "odd side"), ("640x", "is not WIDTHxHEIGHT"), ("-640x480", "is not WIDTHxHEIGHT"),
             ("640*480", "is not WIDTHxHEIGHT"), ("62x48", "out of range"), ("640x2162", "out of range")]


@pytest.mark.parametrize("text, why", BAD_SIZES)
@pytest.mark.parametrize("command", [["run", "wander", "--video"], ["render", "/nonexistent/run"]])
def test_a_bad_video_size_is_one_line_and_exit_2(capsys, tmp_path, command, text, why):
    argv = [*command, f"--video-size={text}"] + (["--out", str(tmp_path)] if command[0] == "run" else [])
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("teamsim: error: --video-size: ") and err.count("\n") == 1, err
    assert why in err and "width 64-3840, height 48-2160" in err
    assert not list(tmp_path.iterdir()), "nothing is written for a rejected run"


def test_an_odd_video_width_set_by_key_is_refused(tmp_path):
    cfg = wander_config(tmp_path)
    apply_setting(cfg, "video.width=641")  # in bounds: the evenness check is the configuration's own
    with pytest.raises(ConfigError, match="video.width=641: must be even"):
        validate(cfg)


def test_an_unknown_camera_is_refused_naming_the_allowed_ones(capsys, tmp_path):
    run_trial(wander_config(tmp_path, params={"robots": 2}, seed=1, duration=0.2, run_id="r"))
    for argv in (["run", "wander", "--set", "robots=2", "--video", "--camera", "nobody", "--out", str(tmp_path / "o")],
                 ["render", str(tmp_path / "wander" / "r"), "--camera", "nobody"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("teamsim: error: ") and err.count("\n") == 1, err
        assert ("camera 'nobody' not in the scene; cameras: top, perspective, or a robot's name for its tracking "
                "camera: red, green") in err
    assert not (tmp_path / "o").exists()


@pytest.fixture(scope="module")
def wander_world(tmp_path_factory):
    return World(wander_config(tmp_path_factory.mktemp("w"), params={"robots": 3}, seed=4), MISSIONS["wander"])


@pytest.mark.parametrize("width, height", [(320, 240), (320, 180)])
def test_the_perspective_camera_frames_the_whole_arena(wander_world, width, height):
    renderer = video.FrameRenderer(wander_world.xml, list(wander_world.robots), width, height, "perspective")
    try:
        frame = renderer.render(0.0, wander_world.data.qpos, ["idle"] * 3)
        assert frame.shape == (height, width, 3) and frame.dtype == np.uint8
        low, high = video.arena_bounds(renderer.model, renderer.data)
        assert low[0] < -1 and high[0] > 1 and high[2] > 0.2  # the walls, not the drawn floor's edge
        corners = np.array(np.meshgrid([low[0], high[0]], [low[1], high[1]], [0, high[2]])).T.reshape(-1, 3)
        pixels = np.array([renderer._project(c)[:2] for c in corners])
        assert np.all(pixels >= -0.5) and np.all(pixels <= [width + 0.5, height + 0.5])  # all of it in the frame
        # ... and filling it one way (fitted, not just anywhere far away), centred the other.
        span = pixels.max(axis=0) - pixels.min(axis=0)
        assert max(span[0] / width, span[1] / height) > 0.9
        margins = np.array([pixels.min(axis=0), [width, height] - pixels.max(axis=0)])
        assert np.all(np.abs(margins[0] - margins[1]) <= 0.05 * np.array([width, height]) + 1)
        # The look is oblique: the far wall is drawn shorter than the near one.
        near = pixels[(corners[:, 1] == low[1]) & (corners[:, 2] == 0)]
        far = pixels[(corners[:, 1] == high[1]) & (corners[:, 2] == 0)]
        assert np.ptp(far[:, 0]) < 0.9 * np.ptp(near[:, 0])
        assert np.mean(frame.max(axis=2) < 20) < 0.01  # floor beyond the arena, not the black void
    finally:
        renderer.close()


@pytest.mark.parametrize("camera", ["top", "perspective"])
def test_a_robot_waiting_to_join_does_not_black_out_the_video(tmp_path, camera):
    """A newcomer waits parked far outside the arena; the frame still shows the arena (it was all black: the parked
    robot stretched the model's extent, and with it the near clip plane, past the camera)."""
    config = wander_config(tmp_path, params={"robots": 2}, seed=4)
    config.faults = [Fault("add-robot", "late", 5.0, {"kind": "diffdrive"})]
    world = World(config, MISSIONS["wander"])
    renderer = video.FrameRenderer(world.xml, list(world.robots), 160, 120, camera)
    try:
        frame = renderer.render(0.0, world.data.qpos, ["idle"] * 3)
        assert np.mean(frame.max(axis=2) < 20) < 0.2, "most of the frame is black"
    finally:
        renderer.close()


def test_a_run_with_a_perspective_video_has_the_size_asked_and_the_same_physics(tmp_path, capsys):
    argv = ["run", "wander", "--duration", "0.5", "--seed", "6", "--set", "robots=2", "--out", str(tmp_path)]
    assert main([*argv, "--run-id", "plain"]) == 0
    assert main([*argv, "--run-id", "video", "--video", "--camera", "perspective", "--video-size", "160x120"]) == 0
    meta, frames = decode(tmp_path / "wander" / "video" / "video.mp4")
    assert meta["size"] == (160, 120) and len(frames) == 16
    digests = [json.loads((tmp_path / "wander" / run / "summary.json").read_text())["final_state_sha256"]
               for run in ("plain", "video")]
    assert digests[0] == digests[1]
    assert main(["render", str(tmp_path / "wander" / "plain"), "--camera", "perspective", "--video-size",
                 "160x120"]) == 0
    _, again = decode(tmp_path / "wander" / "plain" / "video-perspective.mp4")
    assert len(again) == len(frames)
    for a, b in zip(frames, again):
        np.testing.assert_array_equal(a, b)


GREY = 128


def _outline_beyond_glyph(image: np.ndarray, reference: np.ndarray, reach: int) -> int:
    """Pixels the drawing darkened (an outline) farther than ``reach`` px from every pixel of the reference glyphs."""
    dark = image.max(axis=2) < GREY - 40
    near = cv2.dilate(reference, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1, 2 * reach + 1)))
    return int(np.count_nonzero(dark & (near == 0)))


TEXT, ORIGIN = "red: find-locations-methodical", (10, 40)


def _reference(scale: float, thickness: int) -> tuple[np.ndarray, np.ndarray]:
    """The text's anti-aliased coverage (0-255) drawn alone, and where it is (0 or 1)."""
    coverage = np.zeros((60, 700), np.uint8)
    cv2.putText(coverage, TEXT, ORIGIN, video._FONT, scale, 255, thickness, cv2.LINE_AA)
    return coverage, (coverage > 0).astype(np.uint8)


@pytest.mark.parametrize("height", [480, 720, 1080])
def test_the_hud_outline_follows_the_glyphs(height):
    """The outline is one ring round the glyphs, where a reference rendering of the text puts them: no second,
    shifted copy."""
    hud = video.Hud(height)
    image = np.full((60, 700, 3), GREY, np.uint8)
    video._label(image, TEXT, ORIGIN, (217, 38, 38), hud.text, hud.thickness, hud.outline)
    coverage, reference = _reference(hud.text, hud.thickness)
    assert _outline_beyond_glyph(image, reference, hud.outline + 1) == 0
    # The glyphs are the reference glyphs, pixel for pixel: the text colour (230, 110, 110) over a grey of any shade
    # adds (R - G) = 120 x its coverage, which is the reference's anti-aliased coverage.
    drawn = (image[..., 0].astype(float) - image[..., 1]) / 120
    np.testing.assert_allclose(drawn, coverage / 255, atol=0.02)
    # The outline is there and dark: about as many black pixels as the glyphs have pixels.
    assert np.count_nonzero(image.max(axis=2) < 40) > 0.5 * np.count_nonzero(reference)


def test_the_old_drawing_fails_the_outline_check():
    """What the check above catches: the HUD before issue 30 outlined text with a thick black putText (3) under the
    thin one (1). OpenCV 5 draws its Hershey font names with a TrueType face whose weight follows the thickness,
    and the heavier weight advances wider, so the black copy drifts right along the line: a doubled outline."""
    doubled = np.full((60, 700, 3), GREY, np.uint8)
    cv2.putText(doubled, TEXT, ORIGIN, video._FONT, 0.45, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(doubled, TEXT, ORIGIN, video._FONT, 0.45, (217, 38, 38), 1, cv2.LINE_AA)
    _, reference = _reference(0.45, 1)
    assert _outline_beyond_glyph(doubled, reference, 2) > 10


def test_the_hud_scales_with_the_frame():
    small, large = video.Hud(480), video.Hud(720)
    assert large.size("t = 12.3 s", large.text)[1] == pytest.approx(1.5 * small.size("t = 12.3 s", small.text)[1],
                                                                    abs=1.5)
    assert large.line == 24 and small.line == 16


PUCK_SCENE = """
<mujoco>
  <visual><headlight ambient="0.6 0.6 0.6"/></visual>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" rgba="0.8 0.8 0.8 1"/>
    <camera name="top" pos="0 0 {height}" xyaxes="1 0 0 0 1 0" fovy="45"/>
    <body name="puck0/" pos="{x} {y} 0.02">
      <freejoint/>
      <geom name="shell" type="cylinder" size="0.0254 0.019" rgba="0.95 0.75 0.1 1"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_small_object_is_marked_where_it_is_seen():
    renderer = video.FrameRenderer(PUCK_SCENE.format(height=6.0, x=0.7, y=0.4), [], 640, 480, "top")
    try:
        [puck] = video.small_objects(renderer.model, renderer.data, [])
        assert puck.radius == pytest.approx(0.0254) and puck.rgb == (242, 191, 26)
        frame = renderer.render(0.0, renderer.model.qpos0, [])
        x, y, per_metre = renderer._project(renderer.data.geom_xpos[puck.geoms].mean(axis=0))
        assert puck.radius * per_metre < video.MARK_RADIUS  # the puck itself is under 4 px across
        px, py = round(x), round(y)
        # A disc of the puck's colour, MARK_RADIUS px, round the puck's projected centre, with a dark rim.
        for dx, dy in ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)):
            np.testing.assert_allclose(frame[py + dy, px + dx], puck.rgb, atol=40)
        rim = [frame[round(y + 3 * np.sin(a)), round(x + 3 * np.cos(a))].astype(int) for a in np.linspace(0, 6, 12)]
        assert np.mean([p.sum() for p in rim]) < 0.75 * sum(puck.rgb)
        assert np.all(np.abs(frame[py, px + 8].astype(int) - frame[py, px + 30]) < 10)  # nothing beyond it
    finally:
        renderer.close()
    # Seen close, a puck is left as drawn: no marker over it.
    near = video.FrameRenderer(PUCK_SCENE.format(height=0.6, x=0.05, y=-0.05), [], 640, 480, "top")
    try:
        frame = near.render(0.0, near.model.qpos0, [])
        near.renderer.update_scene(near.data, camera=near.camera)
        np.testing.assert_array_equal(frame[200:], near.renderer.render()[200:])  # (below the HUD's panel)
    finally:
        near.close()


def test_the_cleanup_s_pucks_are_its_small_objects(tmp_path):
    config = TrialConfig(mission="hazardous-waste", params=MISSIONS["hazardous-waste"].Params(), out=str(tmp_path))
    world = World(config, MISSIONS["hazardous-waste"])
    renderer = video.FrameRenderer(world.xml, list(world.robots), 64, 48, "top")
    try:
        names = sorted(renderer.model.body(renderer.model.geom_bodyid[o.geoms[0]]).name for o in renderer._small)
        assert names == sorted(f"puck{k}/puck" for k in range(len(names))) and len(names) >= 5
    finally:
        renderer.close()

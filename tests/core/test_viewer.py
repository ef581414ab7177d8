"""The live viewer (issue 30): it opens on a virtual screen (Xvfb), steps a mission, labels the robots and closes
cleanly; without a display it says so in one line and exits 2."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

import mujoco
import numpy as np
import pytest

import imageio_ffmpeg
from teamsim.cli.main import main
from teamsim.tasks import MISSIONS
from teamsim.viewer import KEY_RIGHT, KEY_SPACE, _Keys, _label
from teamsim.world import World
from tests.helpers import wander_config


@pytest.fixture
def virtual_screen():
    """A fresh Xvfb display; CI installs Xvfb (.ci/run), so there the test must not skip."""
    if shutil.which("Xvfb") is None:
        if os.environ.get("CI"):
            pytest.fail("Xvfb is missing on CI: .ci/run installs Debian's xvfb")
        pytest.skip("Xvfb not installed (apt-get install xvfb)")
    # -displayfd: Xvfb picks a free display and writes its number once it accepts connections (a fixed number can
    # collide with a stale server, and its socket can appear before the server is ready)
    read_end, write_end = os.pipe()
    server = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, pass_fds=(write_end,))
    os.close(write_end)
    with os.fdopen(read_end) as ready:
        number = ready.readline().strip()
    if not number:
        server.kill()
        pytest.fail("Xvfb exited before it reported a display")
    display = f":{number}"
    yield display
    server.terminate()
    server.wait(timeout=10)


def _grab(display: str) -> np.ndarray | None:
    """One screenshot of the virtual screen (ffmpeg's x11grab), or None if it failed."""
    grab = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-loglevel", "error", "-f", "x11grab", "-video_size",
                           "1024x768", "-i", display, "-frames:v", "1", "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                          capture_output=True, timeout=30)
    if grab.returncode != 0 or len(grab.stdout) != 1024 * 768 * 3:
        return None
    return np.frombuffer(grab.stdout, np.uint8).reshape(768, 1024, 3)


def test_the_viewer_opens_steps_and_closes_on_a_virtual_screen(virtual_screen):
    env = {**os.environ, "DISPLAY": virtual_screen}
    view = subprocess.Popen([sys.executable, "-X", "faulthandler", "-m", "teamsim.cli",
                             "view", "wander", "--duration", "6", "--seed", "3"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    drawn = 0.0
    while view.poll() is None:  # the window shows the arena: a good share of the screen is not background black
        frame = _grab(virtual_screen)
        if frame is not None:
            drawn = max(drawn, float((frame.max(axis=2) > 40).mean()))
        time.sleep(0.5)
    out, err = view.communicate(timeout=60)
    assert view.returncode == 0, err
    assert out.strip().startswith("completed: 6.0 s simulated"), out
    assert "Traceback" not in err
    assert drawn > 0.05, f"the window never showed the arena ({drawn:.1%} of the screen drawn)"


def test_without_a_display_it_says_so_in_one_line(monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["view", "wander", "--duration", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("teamsim: error: no display") and "\n" not in err


def test_a_display_that_cannot_be_opened_is_one_line(monkeypatch, capsys):
    monkeypatch.setenv("DISPLAY", ":4999")  # no server there
    assert main(["view", "wander", "--duration", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("teamsim: error: cannot open a window on display ':4999'") and "\n" not in err


def test_a_bad_speed_is_refused(capsys):
    assert main(["view", "wander", "--speed", "0"]) == 2
    assert "--speed: must be > 0" in capsys.readouterr().err


def test_labels_name_each_robot_and_its_behaviour(tmp_path):
    config = wander_config(tmp_path)
    world = World(config, MISSIONS["wander"])
    for _ in range(3):
        world.tick()
        world.advance(world.steps_per_tick)
    scene = mujoco.MjvScene(world.model, maxgeom=100)
    _label(scene, world)
    labels = [scene.geoms[k].label for k in range(scene.ngeom)]
    assert labels == [f"{r.name}: {r.behaviour}" for r in world.robots.values()]
    assert all(r.behaviour != "idle" for r in world.robots.values())  # the controllers ran


def test_space_pauses_and_right_arrow_steps_only_while_paused():
    keys = _Keys()
    keys(KEY_RIGHT)
    assert (keys.paused, keys.steps) == (False, 0)
    keys(KEY_SPACE)
    keys(KEY_RIGHT)
    keys(KEY_RIGHT)
    assert (keys.paused, keys.steps) == (True, 2)
    keys(KEY_SPACE)
    assert not keys.paused

"""MUJOCO_GL selection order, and the progress bar's terminal-only drawing."""
from __future__ import annotations

import io

import pytest

from teamsim import gl
from teamsim.progress import Progress


@pytest.mark.parametrize("user, libraries, expected", [
    ("osmesa", {"EGL", "OSMesa"}, "osmesa"),  # the user's choice always wins
    (None, {"EGL", "OSMesa"}, "egl"),
    (None, {"OSMesa"}, "osmesa"),
    (None, set(), "disable"),
])
def test_backend_order(monkeypatch, user, libraries, expected):
    monkeypatch.delenv("PYOPENGL_PLATFORM", raising=False)
    if user:
        monkeypatch.setenv("MUJOCO_GL", user)
    else:
        monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.setattr(gl, "_library_present", lambda name: name in libraries)
    assert gl.choose_backend() == expected
    if expected in ("egl", "osmesa"):
        assert gl.require_rendering() == expected
        import os
        assert os.environ["PYOPENGL_PLATFORM"] == expected


def test_no_backend_is_one_clear_sentence(monkeypatch):
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.setattr(gl, "_library_present", lambda name: False)
    with pytest.raises(gl.RenderBackendError, match=r"^no offscreen OpenGL found: install .*libosmesa6"):
        gl.require_rendering()


def test_progress_draws_only_when_enabled():
    quiet, loud = io.StringIO(), io.StringIO()
    Progress(10.0, "x", stream=quiet).update(5.0)  # StringIO is not a terminal
    bar = Progress(10.0, "wander", enabled=True, stream=loud)
    bar.update(5.0)
    bar.finish()
    assert quiet.getvalue() == ""
    assert "wander [###############" in loud.getvalue() and "5.0/10.0 s sim" in loud.getvalue()
    assert "x real time" in loud.getvalue()


def test_logged_progress_is_a_line_now_and_then():
    log = io.StringIO()
    bar = Progress(720, "720 trials on 2 workers", stream=log, unit="trials done", log_every=0.0)
    bar.update(3)
    bar.update(10)
    bar.finish()
    lines = log.getvalue().splitlines()
    assert len(lines) == 2 and lines[0].startswith("720 trials on 2 workers: 3/720 trials done")
    assert "\r" not in log.getvalue() and "real time" not in log.getvalue()
    hourly = io.StringIO()
    Progress(10.0, "wander", stream=hourly, log_every=3600.0).update(5.0)
    assert hourly.getvalue() == ""  # runs shorter than log_every stay quiet

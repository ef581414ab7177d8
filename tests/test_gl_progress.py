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

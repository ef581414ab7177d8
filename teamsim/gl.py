"""Choose the offscreen OpenGL backend before MuJoCo is imported.

MuJoCo reads ``MUJOCO_GL`` once, at import time (DESIGN.md, "Rendering, headless"). The order is:
the user's own ``MUJOCO_GL`` if set; else ``egl`` (Mesa's software llvmpipe works out of the box); else
``osmesa``; else a one-sentence error saying what to install. GLFW is never used: it needs a display.
"""
from __future__ import annotations

import ctypes.util
import os

INSTALL_HINT = (
    "no offscreen OpenGL found: install Mesa's EGL (apt-get install libegl1 libgl1-mesa-dri) "
    "or OSMesa (apt-get install libosmesa6), or set MUJOCO_GL yourself"
)


class RenderBackendError(RuntimeError):
    """No usable offscreen rendering backend."""


def _library_present(name: str) -> bool:
    return ctypes.util.find_library(name) is not None


def choose_backend() -> str:
    """Set ``MUJOCO_GL`` (and keep ``PYOPENGL_PLATFORM`` consistent) and return the backend chosen.

    Safe to call many times; it never overrides a value the user set.
    """
    chosen = os.environ.get("MUJOCO_GL")
    if not chosen:
        if _library_present("EGL"):
            chosen = "egl"
        elif _library_present("OSMesa"):
            chosen = "osmesa"
        else:
            chosen = "disable"
        os.environ["MUJOCO_GL"] = chosen
    # A mismatched PYOPENGL_PLATFORM gives "'GLXPlatform' object has no attribute 'EGL'" (dm_control#129).
    if chosen in ("egl", "osmesa"):
        os.environ.setdefault("PYOPENGL_PLATFORM", chosen)
    return chosen


def require_rendering() -> str:
    """Return the backend, or raise one clear sentence when nothing can render offscreen."""
    backend = choose_backend()
    if backend in ("disable", "off", ""):
        raise RenderBackendError(INSTALL_HINT)
    return backend

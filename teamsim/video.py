"""Offscreen video: render recorded states, draw the HUD with OpenCV, stream H.264 to an mp4.

The live render and ``teamsim render`` share one path: both feed a recorded frame (time, qpos, behaviours)
to :class:`FrameRenderer`, which poses its own copy of the scene and renders it, so the two produce the
same pixels. :class:`Mp4Writer` pipes each frame to ffmpeg (libx264, yuv420p, playable in browsers) as it
comes, so a video is never held in memory. During a run, :class:`VideoProcess` does both in a process of its
own, fed the recorded frames through a queue, so rendering and encoding take the second core and the physics
keeps the first.
"""
from __future__ import annotations

import multiprocessing
import os
import queue
import signal
from pathlib import Path

import cv2
import imageio_ffmpeg
import numpy as np

from teamsim.gl import require_rendering

require_rendering()
import mujoco  # noqa: E402  (MUJOCO_GL must be chosen first)

from teamsim.models.robot import colour_of  # noqa: E402

_FONT = cv2.FONT_HERSHEY_SIMPLEX
# No multisample anti-aliasing: on software GL (llvmpipe) any multisampling halves the frame rate (22 against
# 43 frames/s at 640x480, 5 robots), for edges a pixel softer (docs/decisions.md, "Video off the physics core").
MULTISAMPLES = 0


class FrameRenderer:
    """Renders frames of one compiled scene from any of its cameras, with the HUD drawn on top."""

    def __init__(self, model_xml: str, robot_names: list[str], width: int, height: int, camera: str = "top"):
        self.model = mujoco.MjModel.from_xml_string(model_xml)
        self.data = mujoco.MjData(self.model)
        self.robot_names = list(robot_names)
        self.width, self.height = width, height
        self.model.vis.global_.offwidth = max(self.model.vis.global_.offwidth, width)
        self.model.vis.global_.offheight = max(self.model.vis.global_.offheight, height)
        self.model.vis.quality.offsamples = MULTISAMPLES
        self.camera = camera_id(self.model, camera)
        self.renderer = mujoco.Renderer(self.model, height, width)
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self._roots = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"{n}/") for n in robot_names]
        self._rgb = {n: tuple(int(255 * c) for c in colour_of(n)[:3]) for n in robot_names}

    def render(self, time: float, qpos: np.ndarray, behaviours: list[str]) -> np.ndarray:
        """An RGB frame (height x width x 3, uint8) of the scene in state ``qpos``, with the HUD."""
        m, d = self.model, self.data
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_camlight(m, d)
        self.renderer.update_scene(d, camera=self.camera)
        frame = np.ascontiguousarray(self.renderer.render())  # OpenCV draws on contiguous arrays only
        self._draw_hud(frame, time, behaviours)
        return frame

    def _project(self, point: np.ndarray) -> tuple[int, int] | None:
        """Pixel of a world point seen by this camera (pinhole, looking down the camera's -z)."""
        d, cam = self.data, self.camera
        local = d.cam_xmat[cam].reshape(3, 3).T @ (point - d.cam_xpos[cam])
        if local[2] >= -1e-6:
            return None
        focal = 0.5 * self.height / np.tan(np.radians(self.model.cam_fovy[cam]) / 2)
        return (int(self.width / 2 + focal * local[0] / -local[2]), int(self.height / 2 - focal * local[1] / -local[2]))

    def _draw_hud(self, frame: np.ndarray, time: float, behaviours: list[str]) -> None:
        for name, root, behaviour in zip(self.robot_names, self._roots, behaviours):
            pixel = self._project(self.data.xpos[root] + np.array([0, 0, 0.4]))
            if pixel and 0 <= pixel[0] < self.width and 0 <= pixel[1] < self.height:
                _label(frame, name, (pixel[0] - 12, pixel[1] - 6), self._rgb[name], scale=0.4)
        lines = [(f"t = {time:6.1f} s", (255, 255, 255))]
        lines += [(f"{name}: {behaviour}", self._rgb[name]) for name, behaviour in zip(self.robot_names, behaviours)]
        panel_h = 8 + 16 * min(len(lines), 20)
        panel = frame[:panel_h, :210]
        panel[:] = panel // 3  # translucent, so the scene under the panel stays visible
        for row, (text, colour) in enumerate(lines[:20]):
            _label(frame, text, (6, 18 + 16 * row), colour, scale=0.45)

    def close(self) -> None:
        # Closed explicitly: EGL/OSMesa contexts left to the garbage collector raise at interpreter exit.
        self.renderer.close()


def _label(image: np.ndarray, text: str, origin: tuple[int, int], colour, scale: float) -> None:
    cv2.putText(image, text, origin, _FONT, scale, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(image, text, origin, _FONT, scale, colour, 1, cv2.LINE_AA)


def camera_name(camera: str) -> str:
    """``top`` stays ``top``; ``red`` or ``red/track`` mean red's tracking camera."""
    if camera == "top" or "/" in camera:
        return camera
    return f"{camera}/track"


def cameras(model: mujoco.MjModel) -> list[str]:
    return [model.camera(k).name for k in range(model.ncam)]


def camera_id(model: mujoco.MjModel, camera: str) -> int:
    """The id of ``camera`` (see :func:`camera_name`); ValueError naming the scene's cameras if it has none."""
    found = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera_name(camera))
    if found < 0:
        raise ValueError(f"camera {camera!r} not in the scene; cameras: {', '.join(cameras(model))}")
    return found


class Mp4Writer:
    """Streams RGB frames to an H.264 (yuv420p) mp4; the file appears under its name only when closed."""

    def __init__(self, path: Path, width: int, height: int, fps: int):
        self.path = Path(path)
        self._part = self.path.with_name(self.path.name + ".part")
        self._stream = imageio_ffmpeg.write_frames(
            str(self._part), (width, height), fps=fps, codec="libx264", pix_fmt_out="yuv420p",
            macro_block_size=2, quality=None,
            # veryfast: x264's CPU per frame about halved against its default (medium), for a file 2 % larger
            output_params=["-f", "mp4", "-movflags", "+faststart", "-preset", "veryfast"],
            bitrate=None, ffmpeg_log_level="error", input_params=None)
        self._stream.send(None)
        self.frames = 0

    def write(self, frame: np.ndarray) -> None:
        self._stream.send(np.ascontiguousarray(frame))
        self.frames += 1

    def close(self) -> None:
        if self._stream is not None:
            self._stream.close()
            self._stream = None
            if self.frames:
                os.replace(self._part, self.path)
            else:
                self._part.unlink(missing_ok=True)


FRAME_QUEUE = 256  # frames waiting for the video process: a few hundred bytes of qpos each


class VideoProcess:
    """A run's ``video.mp4``, rendered and encoded in a spawned process from the frames ``write`` hands it.
    The physics waits only when the queue is full. ``close`` finishes the file and returns None, or what went
    wrong in the video process (the run's own outcome does not depend on it)."""

    def __init__(self, path: Path, model_xml: str, robot_names: list[str], width: int, height: int, camera: str,
                 fps: int):
        context = multiprocessing.get_context("spawn")  # a GL context does not survive a fork
        self._frames = context.Queue(maxsize=FRAME_QUEUE)
        self._failures = context.Queue()
        self._process = context.Process(target=_render_frames, name="teamsim-video", daemon=True,
                                        args=(self._frames, self._failures, Path(path), model_xml,
                                              list(robot_names), width, height, camera, fps))
        self._process.start()

    def write(self, time: float, qpos: np.ndarray, behaviours: list[str]) -> None:
        self._put((time, np.array(qpos), list(behaviours)))

    def _put(self, item) -> bool:
        """Queue ``item``; False if the video process has ended."""
        while self._process.is_alive():
            try:
                self._frames.put(item, timeout=0.5)
                return True
            except queue.Full:
                continue
        return False

    def close(self) -> str | None:
        self._put(None)
        self._process.join()
        if self._process.exitcode == 0:
            return None
        try:
            return self._failures.get(timeout=1.0)
        except queue.Empty:
            return f"the video process ended with exit code {self._process.exitcode}"


def _render_frames(frames, failures, path: Path, model_xml: str, robot_names: list[str], width: int, height: int,
                   camera: str, fps: int) -> None:
    """The video process: render and encode every frame until the end marker (None). It ignores Ctrl-C, which
    reaches the whole process group: the run, interrupted, still sends the end marker, so the video keeps
    every frame up to the interruption."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        renderer = FrameRenderer(model_xml, robot_names, width, height, camera)
        writer = Mp4Writer(path, width, height, fps)
        try:
            while (frame := frames.get()) is not None:
                writer.write(renderer.render(*frame))
        finally:
            writer.close()
            renderer.close()
    except BaseException as exc:  # noqa: BLE001  (reported to the run, which writes it in the summary)
        failures.put(f"{type(exc).__name__}: {exc}")
        raise SystemExit(1) from None

"""Offscreen video: render recorded states, draw the HUD with OpenCV, stream H.264 to an mp4.

The live render and ``teamsim render`` share one path: both feed a recorded frame (time, qpos, behaviours)
to :class:`FrameRenderer`, which poses its own copy of the scene and renders it, so the two produce the
same pixels. :class:`Mp4Writer` pipes each frame to ffmpeg (libx264, yuv420p, playable in browsers) as it
comes, so a video is never held in memory. During a run, :class:`VideoProcess` does both in a process of its
own, fed the recorded frames through a queue, so rendering and encoding take the second core and the physics
keeps the first.

A mission may show an image of its own beside the view (its ``video_panel`` hook, see :class:`VideoProcess`):
each frame is then [rendered view | panel], the panel scaled to the view's height (:class:`SidePanel`). A panel
is not part of the trajectory, so ``teamsim render`` makes the view alone.
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


class SidePanel:
    """A mission's image beside the rendered view, in a slot as high as the view. The first panel sets the slot's
    width (scaled to the view's height, keeping its aspect ratio; one column more if needed for an even frame
    width, which H.264 needs); a later panel of another shape is fitted inside the slot, centred on black, so a
    run's frames all have one size. Until the first panel comes, the slot is a black square."""

    def __init__(self, view_width: int, height: int):
        self.view_width, self.height = view_width, height
        self.width: int | None = None
        self._image: np.ndarray | None = None

    def update(self, image: np.ndarray) -> None:
        """Show ``image`` (RGB, uint8, height x width x 3) from now on; scaled once here, not at every frame."""
        if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 3 or 0 in image.shape:
            raise ValueError(f"video_panel must return an RGB uint8 image (height x width x 3), "
                             f"not {image.dtype} of shape {image.shape}")
        if self.width is None:
            self.width = self._even(round(image.shape[1] * self.height / image.shape[0]))
        self._image = _fit(image, self.width, self.height)

    def beside(self, view: np.ndarray) -> np.ndarray:
        """The frame: ``view`` with the panel (or the black square before the first one) on its right."""
        if self.width is None:
            self.width = self._even(self.height)
        panel = self._image if self._image is not None else np.zeros((self.height, self.width, 3), np.uint8)
        return np.hstack([view, panel])

    def _even(self, width: int) -> int:
        """``width`` (at least 1), one more if the frame would otherwise be of odd width."""
        width = max(1, width)
        return width + (self.view_width + width) % 2


def _fit(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """``image`` scaled to fit a black ``width`` x ``height`` box, keeping its aspect ratio, centred in it. Scaled
    down by area (a large map stays readable), up by nearest neighbour (a map's cells stay sharp squares)."""
    scale = min(width / image.shape[1], height / image.shape[0])
    size = (min(width, max(1, round(image.shape[1] * scale))), min(height, max(1, round(image.shape[0] * scale))))
    scaled = cv2.resize(image, size, interpolation=cv2.INTER_AREA if scale < 1 else cv2.INTER_NEAREST)
    box = np.zeros((height, width, 3), np.uint8)
    top, left = (height - size[1]) // 2, (width - size[0]) // 2
    box[top:top + size[1], left:left + size[0]] = scaled
    return box


FRAME_QUEUE = 256  # frames waiting for the video process: a few hundred bytes of qpos each
PANELS_IN_FLIGHT = 4  # panels sent but not yet taken by the video process: a 640x640 map is 1.2 MB each


class VideoProcess:
    """A run's ``video.mp4``, rendered and encoded in a spawned process from the frames ``write`` hands it.
    The physics waits only when the queue is full. ``close`` finishes the file and returns None, or what went
    wrong in the video process (the run's own outcome does not depend on it).

    With ``panel`` true, every frame has a side panel (:class:`SidePanel`) showing the last image ``write`` was
    given. An image goes through the queue only when it is a new object: a mission whose panel has not changed
    returns the same array (or None) and costs nothing, where pickling a 640x640 map 30 times a second would cost
    37 MB/s. Comparing identity, not content, is what keeps it cheap, so a mission must return a new array when
    its image changes, never redraw the one it returned before. At most ``PANELS_IN_FLIGHT`` images wait in the
    queue at once (the physics waits for the video process beyond that), which bounds the memory they take."""

    def __init__(self, path: Path, model_xml: str, robot_names: list[str], width: int, height: int, camera: str,
                 fps: int, panel: bool = False):
        context = multiprocessing.get_context("spawn")  # a GL context does not survive a fork
        self._frames = context.Queue(maxsize=FRAME_QUEUE)
        self._failures = context.Queue()
        self._panel_slots = context.BoundedSemaphore(PANELS_IN_FLIGHT)
        self._panel: np.ndarray | None = None  # the last image sent; held, so its identity is never reused
        self.panels_sent = 0
        self._process = context.Process(target=_render_frames, name="teamsim-video", daemon=True,
                                        args=(self._frames, self._failures, self._panel_slots, Path(path), model_xml,
                                              list(robot_names), width, height, camera, fps, panel))
        self._process.start()

    def write(self, time: float, qpos: np.ndarray, behaviours: list[str], panel: np.ndarray | None = None) -> None:
        """Queue a frame; ``panel`` is the side panel's image for it, None to keep the previous one."""
        if panel is self._panel:
            panel = None
        if panel is not None:
            self._panel = panel
            panel = np.array(panel)  # a copy: the queue pickles it later, in a thread of its own
            if not self._wait(self._panel_slots.acquire):
                return
            self.panels_sent += 1
        self._put((time, np.array(qpos), list(behaviours), panel))

    def _wait(self, acquire) -> bool:
        """Call ``acquire(timeout=...)`` until it succeeds (True) or the video process has ended (False)."""
        while self._process.is_alive():
            if acquire(timeout=0.5):
                return True
        return False

    def _put(self, item) -> bool:
        """Queue ``item``; False if the video process has ended."""
        def put(timeout: float) -> bool:
            try:
                self._frames.put(item, timeout=timeout)
                return True
            except queue.Full:
                return False
        return self._wait(put)

    def close(self) -> str | None:
        self._put(None)
        self._process.join()
        if self._process.exitcode == 0:
            return None
        try:
            return self._failures.get(timeout=1.0)
        except queue.Empty:
            return f"the video process ended with exit code {self._process.exitcode}"


def _render_frames(frames, failures, panel_slots, path: Path, model_xml: str, robot_names: list[str], width: int,
                   height: int, camera: str, fps: int, panel: bool) -> None:
    """The video process: render and encode every frame until the end marker (None). It ignores Ctrl-C, which
    reaches the whole process group: the run, interrupted, still sends the end marker, so the video keeps
    every frame up to the interruption. The mp4 is opened at the first frame, whose size the panel may set."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        renderer = FrameRenderer(model_xml, robot_names, width, height, camera)
        side = SidePanel(width, height) if panel else None
        writer = None
        try:
            while (item := frames.get()) is not None:
                *state, image = item
                if image is not None:
                    panel_slots.release()
                    side.update(image)
                frame = renderer.render(*state)
                frame = side.beside(frame) if side else frame
                writer = writer or Mp4Writer(path, frame.shape[1], frame.shape[0], fps)
                writer.write(frame)
        finally:
            if writer is not None:
                writer.close()
            renderer.close()
    except BaseException as exc:  # noqa: BLE001  (reported to the run, which writes it in the summary)
        failures.put(f"{type(exc).__name__}: {exc}")
        raise SystemExit(1) from None

"""Offscreen video: render recorded states, draw the HUD with OpenCV, stream H.264 to an mp4.

The live render and ``teamsim render`` share one path: both feed a recorded frame (time, qpos, behaviours)
to :class:`FrameRenderer`, which poses its own copy of the scene and renders it, so the two produce the
same pixels. :class:`Mp4Writer` pipes each frame to ffmpeg (libx264, yuv420p, playable in browsers) as it
comes, so a video is never held in memory. During a run, :class:`VideoProcess` does both in a process of its
own, fed the recorded frames through a queue, so rendering and encoding take the second core and the physics
keeps the first.

Cameras: the scene's own (``top``, each robot's tracking camera ``ROBOT/track``) and ``perspective``, MuJoCo's
free camera looking down at the arena's centre from 50 degrees, at the distance that fits the arena's walls in the
frame (:func:`perspective_camera`). The HUD's text is drawn once, in one pass, and outlined by growing its own
mask (:func:`_label`); small objects such as pucks are drawn over as a disc of their colour, outlined, wherever
they would be only a few pixels across (:func:`small_objects`).

A mission may show an image of its own beside the view (its ``video_panel`` hook, see :class:`VideoProcess`):
each frame is then [rendered view | panel], the panel scaled to the view's height (:class:`SidePanel`). A panel
is not part of the trajectory, so ``teamsim render`` makes the view alone.
"""
from __future__ import annotations

import functools
import multiprocessing
import os
import queue
import signal
from dataclasses import dataclass
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

PERSPECTIVE = "perspective"  # the camera name of the oblique whole-arena view
FREE_CAMERA = -1  # its camera id: MuJoCo's free camera (mujoco.Renderer's convention for camera=-1)
PERSPECTIVE_ELEVATION = -50.0  # degrees below the horizon it looks down at the arena's centre
PERSPECTIVE_AZIMUTH = 90.0  # degrees: from the south, looking north (+y), so x runs left to right as from the top
PERSPECTIVE_FILL = 0.94  # the arena's bounding box fills this share of the frame's half-width or half-height
HUD_HEIGHT = 480  # the frame height the HUD's sizes are given for; it scales with the frame's height
SMALL_OBJECT = 0.1  # m: a free body (not a robot) whose geoms all fit in this radius is a small object
MARK_RADIUS = 3.0  # px at HUD_HEIGHT: one seen smaller than this is marked by a disc of its colour this size, outlined


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
        mujoco.mj_kinematics(self.model, self.data)  # the initial pose: where the walls stand, how big objects are
        if self.camera == FREE_CAMERA:
            self.camera = perspective_camera(self.model, self.data, width, height)
            _floor_to_horizon(self.model, 4 * self.camera.distance)
        self.renderer = mujoco.Renderer(self.model, height, width)
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self._roots = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"{n}/") for n in robot_names]
        self._rgb = {n: tuple(int(255 * c) for c in colour_of(n)[:3]) for n in robot_names}
        self._small = small_objects(self.model, self.data, self._roots)
        self._small_geoms = [g for thing in self._small for g in thing.geoms]
        self._small_mean = np.zeros((len(self._small), len(self._small_geoms)))  # each object's geoms' mean
        column = 0
        for row, thing in enumerate(self._small):
            self._small_mean[row, column:column + len(thing.geoms)] = 1 / len(thing.geoms)
            column += len(thing.geoms)
        self._small_radii = np.array([thing.radius for thing in self._small])
        self._bodies = [_RobotShape(self.model, root) for root in self._roots]
        self._hud = Hud(height)

    def render(self, time: float, qpos: np.ndarray, behaviours: list[str]) -> np.ndarray:
        """An RGB frame (height x width x 3, uint8) of the scene in state ``qpos``, with the HUD."""
        m, d = self.model, self.data
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_camlight(m, d)
        self.renderer.update_scene(d, camera=self.camera)
        self._view = _View(self.renderer.scene, self.width, self.height)
        frame = np.ascontiguousarray(self.renderer.render())  # OpenCV draws on contiguous arrays only
        self._mark_small_objects(frame)
        self._draw_hud(frame, time, behaviours)
        return frame

    def _project(self, point: np.ndarray) -> tuple[float, float, float] | None:
        """Where a world point falls in the last frame rendered, (x, y) in pixels, and how many pixels a metre there
        is; None behind the camera."""
        return self._view.project(point)

    def _mark_small_objects(self, frame: np.ndarray) -> None:
        """Each small object (a puck) seen smaller than ``MARK_RADIUS``, drawn over at that size: a disc of its own
        colour with a darker rim, so that it stays visible (at 640x480 from the top a puck is 4 px across)."""
        if not self._small:
            return
        least = MARK_RADIUS * self.height / HUD_HEIGHT
        centres = self._small_mean @ self.data.geom_xpos[self._small_geoms]
        x, y, per_metre = self._view.project_many(centres)
        marked = ((centres[:, 2] > -0.05)  # (not taken out of the arena, below the floor)
                  & (per_metre > 0) & (self._small_radii * per_metre < least)
                  & (x >= -least) & (x < self.width + least) & (y >= -least) & (y < self.height + least))
        for k in np.flatnonzero(marked):
            _disc(frame, (x[k], y[k]), least, self._small[k].rgb)

    def _draw_hud(self, frame: np.ndarray, time: float, behaviours: list[str]) -> None:
        hud = self._hud
        for name, shape in zip(self.robot_names, self._bodies):
            point = shape.tag_point(self.data)
            seen = None if point is None else self._project(point)
            if seen and 0 <= seen[0] < self.width and 0 <= seen[1] < self.height:
                origin = (round(seen[0] - hud.size(name, hud.tag)[0] / 2), round(seen[1]) - hud.gap)
                _label(frame, name, origin, self._rgb[name], hud.tag, hud.thickness, hud.outline)
        lines = [(f"t = {time:6.1f} s", (255, 255, 255))]
        lines += [(f"{name}: {behaviour}", self._rgb[name]) for name, behaviour in zip(self.robot_names, behaviours)]
        lines = lines[:20]
        panel_w = min(frame.shape[1], hud.margin * 2 + max(hud.size(text, hud.text)[0] for text, _ in lines))
        panel = frame[:hud.margin + hud.line * len(lines), :panel_w]
        panel[:] = panel // 3  # translucent, so the scene under the panel stays visible
        for row, (text, colour) in enumerate(lines):
            _label(frame, text, (hud.margin, hud.first + hud.line * row), colour, hud.text, hud.thickness,
                   hud.outline)

    def close(self) -> None:
        # Closed explicitly: EGL/OSMesa contexts left to the garbage collector raise at interpreter exit.
        self.renderer.close()


class _View:
    """MuJoCo's own projection of a rendered scene: its camera and frustum (mjr_render's glFrustum), the two eyes'
    cameras averaged as a mono render does (each is half the interpupillary distance aside)."""

    def __init__(self, scene: mujoco.MjvScene, width: int, height: int):
        cam = mujoco.mjv_averageCamera(scene.camera[0], scene.camera[1])
        self.pos, self.forward, self.up = (np.array(v, float) for v in (cam.pos, cam.forward, cam.up))
        self.right = np.cross(self.forward, self.up)
        self.near = cam.frustum_near
        self.pixels = height / (cam.frustum_top - cam.frustum_bottom)  # per unit on the near plane
        self.centre = (width / 2 - cam.frustum_center * self.pixels,
                       height / 2 + (cam.frustum_top + cam.frustum_bottom) / 2 * self.pixels)

    def project(self, point: np.ndarray) -> tuple[float, float, float] | None:
        x, y, per_metre = self.project_many(np.asarray(point, float)[None, :])
        return None if per_metre[0] <= 0 else (float(x[0]), float(y[0]), float(per_metre[0]))

    def project_many(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """x, y (pixels) and pixels per metre of each of ``points`` (n x 3); per metre 0 for one behind the camera."""
        offsets = points - self.pos
        depth = offsets @ self.forward
        seen = depth > self.near
        per_metre = np.where(seen, self.near / np.where(seen, depth, 1.0) * self.pixels, 0.0)
        return self.centre[0] + offsets @ self.right * per_metre, self.centre[1] - offsets @ self.up * per_metre, \
            per_metre


class Hud:
    """The HUD's sizes for a frame ``height`` pixels high: given at 480 and scaled with it, so the text takes the
    same share of the frame at every size, and its strokes and outline stay whole pixels."""

    def __init__(self, height: int):
        scale = height / HUD_HEIGHT
        self.text, self.tag = 0.45 * scale, 0.4 * scale  # OpenCV font scales: the panel's lines, robots' names
        self.thickness = max(1, round(scale))  # glyph stroke, px
        self.outline = max(1, round(scale))  # dark outline round each stroke, px
        self.line, self.margin = round(16 * scale), round(6 * scale)  # line pitch and panel margin, px
        self.first = self.margin + round(12 * scale)  # baseline of the first line
        self.gap = round(3 * scale)  # between a robot and its name, px

    def size(self, text: str, font_scale: float) -> tuple[int, int]:
        return cv2.getTextSize(text, _FONT, font_scale, self.thickness)[0]


def _label(image: np.ndarray, text: str, origin: tuple[int, int], colour, scale: float, thickness: int = 1,
           outline: int = 1) -> None:
    """``text`` in ``colour``, outlined in black, its baseline starting at ``origin``. The glyphs are drawn once,
    as a coverage mask; the outline is that mask grown by ``outline`` pixels, so it follows every stroke exactly.
    (The HUD before drew the outline as a second, thicker ``putText`` under the text. OpenCV 5 draws its Hershey
    font names with a TrueType face whose weight follows the thickness, and the heavier face advances wider: the
    black copy drifted right along the line, 5 px by the end of a 30-letter line at 640x480, a doubled outline.)"""
    keep, glyph, top, left = _text_masks(text, scale, thickness, outline)
    x0, y0 = origin[0] - left, origin[1] - top
    ix0, iy0 = max(x0, 0), max(y0, 0)  # the box clipped to the image
    ix1, iy1 = min(x0 + keep.shape[1], image.shape[1]), min(y0 + keep.shape[0], image.shape[0])
    if ix0 >= ix1 or iy0 >= iy1:
        return
    window = (slice(iy0 - y0, iy1 - y0), slice(ix0 - x0, ix1 - x0))
    box = image[iy0:iy1, ix0:ix1] * keep[window] + np.asarray(_text_colour(colour), np.float32) * glyph[window]
    image[iy0:iy1, ix0:ix1] = np.rint(box).astype(np.uint8)


@functools.lru_cache(maxsize=1024)
def _text_masks(text: str, scale: float, thickness: int, outline: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """What drawing ``text`` does to each pixel of its box: the share of the pixel kept (under neither the glyphs
    nor their outline), the glyphs' coverage (their colour's share), both (h x w x 1, float32); and where the text's
    origin is in the box (from its top, from its left). Kept: robots' names and behaviours come back every frame."""
    (width, height), baseline = cv2.getTextSize(text, _FONT, scale, thickness)
    pad = thickness + outline + 1
    mask = np.zeros((height + baseline + 2 * pad, width + 2 * pad), np.uint8)
    cv2.putText(mask, text, (pad, height + pad), _FONT, scale, 255, thickness, cv2.LINE_AA)
    halo = cv2.dilate(mask, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * outline + 1, 2 * outline + 1)))
    halo = cv2.add(halo, halo)  # twice as opaque (saturating): a hairline stroke's coverage peaks at about half
    glyph = mask.astype(np.float32)[..., None] / 255
    dark = halo.astype(np.float32)[..., None] / 255
    return (1 - dark) * (1 - glyph), glyph, height + pad, pad


def _text_colour(colour) -> tuple[int, int, int]:
    """A robot's colour made light enough to read on black: an H.264 video keeps colour at half resolution, so
    a thin stroke's shape rests on its brightness (a third of the way to white: red 217,38,38 -> 230,110,110)."""
    return tuple(round(c + (255 - c) / 3) for c in colour)


def _disc(image: np.ndarray, centre: tuple[float, float], radius: float, colour) -> None:
    """A disc of ``colour`` rimmed a pixel wide in a dark shade of it (as a lit puck's side looks from above), both
    anti-aliased, the centre and radius to a sixteenth of a pixel (OpenCV's fixed point)."""
    at, size = (round(centre[0] * 16), round(centre[1] * 16)), round(radius * 16)
    cv2.circle(image, at, size, colour, -1, cv2.LINE_AA, 4)
    cv2.circle(image, at, size, tuple(round(0.4 * c) for c in colour), 1, cv2.LINE_AA, 4)


@dataclass(frozen=True)
class SmallObject:
    geoms: list[int]  # its geoms: their centre is where it is
    radius: float  # m, its footprint's: how far its geoms reach sideways from that centre
    rgb: tuple[int, int, int]  # its colour (its first geom's)


def small_objects(model: mujoco.MjModel, data: mujoco.MjData, robot_roots: list[int]) -> list[SmallObject]:
    """Every small free object: a body on a free joint (a top-level body, as MuJoCo requires), not a robot, whose
    geoms, its own and its children's, all fit within ``SMALL_OBJECT`` of it (the cleanup's pucks; not a box to
    push). ``data`` is posed (any pose will do: such an object is rigid)."""
    robots = set(robot_roots)
    found = []
    for body in range(1, model.nbody):
        first = model.body_jntadr[body]
        if first < 0 or int(model.jnt_type[first]) != int(mujoco.mjtJoint.mjJNT_FREE) or body in robots:
            continue
        geoms = [g for g in range(model.ngeom) if model.body_rootid[model.geom_bodyid[g]] == body]
        if not geoms or max(np.linalg.norm(data.geom_xpos[g] - data.xpos[body]) + model.geom_rbound[g]
                            for g in geoms) > SMALL_OBJECT:
            continue
        centre = data.geom_xpos[geoms].mean(axis=0)
        radius = max(np.linalg.norm((data.geom_xpos[g] - centre)[:2]) + _footprint(model, g) for g in geoms)
        rgba = model.mat_rgba[model.geom_matid[geoms[0]]] if model.geom_matid[geoms[0]] >= 0 else \
            model.geom_rgba[geoms[0]]
        found.append(SmallObject(geoms, float(radius), tuple(int(round(255 * c)) for c in rgba[:3])))
    return found


class _RobotShape:
    """Where a robot's name goes: above the top of its north edge (how far north and how high its geoms' boxes
    reach, as it stands now), in the middle of it east to west: just above the robot, as each camera here (all
    look north) sees it."""

    def __init__(self, model: mujoco.MjModel, root: int):
        self.root = root
        self.geoms = [g for g in range(model.ngeom) if root >= 0 and model.body_rootid[model.geom_bodyid[g]] == root]
        self.centres, self.halves = model.geom_aabb[self.geoms, :3], model.geom_aabb[self.geoms, 3:]

    def tag_point(self, data: mujoco.MjData) -> np.ndarray | None:
        if not self.geoms:  # (no such robot in the scene)
            return None
        turn = data.geom_xmat[self.geoms].reshape(-1, 3, 3)[:, 1:, :]  # each geom's world-y and world-z rows
        reach = data.geom_xpos[self.geoms, 1:] + np.einsum("gij,gj->gi", turn, self.centres) \
            + np.einsum("gij,gj->gi", np.abs(turn), self.halves)  # (geoms, [north, top])
        return np.array([data.xpos[self.root, 0], *reach.max(axis=0)])


def _footprint(model: mujoco.MjModel, geom: int) -> float:
    """How far a geom reaches sideways from its centre, standing as built (its bounding sphere if not simple)."""
    kind, size, shape = int(model.geom_type[geom]), model.geom_size[geom], mujoco.mjtGeom
    if kind in (int(shape.mjGEOM_SPHERE), int(shape.mjGEOM_CYLINDER), int(shape.mjGEOM_CAPSULE)):
        return float(size[0])
    if kind == int(shape.mjGEOM_BOX):
        return float(np.hypot(size[0], size[1]))
    if kind == int(shape.mjGEOM_ELLIPSOID):
        return float(max(size[0], size[1]))
    return float(model.geom_rbound[geom])


def _floor_to_horizon(model: mujoco.MjModel, reach: float) -> None:
    """Draw the floor (every plane) at least ``reach`` m each way, so an oblique view sees floor, not the black
    void, beyond the arena. Only this renderer's copy of the model changes: a plane collides the same whatever its
    size, and the physics never sees this copy anyway."""
    for g in range(model.ngeom):
        if int(model.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_PLANE) and model.geom_size[g, 0] > 0:
            model.geom_size[g, :2] = np.maximum(model.geom_size[g, :2], reach)


def arena_bounds(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
    """The (low, high) corners of the box round everything fixed in the world but the floor (walls, obstacles,
    marked zones), from posed ``data``; the floor's drawn size if there is nothing else; else the model's extent."""
    corners = []
    for g in range(model.ngeom):
        if model.geom_bodyid[g] != 0 or int(model.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_PLANE):
            continue
        centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
        rotation = data.geom_xmat[g].reshape(3, 3)
        for signs in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3):
            corners.append(data.geom_xpos[g] + rotation @ (centre + signs * half))
    if corners:
        points = np.array(corners)
        return points.min(axis=0), points.max(axis=0)
    planes = [g for g in range(model.ngeom) if int(model.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_PLANE)
              and model.geom_size[g, 0] > 0 and model.geom_size[g, 1] > 0]
    if planes:
        half = np.array([max(model.geom_size[g, 0] for g in planes), max(model.geom_size[g, 1] for g in planes), 0])
        return -half, half
    extent = max(float(model.stat.extent), 1.0)
    return np.asarray(model.stat.center) - extent, np.asarray(model.stat.center) + extent


def perspective_camera(model: mujoco.MjModel, data: mujoco.MjData, width: int, height: int) -> mujoco.MjvCamera:
    """The ``perspective`` view: MuJoCo's free camera looking down at ``PERSPECTIVE_ELEVATION`` from the south,
    as close as it can be with the whole arena (:func:`arena_bounds`, walls and all) in the frame, centred.

    With the camera's orientation fixed, a camera at ``P = c + a right + b up - d forward`` (``c`` the arena's
    centre on the floor) sees a corner at across ``x - a``, up ``y - b`` and depth ``z + d``, where (x, y, z) are
    the corner's offset from ``c`` in the camera's axes; it is in the frame when ``|x - a| <= w (z + d)`` and
    ``|y - b| <= h (z + d)``, w and h the frustum's half-width and half-height per unit of depth. For a given
    ``d`` that bounds ``a`` and ``b`` to intervals; the least ``d`` for which both are not empty (bisection) fits
    the arena, and the middle of each interval centres it. The free camera looks at ``c + a right + b up``."""
    low, high = arena_bounds(model, data)
    elevation, azimuth = np.radians(PERSPECTIVE_ELEVATION), np.radians(PERSPECTIVE_AZIMUTH)
    forward = np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    up = np.array([-np.sin(elevation) * np.cos(azimuth), -np.sin(elevation) * np.sin(azimuth), np.cos(elevation)])
    right = np.cross(forward, up)
    half_up = PERSPECTIVE_FILL * np.tan(np.radians(model.vis.global_.fovy) / 2)
    half_across = half_up * width / height
    floor = min(low[2], 0.0)
    corners = np.array(np.meshgrid([low[0], high[0]], [low[1], high[1]], [floor, max(high[2], floor)])).T.reshape(-1, 3)
    centre = np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, floor])
    x, y, z = ((corners - centre) @ axis for axis in (right, up, forward))

    def intervals(d: float) -> tuple[float, float, float, float]:
        depth = z + d
        return (np.max(x - half_across * depth), np.min(x + half_across * depth),
                np.max(y - half_up * depth), np.min(y + half_up * depth))

    def fits(d: float) -> bool:
        a_lo, a_hi, b_lo, b_hi = intervals(d)
        return bool(np.all(z + d > 0) and a_lo <= a_hi and b_lo <= b_hi)

    near, far = 0.0, 1.0
    while not fits(far):
        near, far = far, 2 * far
    for _ in range(60):
        near, far = (near, (near + far) / 2) if fits((near + far) / 2) else ((near + far) / 2, far)
    a_lo, a_hi, b_lo, b_hi = intervals(far)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = centre + (a_lo + a_hi) / 2 * right + (b_lo + b_hi) / 2 * up
    camera.distance = far
    camera.azimuth, camera.elevation = PERSPECTIVE_AZIMUTH, PERSPECTIVE_ELEVATION
    return camera


def camera_name(camera: str) -> str:
    """``top`` and ``perspective`` stay as they are; ``red`` or ``red/track`` mean red's tracking camera."""
    if camera in ("top", PERSPECTIVE) or "/" in camera:
        return camera
    return f"{camera}/track"


def cameras(model: mujoco.MjModel) -> list[str]:
    return [model.camera(k).name for k in range(model.ncam)]


def camera_choices(model: mujoco.MjModel) -> str:
    """The cameras ``--camera`` accepts in this scene, as one phrase."""
    own = [name for name in cameras(model) if not name.endswith("/track")]
    robots = [name.removesuffix("/track") for name in cameras(model) if name.endswith("/track")]
    choices = ", ".join([*own[:1], PERSPECTIVE, *own[1:]])
    return choices + (f", or a robot's name for its tracking camera: {', '.join(robots)}" if robots else "")


def camera_id(model: mujoco.MjModel, camera: str) -> int:
    """The id of ``camera`` (see :func:`camera_name`), ``FREE_CAMERA`` for ``perspective``; ValueError naming the
    scene's cameras if it has none of that name."""
    if camera == PERSPECTIVE:
        return FREE_CAMERA
    found = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera_name(camera))
    if found < 0:
        raise ValueError(f"camera {camera!r} not in the scene; cameras: {camera_choices(model)}")
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

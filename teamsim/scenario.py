"""Scenarios: one typed, validated description of a whole trial (issue 8), read from and written to YAML.

A scenario holds the arena (size, walls, box and cylinder obstacles, bog zones, an optional occupancy image),
the objects (pucks, long heavy boxes), the team (each robot's kind, start pose, builder overrides and controller
settings), the mission's own settings (``task``), radio, positioning, timing, the fault schedule, the duration
and the seed. A mission that supports scenarios (:class:`teamsim.tasks.base.ScenarioMission`) turns its
parameters into one (``scenario``) and builds its scene from one (``scene``); every run of such a mission goes
through its scenario, so running the mission and running its exported scenario are the same trial.

Validation happens here and only here: :func:`load` checks types, unknown keys and ranges (the bounds of each
``setting``), :func:`check` checks the physics before anything is compiled (robots inside obstacles or each
other, objects outside the arena, sizes, IR counts). Every error is one line naming the field and what is
allowed (:class:`teamsim.config.ConfigError`).

YAML is read with a strict loader: duplicate keys are errors, only ``true``/``false`` are booleans and ``1e-3``
is a number (YAML 1.2 rules; PyYAML's YAML 1.1 would read ``yes`` as true and ``1e-3`` as a string).
"""
from __future__ import annotations

import dataclasses
import functools
import importlib
import math
import re
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from teamsim.config import (ConfigError, PositioningConfig, RadioConfig, Timing, TrialConfig, apply_setting,
                            check_value, setting, settable_keys, validate)
from teamsim.faults import FAULT_KINDS, Fault, parse_fault, role_refusal
from teamsim.models import ROBOT_BUILDERS, ROBOT_KINDS, build_robot
from teamsim.models.arenas import OBSTACLE_RGBA, Bog, Box, add_bog, walled_room
from teamsim.models.objects import BoxDims, PuckDims, box, place, place_puck
from teamsim.models.robot import TricycleSpec
from teamsim.scene import RobotSlot, Scene

MAX_EXTENT = 1000.0  # m: bound on every position and size, so that a typo (or inf) is caught as out of range
ROBOT_NAME = re.compile(r"^[A-Za-z0-9_-]+$")  # what a fault spec (ROBOT@...) and an MJCF prefix accept
# Width of one IR sensor on a robot's rim. Not in the theses; the Sharp GP2Y0A21/GP2D12 rangers of that era are
# 44.5 mm wide, so a rim of circumference C holds at most C / 4.5 cm of them.
IR_SENSOR_WIDTH = 0.045
OCCUPIED_BELOW = 128  # an image pixel darker than mid-grey is an obstacle (black = occupied, as maps are shared)


def _part(kind: type, meaning: str) -> Any:
    return field(default_factory=kind, metadata={"meaning": meaning})


def _many(meaning: str) -> Any:
    return field(default_factory=list, metadata={"meaning": meaning})


def _position(default: float, meaning: str) -> Any:
    return setting(default, lo=-MAX_EXTENT, hi=MAX_EXTENT, meaning=meaning)


def _size(default: float, meaning: str) -> Any:
    return setting(default, lo=0.0, open_lo=True, hi=MAX_EXTENT, meaning=meaning)


def _angle(default: float, meaning: str) -> Any:
    return setting(default, lo=-math.tau, hi=math.tau, meaning=meaning)


# -- the schema -------------------------------------------------------------------------------------------------
@dataclass
class Spot:
    x: float = _position(0.0, "centre x, m")
    y: float = _position(0.0, "centre y, m")


@dataclass
class _Rectangle(Spot):
    half_x: float = _size(0.5, "half length along its own x, m")
    half_y: float = _size(0.5, "half length along its own y, m")


@dataclass
class BoxObstacle(_Rectangle):
    """A static box (``teamsim.models.arenas.Box``): same fields."""
    half_z: float = _size(0.25, "half height, m")
    yaw: float = _angle(0.0, "rotation about the vertical, rad")


@dataclass
class Cylinder(Spot):
    """A static upright cylinder (a pillar, a drum)."""
    radius: float = _size(0.25, "radius, m")
    height: float = _size(0.5, "height, m")


@dataclass
class BogZone(_Rectangle):
    """Boggy ground (``teamsim.models.arenas.Bog``, same fields): drag on the robots inside, by their
    traversability."""


@dataclass
class OccupancyImage:
    """Obstacles from a black-and-white picture: each run of dark pixels becomes box obstacles."""
    file: str = setting("", meaning="PNG (or any image OpenCV reads), relative to the scenario file")
    resolution: float = setting(0.05, lo=0.0, open_lo=True, hi=10.0, meaning="m per pixel")
    origin: tuple[float, float] | None = _position(None, "world x, y of the image's lower-left corner, m "
                                                          "(null: the image is centred on the arena)")
    height: float = _size(0.5, "height of the obstacles it gives, m")


@dataclass
class Arena:
    size: tuple[float, float] = _size((10.0, 10.0), "floor x and y extent, m (the room is centred on the origin)")
    walls: bool = setting(True, meaning="walls around the floor")
    wall_height: float = _size(0.5, "m")
    wall_thickness: float = _size(0.1, "m")
    boxes: list[BoxObstacle] = _many("box obstacles")
    cylinders: list[Cylinder] = _many("cylinder obstacles")
    bogs: list[BogZone] = _many("bog zones")
    image: OccupancyImage | None = setting(None, meaning="occupancy image whose dark pixels are obstacles")


@dataclass
class HeavyBox(Spot):
    yaw: float = _angle(0.0, "rotation about the vertical, rad (0: its length along y)")


@dataclass
class Objects:
    pucks: list[Spot] = _many("pucks (Parker §3.8), at their centres")
    boxes: list[HeavyBox] = _many("long heavy boxes (Parker §6.1)")
    puck: PuckDims = _part(PuckDims, "every puck's size (m), mass (kg) and friction")
    box: BoxDims = _part(BoxDims, "every heavy box's size (m), mass (kg) and friction")


@dataclass
class RobotEntry:
    kind: str = setting("diffdrive", choices=ROBOT_KINDS, meaning="robot kind (`teamsim list`)")
    pose: tuple[float, float, float] = _position((0.0, 0.0, 0.0), "start x (m), y (m) and heading (rad)")
    options: dict = field(default_factory=dict, metadata={
        "meaning": "overrides of the kind's dimensions (the Dims class in models/KIND.py), e.g. radius: 0.4"})
    controller: Any = field(default=None, metadata={"of": "Controller", "meaning": "the mission's controller "
                                                                                      "settings for this robot"})


@dataclass
class FaultEntry:
    """A fault (``teamsim.faults``), as ``--fault KIND:ROBOT@TIME,key=value`` writes it."""
    kind: str = setting("kill", choices=FAULT_KINDS, meaning="what goes wrong")
    robot: str = setting("", meaning="the robot it happens to, or @ROLE: whoever holds that role of the mission "
                                     "when it is due (missions that elect roles)")
    time: float = setting(0.0, lo=0.0, hi=1e7, meaning="when, s")
    options: dict = field(default_factory=dict, metadata={"meaning": "the kind's options (`teamsim run --help`)"})


@dataclass
class Scenario:
    mission: str | None = setting(None, meaning="the mission whose rules run it (must match `teamsim run MISSION`)")
    seed: int = setting(0, lo=0, hi=2**63 - 1, meaning="trial seed: every random stream derives from it")
    duration: float | None = setting(None, lo=0.0, open_lo=True, hi=1e7,
                                     meaning="simulated seconds (null: the mission's default)")
    arena: Arena = _part(Arena, "the room")
    objects: Objects = _part(Objects, "movable things that are not robots")
    robots: dict[str, RobotEntry] = field(default_factory=dict, metadata={
        "meaning": "the team, by name; a robot named by an add-robot fault waits outside until then"})
    task: Any = field(default=None, metadata={"of": "Task", "meaning": "the mission's own settings"})
    radio: RadioConfig = _part(RadioConfig, "broadcast radio (Parker §2.2.3)")
    positioning: PositioningConfig = _part(PositioningConfig, "positioning system (Parker §2.2.3)")
    timing: Timing = _part(Timing, "physics and control periods")
    faults: list[FaultEntry] = _many("fault schedule (after any the mission starts with)")


# -- reading: data -> typed objects, every error one line --------------------------------------------------------
def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _name(key: Any) -> str:
    """A key as it reads in a dotted path: plain names bare, anything else quoted."""
    return key if isinstance(key, str) and ROBOT_NAME.match(key) else _show(key)


def _number(path: str, value: Any, kind: type) -> Any:
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{path}: expected a whole number, got {_show(value)}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{path}: expected a number, got {_show(value)}")
    try:
        return float(value)
    except OverflowError:
        raise ConfigError(f"{path}={_show(value)}: too large") from None


def _convert(path: str, kind: Any, value: Any, meta: dict, schema: dict) -> Any:
    """``value`` (plain YAML data) as ``kind``, bounds-checked with ``meta``; ConfigError naming ``path``."""
    if kind is Any:
        kind = schema[meta["of"]]
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        if value is None:
            return None
        kind = next(a for a in args if a is not type(None))
        origin, args = typing.get_origin(kind), typing.get_args(kind)
    if dataclasses.is_dataclass(kind):
        return _object(path, kind, value, schema)
    if kind in (int, float):
        number = _number(path, value, kind)
        check_value(path, number, meta)
        return number
    if kind in (bool, str):
        if not isinstance(value, kind):
            raise ConfigError(f"{path}: expected {'true or false' if kind is bool else 'text'}, got {_show(value)}")
        check_value(path, value, meta)
        return value
    if origin is tuple and len(args) == 2 and args[1] is Ellipsis:  # tuple[X, ...]: a list of any length
        if not isinstance(value, list):
            raise ConfigError(f"{path}: expected a list, got {_show(value)}")
        return tuple(_convert(f"{path}[{k}]", args[0], v, meta, schema) for k, v in enumerate(value))
    if origin is tuple:
        if not isinstance(value, list) or len(value) != len(args):
            raise ConfigError(f"{path}: expected a list of {len(args)} numbers, got {_show(value)}")
        return tuple(_convert(f"{path}[{k}]", a, v, meta, schema) for k, (a, v) in enumerate(zip(args, value)))
    if origin is list:
        if not isinstance(value, list):
            raise ConfigError(f"{path}: expected a list, got {_show(value)}")
        return [_convert(f"{path}[{k}]", args[0], v, meta, schema) for k, v in enumerate(value)]
    if origin is dict or kind is dict:
        if not isinstance(value, dict):
            raise ConfigError(f"{path}: expected a mapping, got {_show(value)}")
        if not args:
            return dict(value)
        for name in value:
            if not isinstance(name, str) or not ROBOT_NAME.match(name):
                raise ConfigError(f"{path}: name {_show(name)}: allowed: letters, digits, '_' and '-'")
        return {name: _convert(f"{path}.{name}", args[1], v, meta, schema) for name, v in value.items()}
    raise TypeError(f"{path}: the schema has a field of unsupported type {kind!r}")


def _object(path: str, cls: type, value: Any, schema: dict) -> Any:
    """A dataclass from a mapping: unknown keys are errors, missing ones take their defaults.

    Plain dataclasses of the models and controllers (no ``setting`` bounds) are checked by one rule: a field
    whose default is positive is a size, mass, rate or period, and must stay positive."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    if not isinstance(value, dict):
        raise ConfigError(f"{path or 'the scenario'}: expected a mapping with keys {', '.join(fields)}; "
                          f"got {_show(value)}")
    prefix = f"{path}." if path else ""
    unknown = [k for k in value if k not in fields]
    if unknown:
        raise ConfigError(f"{prefix}{_name(unknown[0])}: unknown key; allowed: {', '.join(fields)}")
    hints = typing.get_type_hints(cls)
    values = {}
    for name, f in fields.items():
        if name not in value:
            continue
        meta = dict(f.metadata)
        if not meta and isinstance(f.default, (int, float)) and not isinstance(f.default, bool) and f.default > 0:
            meta = {"lo": 0.0, "open_lo": True}
        values[name] = _convert(prefix + name, hints[name], value[name], meta, schema)
    for name, f in fields.items():
        if name not in values and f.metadata.get("of"):
            values[name] = schema[f.metadata["of"]]()
    return cls(**values)


def load(data: Any, mission, base: Path | None = None) -> Scenario:
    """A Scenario from plain data (a parsed YAML document) for ``mission``; an image path is taken relative to
    ``base``. Checks types, keys and ranges; :func:`check` then checks the physics."""
    named = data.get("mission") if isinstance(data, dict) else None
    if named is not None and named != mission.name:  # before the mission's own sections are read
        raise ConfigError(f"mission: the scenario is for {_show(named)}, not {mission.name!r}")
    scenario = _object("", Scenario, data, {"Task": mission.Task, "Controller": mission.Controller})
    scenario.mission = mission.name
    image = scenario.arena.image
    if image is not None:
        if not image.file:
            raise ConfigError("arena.image.file: required (a PNG path)")
        if base is not None and not Path(image.file).is_absolute():
            image.file = str((base / image.file).resolve())
    return scenario


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 booleans and floats, and duplicate keys as errors."""

    def construct_mapping(self, node, deep=False):
        self.flatten_mapping(node)
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                duplicate = key in seen
            except TypeError:
                raise yaml.constructor.ConstructorError(None, None, "a key must be text or a number",
                                                        key_node.start_mark) from None
            if duplicate:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep)


_BOOL, _FLOAT = "tag:yaml.org,2002:bool", "tag:yaml.org,2002:float"
_Loader.yaml_implicit_resolvers = {first: [(tag, rx) for tag, rx in resolvers if tag not in (_BOOL, _FLOAT)]
                                   for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_Loader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))
_Loader.add_implicit_resolver(_FLOAT, re.compile(
    r"^(?:[-+]?(?:[0-9][0-9_]*\.[0-9_]*|\.[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)?|[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+"
    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"), list("-+0123456789."))


def parse_yaml(text: str, where: str) -> Any:
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506  (_Loader is a SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = " ".join(str(exc.problem or exc.context or "").split())
        raise ConfigError(f"{where}: not valid YAML{at}: {problem}") from None
    except (yaml.YAMLError, RecursionError) as exc:
        raise ConfigError(f"{where}: not valid YAML: {' '.join(str(exc).split())}") from None


def read(path: Path) -> Any:
    """The YAML document of a scenario file."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"--scenario {path}: cannot read ({getattr(exc, 'strerror', None) or exc})") from None
    return parse_yaml(text, str(path))


_INDEX = re.compile(r"^([^\[\]]+)((?:\[\d+\])*)$")


def set_path(data: Any, assignment: str) -> Any:
    """Apply ``--set dotted.path=VALUE`` (VALUE in YAML, e.g. ``[1, 2, 0]``) to plain scenario data; missing
    mappings on the way are created, list items are addressed as ``boxes[0]``. Returns the data."""
    key, sep, text = assignment.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ConfigError(f"--set {assignment!r}: expected key=value")
    value = parse_yaml(text, f"--set {key}")
    steps: list = []
    for part in key.split("."):
        match = _INDEX.match(part)
        if not match:
            raise ConfigError(f"--set {key}: expected a dotted path such as robots.red.pose or arena.boxes[0].x")
        steps += [match[1]] + [int(k) for k in re.findall(r"\d+", match[2])]
    root = {"": data}
    holder, slot, where = root, "", "the scenario"
    for k, step in enumerate(steps):
        container = holder[slot]
        if isinstance(step, str):
            if container is None:
                container = holder[slot] = {}
            if not isinstance(container, dict):
                raise ConfigError(f"--set {key}: {where} is not a mapping")
            if k < len(steps) - 1 and step not in container:
                container[step] = {}
            where = step if where == "the scenario" else f"{where}.{step}"
        else:
            if not isinstance(container, list) or not 0 <= step < len(container):
                count = f"a list of {len(container)}" if isinstance(container, list) else "not a list"
                raise ConfigError(f"--set {key}: no item {step} in {where} ({count})")
            where = f"{where}[{step}]"
        holder, slot = container, step
    holder[slot] = value
    return root[""]


# -- writing -----------------------------------------------------------------------------------------------------
def to_data(value: Any) -> Any:
    """Plain YAML-ready data of a scenario (or any part of one): every field, defaults included."""
    if dataclasses.is_dataclass(value):
        return {f.name: to_data(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): to_data(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [to_data(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    return value


class _Dumper(yaml.SafeDumper):
    """Lists of plain values on one line ([x, y, yaw]), and so is each item of a list that is a mapping of plain
    values (a box, a puck, a fault); everything else in block style."""


class _Line(dict):
    """A mapping written on one line."""


def _plain(value) -> bool:
    return not isinstance(value, (dict, list)) or (isinstance(value, list) and all(map(_plain, value)))


def _represent_list(dumper: yaml.SafeDumper, data: list):
    items = [_Line(v) if isinstance(v, dict) and all(map(_plain, v.values())) else v for v in data]
    flow = all(not isinstance(v, (dict, list)) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", items, flow_style=flow)


_Dumper.add_representer(list, _represent_list)
_Dumper.add_representer(_Line, lambda dumper, data: dumper.represent_mapping("tag:yaml.org,2002:map", data,
                                                                             flow_style=True))


def dump(scenario: Scenario) -> str:
    return yaml.dump(to_data(scenario), Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=4096)


# -- the world it describes ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Obstacle:
    """A static obstacle for the physical checks and the navigation maps: a box or a cylinder, and its field."""
    name: str
    x: float
    y: float
    half_x: float = 0.0  # a box's half sides (rotated by yaw); 0 for a cylinder
    half_y: float = 0.0
    yaw: float = 0.0
    radius: float = 0.0  # a cylinder's radius; 0 for a box

    def distance(self, x, y):
        """From points (numbers or arrays) to the obstacle's footprint: 0 inside."""
        dx, dy = x - self.x, y - self.y
        if self.radius:
            return np.maximum(np.hypot(dx, dy) - self.radius, 0.0)
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        along, across = dx * c + dy * s, -dx * s + dy * c
        return np.hypot(np.maximum(np.abs(along) - self.half_x, 0.0), np.maximum(np.abs(across) - self.half_y, 0.0))


def image_boxes(arena: Arena) -> list[tuple[BoxObstacle, str]]:
    """The box obstacles of the arena's occupancy image, each with a name for errors: every maximal vertical
    stack of identical runs of dark pixels is one box (a rectangle drawn in the image comes back as itself)."""
    image = arena.image
    if image is None:
        return []
    import cv2  # noqa: PLC0415  (OpenCV only when a scenario has an image)

    try:
        encoded = np.frombuffer(Path(image.file).read_bytes(), np.uint8)
    except OSError as exc:
        raise ConfigError(f"arena.image.file={image.file!r}: cannot read ({exc.strerror or exc})") from None
    # (decoding from memory: cv2.imread would also print its own warning on a bad file)
    pixels = cv2.imdecode(encoded, cv2.IMREAD_GRAYSCALE) if encoded.size else None
    if pixels is None:
        raise ConfigError(f"arena.image.file={image.file!r}: not an image OpenCV can read")
    rows, cols = pixels.shape
    width, height = cols * image.resolution, rows * image.resolution
    ox, oy = image.origin if image.origin is not None else (-width / 2, -height / 2)
    hx, hy = arena.size[0] / 2, arena.size[1] / 2
    if ox < -hx - 1e-9 or oy < -hy - 1e-9 or ox + width > hx + 1e-9 or oy + height > hy + 1e-9:
        raise ConfigError(f"arena.image: {cols} x {rows} px at {image.resolution:g} m/px is {width:g} x {height:g} m "
                          f"from ({ox:g}, {oy:g}); it must lie inside the arena, x in [{-hx:g}, {hx:g}], "
                          f"y in [{-hy:g}, {hy:g}]")
    occupied = pixels < OCCUPIED_BELOW
    rects, open_runs = [], {}
    for r in range(rows + 1):
        runs = []
        if r < rows:
            edges = np.flatnonzero(np.diff(np.concatenate(([0], occupied[r].astype(np.int8), [0]))))
            runs = list(zip(edges[::2].tolist(), edges[1::2].tolist()))
        still_open = {run: open_runs.pop(run, r) for run in runs}
        rects += [(top, r, c0, c1) for (c0, c1), top in open_runs.items()]
        open_runs = still_open
    res = image.resolution
    return [(BoxObstacle(x=ox + (c0 + c1) * res / 2, y=oy + (2 * rows - r0 - r1) * res / 2, half_x=(c1 - c0) * res / 2,
                         half_y=(r1 - r0) * res / 2, half_z=image.height / 2),
             f"arena.image (pixel rows {r0}-{r1 - 1}, columns {c0}-{c1 - 1})")
            for r0, r1, c0, c1 in sorted(rects)]


def obstacles(arena: Arena) -> list[Obstacle]:
    """Every static obstacle of the arena: its boxes, its image's boxes, its cylinders."""
    named = [(b, f"arena.boxes[{k}]") for k, b in enumerate(arena.boxes)] + image_boxes(arena)
    return ([Obstacle(name, b.x, b.y, b.half_x, b.half_y, b.yaw) for b, name in named]
            + [Obstacle(f"arena.cylinders[{k}]", c.x, c.y, radius=c.radius) for k, c in enumerate(arena.cylinders)])


def scene_of(scenario: Scenario, newcomers: list[tuple[str, str]], physics_dt: float):
    """The Scene a scenario describes (``teamsim.tasks.base.Scene``); robots named in ``newcomers`` (add-robot
    faults' (name, kind)) wait outside the arena until their fault fires."""
    a = scenario.arena
    boxes = [b for b in a.boxes] + [b for b, _ in image_boxes(a)]
    arena = walled_room(*a.size, wall_height=a.wall_height, wall_thickness=a.wall_thickness,
                        obstacles=tuple(Box(**dataclasses.asdict(b)) for b in boxes), physics_dt=physics_dt)
    if not a.walls:
        for side in ("north", "south", "east", "west"):
            arena.find("geom", f"wall_{side}").remove()
    for k, c in enumerate(a.cylinders):
        arena.worldbody.add("geom", name=f"cylinder{k}", type="cylinder", pos=[c.x, c.y, c.height / 2],
                            size=[c.radius, c.height / 2], rgba=OBSTACLE_RGBA)
    bogs = [Bog(**dataclasses.asdict(b)) for b in a.bogs]
    for k, bog in enumerate(bogs):
        add_bog(arena, bog, f"bog{k}")
    things = scenario.objects
    for k, p in enumerate(things.pucks):
        place_puck(arena, f"puck{k}", things.puck, p.x, p.y)
    for k, b in enumerate(things.boxes):
        place(arena, box(f"box{k}", things.box), b.x, b.y, b.yaw)
    joining = {name for name, _ in newcomers}
    slots = [RobotSlot(name, r.kind, *r.pose, dormant=name in joining, options=dict(r.options))
             for name, r in scenario.robots.items()]
    return Scene(arena=arena, robots=slots, bogs=bogs, scenario=scenario)


# -- physical checks -------------------------------------------------------------------------------------------------
def _dims_class(kind: str) -> type:
    """The frozen ``...Dims`` dataclass whose fields a robot kind's builder overrides."""
    module = importlib.import_module(f"teamsim.models.{kind}")
    return next(v for name, v in vars(module).items()
                if name.endswith("Dims") and dataclasses.is_dataclass(v) and v.__module__ == module.__name__)


def _robot_options(path: str, kind: str, options: dict) -> dict:
    """Builder overrides checked against the kind's dimensions: known names, the default's type, and sizes
    (positive defaults) kept positive."""
    defaults = {f.name: f.default for f in dataclasses.fields(_dims_class(kind))}
    checked = {}
    for name, value in options.items():
        where = f"{path}.{_name(name)}"
        if name not in defaults:
            raise ConfigError(f"{where}: unknown option for a {kind}; allowed: {', '.join(defaults)}")
        default = defaults[name]
        if isinstance(default, tuple):
            if not isinstance(value, list) or len(value) != len(default):
                raise ConfigError(f"{where}: expected a list of {len(default)} numbers, got {_show(value)}")
            checked[name] = tuple(_number(f"{where}[{k}]", v, float) for k, v in enumerate(value))
            for k, v in enumerate(checked[name]):
                check_value(f"{where}[{k}]", v, {"lo": -MAX_EXTENT, "hi": MAX_EXTENT})
            continue
        kind_of = int if isinstance(default, int) else float
        checked[name] = _number(where, value, kind_of)
        check_value(where, checked[name], {"lo": 0.0, "open_lo": True, "hi": 1000 if kind_of is int else 1e6}
                    if default > 0 else {"lo": -MAX_EXTENT, "hi": MAX_EXTENT})
    if "ir_count" in checked:  # (every kind with an IR ring of chosen size has a radius: its enclosing circle)
        radius = checked.get("radius", defaults["radius"])
        most = math.floor(2 * math.pi * radius / IR_SENSOR_WIDTH)
        if checked["ir_count"] > most:
            raise ConfigError(f"{path}.ir_count={checked['ir_count']}: must be in [1, {most}] (the rim of a "
                              f"{radius:g} m robot holds one {IR_SENSOR_WIDTH * 100:g} cm IR sensor per "
                              f"{IR_SENSOR_WIDTH * 100:g} cm)")
    return checked


@functools.lru_cache(maxsize=256)
def _footprint(kind: str, options: tuple) -> tuple[float, float]:
    """(enclosing radius, its centre's offset ahead of the pose) of a robot kind with builder options."""
    try:
        model = build_robot(kind, "probe", **dict(options))
    except (ValueError, ArithmeticError) as exc:
        raise ConfigError(str(exc)) from None
    offset = model.drive.wheelbase / 2 if isinstance(model.drive, TricycleSpec) else 0.0
    return model.footprint_radius, offset


def check(scenario: Scenario, faults: list[Fault], roles: dict | None = None) -> None:
    """The physics of a scenario, before anything is compiled: sizes, robots clear of the walls, obstacles,
    objects and each other, objects inside the arena, IR counts that fit their robots, faults that name robots
    of the team or roles of the mission (``roles``: its ``fault_roles``, resolved at run time). ``faults`` is the
    whole schedule (the scenario's and the command line's)."""
    a = scenario.arena
    hx, hy = a.size[0] / 2, a.size[1] / 2
    inside = f"inside the {a.size[0]:g} x {a.size[1]:g} m arena"

    def within(path: str, x: float, y: float, margin: float | tuple[float, float], what: str) -> None:
        """(x, y) with ``margin`` (or one per axis: how far the thing reaches either side) inside the arena."""
        margins = margin if isinstance(margin, tuple) else (margin, margin)
        for axis, v, half, reach in (("x", x, hx, margins[0]), ("y", y, hy, margins[1])):
            if reach > half + 1e-9:
                raise ConfigError(f"{path}: does not fit {inside}: {2 * reach:g} m across along {axis}")
            if abs(v) > half - reach + 1e-9:
                raise ConfigError(f"{path}: {axis}={v:g} must be in [{reach - half:g}, {half - reach:g}] "
                                  f"({what} {inside})")

    for group in ("boxes", "cylinders", "bogs"):
        for k, thing in enumerate(getattr(a, group)):
            within(f"arena.{group}[{k}]", thing.x, thing.y, 0.0, "its centre")
    world = obstacles(a)
    things = scenario.objects
    for k, p in enumerate(things.pucks):
        within(f"objects.pucks[{k}]", p.x, p.y, things.puck.radius, f"a puck of radius {things.puck.radius:g} m")
    solid = list(world) + [Obstacle(f"objects.pucks[{k}]", p.x, p.y, radius=things.puck.radius)
                           for k, p in enumerate(things.pucks)]
    for k, b in enumerate(things.boxes):
        half = Obstacle("", b.x, b.y, things.box.depth / 2, things.box.length / 2, b.yaw)
        reach = (abs(half.half_x * math.cos(b.yaw)) + abs(half.half_y * math.sin(b.yaw)),
                 abs(half.half_x * math.sin(b.yaw)) + abs(half.half_y * math.cos(b.yaw)))
        within(f"objects.boxes[{k}]", b.x, b.y, reach, "the whole box")
        solid.append(dataclasses.replace(half, name=f"objects.boxes[{k}]"))

    if not scenario.robots:
        raise ConfigError("robots: a scenario needs at least one robot")
    placed: list[tuple[str, float, float, float]] = []
    for name, robot in scenario.robots.items():
        path = f"robots.{name}"
        if robot.kind not in ROBOT_BUILDERS:
            raise ConfigError(f"{path}.kind={robot.kind!r}: not available; available: {', '.join(ROBOT_BUILDERS)}")
        options = _robot_options(f"{path}.options", robot.kind, robot.options)
        radius, offset = _footprint(robot.kind, tuple(sorted(options.items())))
        x, y, yaw = robot.pose
        cx, cy = x + offset * math.cos(yaw), y + offset * math.sin(yaw)
        within(f"{path}.pose", cx, cy, radius, f"the centre of a {radius:g} m robot")
        for thing in solid:
            if thing.distance(cx, cy) < radius:
                raise ConfigError(f"{path}.pose: the robot (radius {radius:g} m) overlaps {thing.name}; its centre "
                                  f"must be at least {radius:g} m from it")
        for other, ox, oy, r in placed:
            gap = math.hypot(cx - ox, cy - oy)
            if gap < radius + r:
                raise ConfigError(f"{path}.pose: overlaps robots.{other} (centres {gap:.3g} m apart; must be at "
                                  f"least {radius + r:.3g} m)")
        placed.append((name, cx, cy, radius))

    team = ", ".join(scenario.robots)
    for k, fault in enumerate(faults):
        spec = f"faults[{k}] {fault.kind}:{fault.robot}@{fault.time:g}"
        if fault.role is not None:
            if fault.role not in (roles or {}):
                raise ConfigError(f"{spec}: {role_refusal(scenario.mission or 'this mission', fault.role, roles)}")
            continue
        robot = scenario.robots.get(fault.robot)
        if robot is None:
            extra = " (a newcomer needs its kind and pose in robots)" if fault.kind == "add-robot" else ""
            raise ConfigError(f"{spec}: no robot {fault.robot!r}; team: {team}{extra}")
        if fault.kind == "add-robot" and fault.options.get("kind") != robot.kind:
            raise ConfigError(f"{spec}: kind={fault.options.get('kind')} but robots.{fault.robot}.kind is "
                              f"{robot.kind}; allowed: {robot.kind}")


def _fault(k: int, entry: FaultEntry) -> Fault:
    """A fault entry as a Fault, through the ``--fault`` parser (one set of rules for options)."""
    for key, value in entry.options.items():
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            raise ConfigError(f"faults[{k}].options.{_name(key)}: expected text or a number, got {_show(value)}")
    spec = f"{entry.kind}:{entry.robot}@{entry.time!r}" + "".join(f",{key}={value}"
                                                                  for key, value in entry.options.items())
    try:
        return parse_fault(spec)
    except ConfigError as exc:
        reason = str(exc).split("': ", 1)[-1]
        raise ConfigError(f"faults[{k}] ({_show(spec)}): {reason}") from None


# -- scenarios and trial configurations ------------------------------------------------------------------------------
def supports(mission) -> bool:
    """Whether a mission describes its worlds as scenarios (``teamsim.tasks.base.ScenarioMission``)."""
    return all(callable(getattr(mission, name, None)) for name in ("scenario", "scene"))


def not_supported(mission) -> ConfigError:
    return ConfigError(f"{mission.name}: scenarios are not supported yet (the mission must provide scenario(params, "
                       f"rng, newcomers) and scene(scenario, newcomers, physics_dt), with Task and Controller "
                       f"settings classes; see docs/scenarios.md)")


def generate(config: TrialConfig, mission) -> Scenario:
    """The scenario a run of ``config`` uses: the world the mission makes of its parameters (from the trial
    seed's layout stream, as the world would draw it), with the config's trial-wide settings. Its faults are
    the mission's own; ``config.faults`` stay the caller's to add."""
    if not supports(mission):
        raise not_supported(mission)
    from teamsim.rng import RandomStreams  # noqa: PLC0415

    newcomers = [(f.robot, f.options["kind"]) for f in config.faults if f.kind == "add-robot"]
    world = mission.scenario(config.params, RandomStreams(config.seed).get("mission", "layout"), newcomers)
    default = getattr(mission, "duration_of", lambda params: mission.default_duration)(config.params)
    # A mission may set the radio from its parameters (the janitorial mission's rho, Parker §6.2.3).
    radio = getattr(mission, "radio_of", lambda params, radio: radio)(config.params, config.radio)
    scenario = dataclasses.replace(world, mission=config.mission, seed=config.seed,
                                   duration=config.duration or default, timing=config.timing,
                                   radio=radio, positioning=config.positioning)
    return load(to_data(scenario), mission)  # as a file would give it: plain floats, tuples, checked ranges


def config_of(scenario: Scenario, mission, like: TrialConfig, extra_faults: list[Fault]) -> TrialConfig:
    """The trial configuration that runs ``scenario`` (physically checked), with ``extra_faults`` after the
    scenario's own and the output settings (out, run id, video) of ``like``. The config holds the seed, the
    duration, timing, radio, positioning and the faults; its ``scenario`` holds the world (faults emptied)."""
    faults = [_fault(k, entry) for k, entry in enumerate(scenario.faults)] + list(extra_faults)
    if hasattr(mission, "fault_targets"):  # a mission may let faults name robots by role ("kill:planner@60")
        faults = mission.fault_targets(scenario, faults)
    check(scenario, faults, getattr(mission, "fault_roles", {}))
    extra_check = getattr(mission, "check_scenario", None)
    if extra_check is not None:
        extra_check(scenario)
    return dataclasses.replace(like, mission=mission.name, seed=scenario.seed, duration=scenario.duration,
                               timing=scenario.timing, radio=scenario.radio, positioning=scenario.positioning,
                               faults=faults, scenario=dataclasses.replace(scenario, faults=[]))


SCENARIO_FIELDS = tuple(f.name for f in dataclasses.fields(Scenario))


def configure(mission, like: TrialConfig, scenario_file: Path | None, seed: int | None, duration: float | None,
              settings: list[str], faults: list[str]) -> TrialConfig:
    """The trial configuration of a run, for a mission that supports scenarios, in the command line's precedence
    (teamsim/cli/scenario.py): the file (or the world the mission makes of ``like``'s parameters), then ``seed`` and
    ``duration``, then each ``KEY=VALUE`` of ``settings`` in order, then ``faults`` (specs) after the scenario's.
    ``like`` holds the run's other settings (mission parameters, output folder, video)."""
    if not supports(mission):
        raise not_supported(mission)
    parsed = [parse_fault(spec) for spec in faults]
    legacy = set(settable_keys(like)) if not scenario_file else set()
    paths = []
    for assignment in settings:
        key = assignment.partition("=")[0].strip()
        bare_unknown = not scenario_file and key.isidentifier() and key not in SCENARIO_FIELDS
        if key.startswith("video.") or key in legacy or bare_unknown:
            apply_setting(like, assignment)  # (a bare unknown key gets its error listing the settable keys)
        else:
            paths.append(assignment)
    validate(like)
    if scenario_file:
        data, base = read(scenario_file), Path(scenario_file).parent
        for name, value in (("seed", seed), ("duration", duration)):
            if value is not None:
                if not isinstance(data, dict):
                    raise ConfigError(f"{scenario_file}: expected a mapping of scenario fields")
                data[name] = value
        like = dataclasses.replace(like, params=None)  # the file, not the mission's parameters, is the world
    else:
        data, base = to_data(generate(dataclasses.replace(like, faults=parsed), mission)), None
    for assignment in paths:
        data = set_path(data, assignment)
    return config_of(load(data, mission, base), mission, like, parsed)


def resolve(config: TrialConfig, mission) -> TrialConfig:
    """``config`` with its scenario: the one it has, or the one the mission generates (missions without
    scenario support run as they are)."""
    if config.scenario is not None or not supports(mission):
        return config
    return config_of(generate(config, mission), mission, config, config.faults)


def scenario_of(config: TrialConfig, mission) -> Scenario:
    """The complete scenario a resolved config runs: what ``teamsim scenario show`` prints and summary.json
    records."""
    return dataclasses.replace(config.scenario, mission=config.mission, seed=config.seed,
                               duration=config.duration or mission.default_duration, timing=config.timing,
                               radio=config.radio, positioning=config.positioning,
                               faults=[FaultEntry(**f.describe()) for f in config.faults])

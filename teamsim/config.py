"""Typed, validated configuration: every tunable of a trial, with its default next to its meaning.

A field is declared with :func:`setting`, which records its bounds and a one-line meaning. :func:`validate`
checks a whole (nested) configuration, and :func:`apply_setting` parses one ``--set key=value`` into it. Both
raise :class:`ConfigError` with a one-line message naming the field and what is allowed.
"""
from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass, field
from typing import Any


class ConfigError(ValueError):
    """Bad configuration; the message names the field and what is allowed."""


def setting(default: Any, *, lo: float | None = None, hi: float | None = None, choices: tuple = (),
            open_lo: bool = False, meaning: str = "") -> Any:
    """A validated dataclass field. ``lo``/``hi`` bound numbers (``open_lo`` excludes ``lo``)."""
    meta = {"lo": lo, "hi": hi, "choices": choices, "open_lo": open_lo, "meaning": meaning}
    return field(default=default, metadata=meta)


@dataclass
class Timing:
    physics_dt: float = setting(0.002, lo=1e-4, hi=0.02,
                                meaning="physics timestep, s (stable wheel, gripper, leg contacts)")
    control_dt: float = setting(0.1, lo=0.01, hi=1.0,
                                meaning="sensing/control period, s (Chand's explorers ran at 10 Hz)")
    energy_dt: float = setting(0.01, lo=1e-4, hi=1.0, meaning="actuator power sampling period for energy, s")


@dataclass
class RadioConfig:
    """Parker §2.2.3: one 10-byte broadcast per robot every 3 s, so rate 1/3 Hz and timeout tau = 3/rate."""
    rate_hz: float = setting(1 / 3, lo=0.0, open_lo=True, hi=100.0, meaning="broadcasts per second per robot")
    latency: float = setting(0.0, lo=0.0, hi=60.0, meaning="delivery delay, s")
    loss: float = setting(0.0, lo=0.0, hi=1.0, meaning="probability a message is lost, per receiver")
    range: float = setting(math.inf, lo=0.0, meaning="maximum sender-receiver distance, m")
    timeout_periods: float = setting(3.0, lo=1.0, hi=100.0, meaning="tau in broadcast periods (tau = 3/rate)")

    @property
    def timeout(self) -> float:
        return self.timeout_periods / self.rate_hz


@dataclass
class PositioningConfig:
    """Parker §2.2.3: x,y updated every 600 ms, accurate to 1/2 in still and about 6 in while moving.

    The thesis gives accuracies, not distributions: we read them as the standard deviation of Gaussian noise
    on each axis. It gives no heading source; the thesis simulator had a compass (§2.1), so a heading with
    its own noise is provided.
    """
    period: float = setting(0.6, lo=0.0, open_lo=True, hi=60.0, meaning="update period, s")
    noise_still: float = setting(0.0127, lo=0.0, hi=10.0, meaning="position std dev per axis when still, m")
    noise_moving: float = setting(0.15, lo=0.0, hi=10.0, meaning="position std dev per axis when moving, m")
    moving_speed: float = setting(0.02, lo=0.0, hi=10.0, meaning="speed above which a robot counts as moving, m/s")
    heading_noise: float = setting(0.05, lo=0.0, hi=math.pi, meaning="compass std dev, rad")


@dataclass
class VideoConfig:
    enabled: bool = setting(False, meaning="render video.mp4 while running")
    fps: int = setting(30, lo=1, hi=120, meaning="video frame rate (also the trajectory sampling rate)")
    width: int = setting(640, lo=64, hi=3840, meaning="frame width, px (even: H.264 in yuv420p)")
    height: int = setting(480, lo=48, hi=2160, meaning="frame height, px (even: H.264 in yuv420p)")
    camera: str = setting("top", meaning="camera: 'top', 'perspective' (the whole arena, oblique) or ROBOT "
                                         "(its tracking camera, also ROBOT/track)")
    speedup: float | None = setting(None, lo=1.0, hi=1000.0,
                                    meaning="simulated seconds per second of video, a time-lapse (unset: the "
                                            "mission's default, 1 for most)")

    def check(self) -> None:
        for name in ("width", "height"):
            if getattr(self, name) % 2:
                raise ConfigError(f"video.{name}={getattr(self, name)}: must be even (H.264 in yuv420p)")

    @staticmethod
    def parse_size(text: str) -> tuple[int, int]:
        """``WIDTHxHEIGHT`` (``1280x720``) as (width, height), within the width and height bounds and even;
        else ConfigError, one line, naming ``--video-size`` and what it allows."""
        bounds = {f.name: (f.metadata["lo"], f.metadata["hi"]) for f in dataclasses.fields(VideoConfig)
                  if f.name in ("width", "height")}
        (w_lo, w_hi), (h_lo, h_hi) = bounds["width"], bounds["height"]
        allowed = f"allowed: WIDTHxHEIGHT, even whole pixels, width {w_lo}-{w_hi}, height {h_lo}-{h_hi} (e.g. 1280x720)"
        width, x, height = text.strip().lower().partition("x")
        if not (x and all(side.isascii() and side.isdigit() for side in (width, height))):
            raise ConfigError(f"--video-size: {text!r} is not WIDTHxHEIGHT; {allowed}")
        size = int(width), int(height)
        if not (w_lo <= size[0] <= w_hi and h_lo <= size[1] <= h_hi):
            raise ConfigError(f"--video-size: {text} is out of range; {allowed}")
        if size[0] % 2 or size[1] % 2:
            raise ConfigError(f"--video-size: {text} has an odd side (H.264 in yuv420p needs even ones); {allowed}")
        return size


@dataclass
class TrialConfig:
    """Everything that defines one trial. ``params`` is the mission's own parameter dataclass."""
    mission: str
    params: Any
    seed: int = setting(0, lo=0, hi=2**63 - 1, meaning="trial seed; every random stream derives from it")
    duration: float | None = setting(None, lo=0.0, open_lo=True, hi=1e7,
                                     meaning="simulated seconds (mission default if unset)")
    out: str = setting("renders", meaning="output root; a run writes OUT/<mission>/<run-id>/")
    run_id: str | None = setting(None, meaning="run folder name (default: seed and a timestamp)")
    timing: Timing = field(default_factory=Timing)
    radio: RadioConfig = field(default_factory=RadioConfig)
    positioning: PositioningConfig = field(default_factory=PositioningConfig)
    video: VideoConfig = field(default_factory=VideoConfig)
    faults: list = field(default_factory=list)
    # The world a scenario describes (teamsim.scenario.Scenario: arena, objects, team, task; its faults are in
    # ``faults``), or None: the mission builds its world from ``params``.
    scenario: Any = None


def check_value(name: str, value: Any, meta: dict) -> None:
    """Check one value against a field's bounds and choices (ConfigError naming ``name``); a tuple of numbers (a
    range such as ``(5.0, 7.0)``) item by item."""
    if isinstance(value, tuple) and not meta.get("choices"):
        for k, item in enumerate(value):
            check_value(f"{name}[{k}]", item, meta)
        return
    if meta.get("choices") and value not in meta["choices"]:
        raise ConfigError(f"{name}={value!r}: allowed values are {', '.join(map(str, meta['choices']))}")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return
    if isinstance(value, float) and math.isnan(value):
        raise ConfigError(f"{name}: NaN is not allowed")
    lo, hi = meta.get("lo"), meta.get("hi")
    below = lo is not None and (value <= lo if meta.get("open_lo") else value < lo)
    if below or (hi is not None and value > hi):
        low = "-inf" if lo is None else f"{lo:g}"
        bracket = "(" if meta.get("open_lo") else "["
        high = "inf" if hi is None else f"{hi:g}"
        raise ConfigError(f"{name}={value!r}: must be in {bracket}{low}, {high}]")


def validate(obj: Any, prefix: str = "") -> None:
    """Check every field of a (nested) configuration dataclass against its bounds."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        name = prefix + f.name
        if dataclasses.is_dataclass(value):
            validate(value, "" if f.name == "params" else name + ".")
        elif value is not None:
            check_value(name, value, f.metadata)
    post = getattr(obj, "check", None)
    if callable(post):
        post()


def _parse_scalar(name: str, text: str, kind: Any, example: str = "") -> Any:
    """Parse ``text`` as ``kind``: bool, int, float, str, a tuple of those (``5,7`` or ``[5, 7]``; ``example`` shows
    one in the error), or Optional of one of those."""
    if typing.get_origin(kind) in (typing.Union, types.UnionType):  # Optional[X]
        if text.lower() in ("none", "null", ""):
            return None
        kind = next(a for a in typing.get_args(kind) if a is not type(None))
    if typing.get_origin(kind) is tuple:
        args = typing.get_args(kind)
        items = text.removeprefix("[").removesuffix("]").split(",")
        expected = (f"expected {len(args)} values separated by commas, each {_EXPECTED.get(args[0], 'text')}"
                    + (f", e.g. {example}" if example else ""))
        if len(items) != len(args) or Ellipsis in args:
            raise ConfigError(f"--set {name}={text}: {expected}")
        try:
            return tuple(_parse_scalar(name, item.strip(), arg) for item, arg in zip(items, args))
        except ConfigError:
            raise ConfigError(f"--set {name}={text}: {expected}") from None
    try:
        if kind is bool:
            lowered = text.lower()
            if lowered in ("1", "true", "yes", "on"):
                return True
            if lowered in ("0", "false", "no", "off"):
                return False
            raise ValueError
        if kind is int:
            return int(text)
        if kind is float:
            return float(text)
    except ValueError:
        raise ConfigError(f"--set {name}={text}: expected {_EXPECTED[kind]}") from None
    return text


_EXPECTED = {bool: "true or false", int: "an integer", float: "a number"}


def settable_keys(cfg: TrialConfig) -> list[str]:
    """Every key ``--set`` accepts: the mission's own parameters bare, the others dotted."""
    keys = [f.name for f in dataclasses.fields(cfg.params)]
    for group in ("timing", "radio", "positioning", "video"):
        keys += [f"{group}.{f.name}" for f in dataclasses.fields(getattr(cfg, group))]
    return keys


def apply_setting(cfg: TrialConfig, assignment: str) -> None:
    """Apply one ``key=value`` to ``cfg`` in place, with type coercion and bounds checking."""
    key, sep, text = assignment.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ConfigError(f"--set {assignment!r}: expected key=value")
    group, dot, leaf = key.rpartition(".")
    target = getattr(cfg, group, None) if dot else cfg.params
    fields = {f.name: f for f in dataclasses.fields(target)} if dataclasses.is_dataclass(target) else {}
    if group in ("params",) or leaf not in fields:
        raise ConfigError(f"--set {key}: unknown key for mission {cfg.mission!r}; "
                          f"allowed: {', '.join(settable_keys(cfg))}")
    kind = typing.get_type_hints(type(target))[leaf]
    if dataclasses.is_dataclass(kind):  # (a mission's group of behaviour constants: its robots' controller settings)
        raise ConfigError(f"--set {key}: a group of settings, not one value; allowed: each of its fields by its "
                          f"scenario path (`teamsim scenario show {cfg.mission}` lists them)")
    default = fields[leaf].default
    example = ",".join(map(str, default)) if isinstance(default, tuple) else ""
    value = _parse_scalar(key, text.strip(), kind, example)
    check_value(key, value, fields[leaf].metadata)
    setattr(target, leaf, value)

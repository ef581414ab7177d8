"""Unit tests for teamsim.config: apply_setting, validate and value parsing."""
from __future__ import annotations

import copy
import math

import pytest

from teamsim.config import ConfigError, RadioConfig, TrialConfig, apply_setting, settable_keys, validate
from teamsim.tasks import MISSIONS


@pytest.fixture
def cfg() -> TrialConfig:
    mission = MISSIONS["wander"]
    return TrialConfig(mission="wander", params=mission.Params())


def error_message(cfg, assignment: str) -> str:
    before = copy.deepcopy(cfg)
    with pytest.raises(ConfigError) as info:
        apply_setting(cfg, assignment)
    message = str(info.value)
    assert "\n" not in message and "\r" not in message, message
    assert cfg == before, "a rejected setting must leave the configuration unchanged"
    return message


def test_default_config_is_valid(cfg):
    validate(cfg)


# ---------------------------------------------------------------- accepted settings


def test_set_mission_parameter(cfg):
    apply_setting(cfg, "robots=5")
    assert cfg.params.robots == 5
    assert type(cfg.params.robots) is int


def test_set_radio_loss(cfg):
    apply_setting(cfg, "radio.loss=0.2")
    assert cfg.radio.loss == 0.2
    assert type(cfg.radio.loss) is float


@pytest.mark.parametrize("assignment, getter, expected", [
    ("radio.rate_hz=2", lambda c: c.radio.rate_hz, 2.0),
    ("radio.range=inf", lambda c: c.radio.range, math.inf),
    ("radio.latency=0", lambda c: c.radio.latency, 0.0),
    ("radio.loss=1", lambda c: c.radio.loss, 1.0),
    ("timing.control_dt=0.05", lambda c: c.timing.control_dt, 0.05),
    ("positioning.noise_moving=0.3", lambda c: c.positioning.noise_moving, 0.3),
    ("video.fps=60", lambda c: c.video.fps, 60),
    ("video.camera=red/track", lambda c: c.video.camera, "red/track"),
    ("room_size=12.5", lambda c: c.params.room_size, 12.5),
    ("obstacles=0", lambda c: c.params.obstacles, 0),
    ("kind=diffdrive", lambda c: c.params.kind, "diffdrive"),
    ("  robots = 7 ", lambda c: c.params.robots, 7),
    ("robots=200", lambda c: c.params.robots, 200),  # upper bound inclusive
])
def test_set_various(cfg, assignment, getter, expected):
    apply_setting(cfg, assignment)
    assert getter(cfg) == expected


def test_setting_changes_only_its_own_field(cfg):
    before = copy.deepcopy(cfg)
    apply_setting(cfg, "radio.loss=0.2")
    before.radio.loss = 0.2
    assert cfg == before


def test_radio_setting_reaches_timeout_property(cfg):
    apply_setting(cfg, "radio.rate_hz=0.5")
    apply_setting(cfg, "radio.timeout_periods=4")
    assert cfg.radio.timeout == pytest.approx(8.0)


@pytest.mark.parametrize("text, value", [
    ("true", True), ("True", True), ("TRUE", True), ("1", True), ("yes", True), ("on", True),
    ("false", False), ("False", False), ("0", False), ("no", False), ("off", False), ("OFF", False),
])
def test_bool_parsing(cfg, text, value):
    cfg.video.enabled = not value
    apply_setting(cfg, f"video.enabled={text}")
    assert cfg.video.enabled is value


@pytest.mark.parametrize("text", ["maybe", "2", "", "truth", "y"])
def test_bool_rejects_other_words(cfg, text):
    message = error_message(cfg, f"video.enabled={text}")
    assert "video.enabled" in message and "true or false" in message


def test_settable_keys(cfg):
    keys = settable_keys(cfg)
    assert {"robots", "room_size", "obstacles", "kind", "radio.loss", "radio.rate_hz", "timing.physics_dt",
            "positioning.period", "video.enabled"} <= set(keys)
    for key in keys:
        assert not key.startswith("params.")


# ---------------------------------------------------------------- rejected settings


@pytest.mark.parametrize("key", ["robtos", "radio.los", "radio", "params.robots", "timing.radio.loss",
                                 "mission.x", "faults.x", "seed", "radio.timeout", "nosuch.loss"])
def test_unknown_key(cfg, key):
    message = error_message(cfg, f"{key}=1")
    assert key in message
    assert "unknown key" in message
    assert "radio.loss" in message  # lists what is allowed


@pytest.mark.parametrize("assignment", ["robots", "=5", "", "  =1"])
def test_not_key_value(cfg, assignment):
    message = error_message(cfg, assignment)
    assert "key=value" in message


@pytest.mark.parametrize("assignment, key, expected", [
    ("robots=abc", "robots", "an integer"),
    ("robots=2.5", "robots", "an integer"),
    ("robots=", "robots", "an integer"),
    ("obstacles=three", "obstacles", "an integer"),
    ("radio.loss=abc", "radio.loss", "a number"),
    ("radio.loss=", "radio.loss", "a number"),
    ("video.fps=30.0", "video.fps", "an integer"),
])
def test_wrong_type(cfg, assignment, key, expected):
    message = error_message(cfg, assignment)
    assert key in message and expected in message


@pytest.mark.parametrize("assignment, key", [
    ("radio.loss=2", "radio.loss"),
    ("radio.loss=-0.1", "radio.loss"),
    ("radio.loss=nan", "radio.loss"),
    ("radio.rate_hz=0", "radio.rate_hz"),     # open lower bound
    ("radio.rate_hz=-1", "radio.rate_hz"),
    ("radio.range=-1", "radio.range"),
    ("radio.timeout_periods=0.5", "radio.timeout_periods"),
    ("robots=0", "robots"),
    ("robots=201", "robots"),
    ("timing.physics_dt=1", "timing.physics_dt"),
    ("positioning.period=0", "positioning.period"),
    ("video.width=10", "video.width"),
    ("kind=legged", "kind"),
])
def test_out_of_range(cfg, assignment, key):
    message = error_message(cfg, assignment)
    assert key in message
    assert "must be in" in message or "allowed values" in message or "NaN" in message


def test_out_of_range_message_states_bounds(cfg):
    message = error_message(cfg, "radio.loss=2")
    assert "radio.loss" in message and "[0, 1]" in message
    message = error_message(cfg, "radio.rate_hz=0")
    assert "(0, 100]" in message


# ---------------------------------------------------------------- validate


@pytest.mark.parametrize("mutate, key", [
    (lambda c: setattr(c.radio, "loss", 2.0), "radio.loss"),
    (lambda c: setattr(c.radio, "latency", -1.0), "radio.latency"),
    (lambda c: setattr(c.positioning, "noise_still", float("nan")), "positioning.noise_still"),
    (lambda c: setattr(c.timing, "control_dt", 0.0), "timing.control_dt"),
    (lambda c: setattr(c.video, "fps", 0), "video.fps"),
    (lambda c: setattr(c.params, "robots", 0), "robots"),
    (lambda c: setattr(c.params, "kind", "tank"), "kind"),
    (lambda c: setattr(c, "seed", -1), "seed"),
    (lambda c: setattr(c, "duration", 0.0), "duration"),
])
def test_validate_catches_bad_value(cfg, mutate, key):
    mutate(cfg)
    with pytest.raises(ConfigError) as info:
        validate(cfg)
    message = str(info.value)
    assert key in message
    assert "\n" not in message


def test_validate_runs_mission_check(cfg):
    cfg.params.robots = 30
    cfg.params.room_size = 6.0  # 5 x 5 spawn cells: 30 robots + 3 obstacles do not fit
    with pytest.raises(ConfigError) as info:
        validate(cfg)
    assert "room_size" in str(info.value)
    assert "\n" not in str(info.value)


def test_validate_standalone_group():
    validate(RadioConfig())
    with pytest.raises(ConfigError, match="loss"):
        validate(RadioConfig(loss=1.5))


def test_validate_allows_unset_optionals(cfg):
    cfg.duration = None
    cfg.run_id = None
    validate(cfg)
    cfg.duration = 30.0
    validate(cfg)

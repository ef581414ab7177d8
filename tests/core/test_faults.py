"""Unit tests for teamsim.faults: parsing --fault specs and applying them to Health."""
from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamsim.config import ConfigError
from teamsim.faults import FAULT_KINDS, FAULT_OPTIONS, SPEC_FORM, Fault, Health, apply_fault, parse_fault

MOTORS = ("left", "right")


# ---------------------------------------------------------------- parsing valid specs


@pytest.mark.parametrize("spec, kind, robot, time, options", [
    ("kill:red@60", "kill", "red", 60.0, {}),
    ("blind-ir:green@30", "blind-ir", "green", 30.0, {}),
    ("radio-off:blue@0", "radio-off", "blue", 0.0, {}),
    ("radio-on:blue@12.5", "radio-on", "blue", 12.5, {}),
    ("slow:red@10,factor=0.5", "slow", "red", 10.0, {"factor": 0.5}),
    ("slow:red@10,factor=1", "slow", "red", 10.0, {"factor": 1.0}),
    ("slow:red@10", "slow", "red", 10.0, {"factor": 0.5}),                      # default factor
    ("break-motor:red@5,motor=left", "break-motor", "red", 5.0, {"motor": "left"}),
    ("break-motor:red@5", "break-motor", "red", 5.0, {}),                        # default: first motor
    ("break-gripper:Robot_2@1e2", "break-gripper", "Robot_2", 100.0, {}),
    ("add-robot:purple@20,kind=diffdrive", "add-robot", "purple", 20.0, {"kind": "diffdrive"}),
    ("add-robot:purple@20", "add-robot", "purple", 20.0, {"kind": "diffdrive"}),  # default kind
    ("  kill:red@60  ", "kill", "red", 60.0, {}),                                # surrounding blanks
])
def test_parse_valid(spec, kind, robot, time, options):
    fault = parse_fault(spec)
    assert fault == Fault(kind, robot, time, options)
    assert isinstance(fault.time, float)
    described = fault.describe()
    # The fault's own kind must survive even when an option is also called "kind" (add-robot).
    assert (described["kind"], described["robot"], described["time"]) == (kind, robot, time)


@st.composite
def fault_specs(draw):
    kind = draw(st.sampled_from(FAULT_KINDS))
    robot = draw(st.from_regex(r"[A-Za-z0-9_][A-Za-z0-9_-]{0,11}", fullmatch=True))
    time = draw(st.floats(min_value=0.0, max_value=1e6, allow_nan=False, allow_infinity=False))
    options = {}
    if kind == "slow" and draw(st.booleans()):
        options["factor"] = draw(st.floats(min_value=1e-6, max_value=1.0))
    if kind == "break-motor" and draw(st.booleans()):
        options["motor"] = draw(st.from_regex(r"[a-z][a-z_0-9]{0,9}", fullmatch=True))
    if kind == "add-robot" and draw(st.booleans()):
        options["kind"] = draw(st.sampled_from(["diffdrive", "legged", "gripper_bot"]))
    return kind, robot, time, options


@settings(max_examples=300, deadline=None)
@given(fault_specs())
def test_parse_round_trip(parts):
    kind, robot, time, options = parts
    spec = f"{kind}:{robot}@{time!r}" + "".join(f",{k}={v!r}" if isinstance(v, float) else f",{k}={v}"
                                                  for k, v in options.items())
    fault = parse_fault(spec)
    defaults = {k: d for k, (_, d, _) in FAULT_OPTIONS[kind].items() if d is not None}
    assert fault.kind == kind
    assert fault.robot == robot
    assert fault.time == time
    assert fault.options == {**defaults, **options}


# ---------------------------------------------------------------- rejecting malformed specs


def parse_error(spec: str) -> str:
    with pytest.raises(ConfigError) as info:
        parse_fault(spec)
    message = str(info.value)
    assert "\n" not in message and "\r" not in message, message
    assert message.strip(), "empty message"
    return message


@pytest.mark.parametrize("spec", ["kill:red60", "kill:red", "killred@60", "", "kill:@60", ":red@60",
                                  "kill:red@", "kill:red@60,factor", "Kill:red@60"])
def test_rejects_malformed_form(spec):
    message = parse_error(spec)
    assert SPEC_FORM in message


def test_missing_at_names_expected_form():
    message = parse_error("kill:red60")
    assert "'kill:red60'" in message
    assert "KIND:ROBOT@SECONDS" in message


@pytest.mark.parametrize("kind", ["explode", "stop", "kil", "radio"])
def test_rejects_unknown_kind(kind):
    message = parse_error(f"{kind}:red@60")
    assert f"unknown kind {kind!r}" in message
    for allowed in FAULT_KINDS:
        assert allowed in message


@pytest.mark.parametrize("time", ["-1", "-0.5", "-1e-9"])
def test_rejects_negative_time(time):
    message = parse_error(f"kill:red@{time}")
    assert "time" in message and ">= 0" in message


@pytest.mark.parametrize("time", ["abc", "1O", "ten", "5s", "6@0"])
def test_rejects_non_numeric_time(time):
    message = parse_error(f"kill:red@{time}")
    assert f"time {time!r} is not a number" in message


@pytest.mark.parametrize("time", ["inf", "nan", "-inf", "1e999"])
def test_rejects_non_finite_time(time):
    message = parse_error(f"kill:red@{time}")
    assert "finite" in message


@pytest.mark.parametrize("spec, option, kind", [
    ("kill:red@60,factor=0.5", "factor", "kill"),
    ("slow:red@10,speed=0.5", "speed", "slow"),
    ("break-motor:red@5,wheel=left", "wheel", "break-motor"),
    ("add-robot:purple@20,kind=diffdrive,count=2", "count", "add-robot"),
])
def test_rejects_unknown_option(spec, option, kind):
    message = parse_error(spec)
    assert f"unknown option {option!r} for {kind}" in message


@pytest.mark.parametrize("factor", ["0", "-0.5", "1.5", "1.0000001", "nan", "inf"])
def test_rejects_factor_outside_unit_interval(factor):
    message = parse_error(f"slow:red@10,factor={factor}")
    assert "factor" in message and "(0, 1]" in message


@pytest.mark.parametrize("factor", ["half", "", "0.5x"])
def test_rejects_badly_typed_option(factor):
    message = parse_error(f"slow:red@10,factor={factor}")
    assert f"factor={factor!r} is not a valid float" in message


@pytest.mark.parametrize("spec", ["kill:red@6\n0", "slow:red@10,factor=0.\n5", "kill:red\n@60"])
def test_messages_stay_on_one_line_even_for_multiline_input(spec):
    parse_error(spec)


# ---------------------------------------------------------------- applying faults


def applied(*specs: str) -> Health:
    health = Health()
    for spec in specs:
        apply_fault(parse_fault(spec), health, MOTORS)
    return health


def test_fresh_health_is_healthy():
    h = Health()
    assert (h.alive, h.ir_blind, h.radio_on, h.gripper_broken, h.speed_factor, h.broken_motors) == \
           (True, (), True, False, 1.0, set())


def test_kill_silences_radio_too():
    h = applied("kill:red@60")
    assert not h.alive and not h.radio_on
    assert h == Health(alive=False, radio_on=False)


def test_radio_on_cannot_revive_dead_robot():
    h = applied("kill:red@1", "radio-on:red@2")
    assert not h.radio_on and not h.alive


def test_radio_off_then_on():
    h = applied("radio-off:red@1")
    assert h == Health(radio_on=False, radio_cut=True)
    apply_fault(parse_fault("radio-on:red@2"), h, MOTORS)
    assert h == Health()


def test_revive_switches_a_robot_on_but_not_a_radio_cut_before():
    h = applied("radio-off:red@1", "remove:red@2")
    assert not h.alive and h.removed
    apply_fault(parse_fault("revive:red@3"), h, MOTORS)
    assert h.alive and not h.radio_on  # a power cycle does not mend a cut radio
    h = applied("kill:red@1", "revive:red@2")
    assert h.alive and h.radio_on and not h.removed


def test_blind_ir():
    assert applied("blind-ir:red@1") == Health(ir_blind=("",))
    assert applied("blind-ir:red@1,sensors=ir_left+ir_back") == Health(ir_blind=("ir_left", "ir_back"))


def test_break_gripper():
    assert applied("break-gripper:red@1") == Health(gripper_broken=True)


def test_break_motor_named_and_default():
    assert applied("break-motor:red@5,motor=right").broken_motors == {"right"}
    assert applied("break-motor:red@5").broken_motors == {"left"}  # the first motor
    assert applied("break-motor:red@5,motor=right", "break-motor:red@6").broken_motors == {"left", "right"}


def test_slow_compounds():
    assert applied("slow:red@1,factor=0.5").speed_factor == pytest.approx(0.5)
    assert applied("slow:red@1,factor=0.5", "slow:red@2,factor=0.4").speed_factor == pytest.approx(0.2)
    assert applied("slow:red@1").speed_factor == pytest.approx(0.5)


def test_add_robot_changes_no_health():
    assert applied("add-robot:purple@20,kind=diffdrive") == Health()


def test_health_instances_do_not_share_motor_sets():
    a, b = Health(), Health()
    apply_fault(parse_fault("break-motor:red@1"), a, MOTORS)
    assert b.broken_motors == set()


# ---------------------------------------------------------------- faults by run-time role (kill:@leader@300)


@pytest.mark.parametrize("spec, robot, role", [
    ("kill:@leader@300", "@leader", "leader"),
    ("kill:@leader:A@12.5", "@leader:A", "leader:A"),
    ("break-motor:@leader@5,motor=left", "@leader", "leader"),
    ("kill:red@60", "red", None),
])
def test_a_role_target_is_marked_by_at(spec, robot, role):
    fault = parse_fault(spec)
    assert (fault.robot, fault.role) == (robot, role)
    assert fault.describe()["robot"] == robot  # the schedule keeps the role; the world records whom it struck


@pytest.mark.parametrize("spec", ["kill:red:A@3", "kill:@@leader@3", "kill:@leader:@3", "kill:@leader:A:B@3"])
def test_a_role_is_written_at_role_or_at_role_colon_qualifier(spec):
    assert SPEC_FORM in parse_error(spec)


@pytest.mark.parametrize("kind", ["add-robot", "revive"])
def test_a_role_cannot_bring_a_robot_in_or_back(kind):
    message = parse_error(f"{kind}:@leader@3")
    assert f"{kind} needs a robot's name, not a role" in message and "kill" in message

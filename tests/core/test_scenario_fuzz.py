"""Fuzzing scenario files: valid files mutated (deleted fields, wrong types, out-of-range numbers, unknown keys,
broken YAML) either load or get one line ``teamsim: error: ...`` and exit status 2, never a traceback. Runs the CLI
in-process (``teamsim scenario show MISSION --scenario FILE``), 600 mutations per mission of three hand-written
files; and for every mission, 250 field-by-field mutations of its exported scenario, checked to name the field."""
from __future__ import annotations

import contextlib
import copy
import io
import math
import os
import random
import tempfile
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings, strategies as st

from teamsim.cli import main
from teamsim.config import ConfigError, TrialConfig
from teamsim.runner import trial_config
from teamsim.scenario import config_of, load, scenario_of, to_data
from teamsim.tasks import MISSIONS

WANDER = """\
mission: wander
seed: 4
duration: 30
arena:
  size: [8, 8]
  boxes: [{x: 2, y: 2, half_x: 0.4, half_y: 0.3, yaw: 0.5}]
  cylinders: [{x: -2, y: 2, radius: 0.3}]
  bogs: [{x: 0, y: -2.5, half_x: 1, half_y: 0.5}]
  image: {file: map.png, resolution: 0.5, origin: [-3, -3]}
objects:
  pucks: [{x: 1, y: 0}, {x: 1.2, y: 0.3}]
  boxes: [{x: -1.5, y: -1, yaw: 0.2}]
robots:
  red: {kind: diffdrive, pose: [0, 0, 0], options: {radius: 0.3, ir_count: 12}}
  green: {kind: tracked, pose: [2.5, -2, 1.0], controller: {cruise_speed: 0.2}}
  blue: {kind: r2, pose: [-2.8, -2.8, 0]}
radio: {loss: 0.1, range: 5}
positioning: {period: 0.6}
timing: {physics_dt: 0.002}
faults:
  - {kind: slow, robot: red, time: 2, options: {factor: 0.5}}
  - {kind: add-robot, robot: blue, time: 5, options: {kind: r2}}
  - {kind: blind-ir, robot: green, time: 1, options: {sensors: ir1}}
"""
NAVIGATE = """\
mission: navigate
arena:
  size: [15, 15]
  boxes: [{x: 0, y: 0, half_x: 1, half_y: 0.8}, {x: 3, y: -2, half_x: 0.6, half_y: 1.0}]
robots:
  red: {kind: tricycle, pose: [-6, 6, -0.78], controller: {method: HRDK}}
task: {goal: [6, -6], time_limit: 300, map_resolution: 0.1}
"""
HAZARDOUS_WASTE = """\
mission: hazardous-waste
arena: {size: [7.9, 3.6]}
objects:
  pucks: [{x: -2.6, y: 0}, {x: -2.5, y: 0.1}, {x: -2.7, y: -0.1}]
robots:
  red: {kind: r2, pose: [-3.2, -0.6, 0], controller: {methodical: true, behaviour: {report_interval: 120}}}
  green: {kind: r2, pose: [-3.2, 0.6, 0], controller: {methodical: false, behaviour: {drive: {cruise: 0.25}}}}
task: {completion: 0.6, goal: [3.3, 0], goal_size: [1.3, 1.8], entrance: [-3.95, 0]}
faults:
  - {kind: blind-ir, robot: green, time: 0, options: {sensors: ir_left+ir_right}}
"""
ODD_VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-10**30, 10**30), st.text(max_size=12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([-1, 0, 0.0, -0.5, 1e9, 10**400, "1e-3", "nan", [], {}, [1, 2], {"x": 1}, [[1]], "red"]),
    st.lists(st.floats(-20, 20), max_size=4))


def paths(node, prefix=()):
    """Every (path, value) in a parsed document, the root first."""
    yield prefix, node
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        yield from paths(value, prefix + (key,))


def at(doc, path):
    for key in path:
        doc = doc[key]
    return doc


def mutate(text: str, data) -> str:
    """One mutation of a valid document, as the text of a file."""
    how = data.draw(st.sampled_from(["delete", "retype", "range", "unknown", "truncate", "garble"]))
    if how == "truncate":
        return text[:data.draw(st.integers(0, len(text)))]
    if how == "garble":
        k = data.draw(st.integers(0, len(text)))
        return text[:k] + data.draw(st.sampled_from(["\t", ": ", "[", "}", "- ", "&a ", "*b", "!!python/none ", "'",
                                                     "\x00", "{{", "\n  x: 1\n", "%", "@"])) + text[k:]
    doc = yaml.safe_load(text)
    path, node = data.draw(st.sampled_from(list(paths(doc))))
    if how == "delete" and path:
        del at(doc, path[:-1])[path[-1]]
    elif how == "retype":
        if path:
            at(doc, path[:-1])[path[-1]] = data.draw(ODD_VALUES)
        else:
            doc = data.draw(ODD_VALUES)
    elif how == "range":
        numbers = [(p, v) for p, v in paths(doc) if isinstance(v, (int, float)) and not isinstance(v, bool)]
        path, value = data.draw(st.sampled_from(numbers))
        scale = data.draw(st.sampled_from([-1, 0, 1e3, 1e6, -1e-9, math.inf, math.nan]))
        at(doc, path[:-1])[path[-1]] = value * scale if not isinstance(value, int) or math.isfinite(scale) and \
            scale == int(scale) and abs(scale) < 1e7 else value + scale
    elif how == "unknown":
        target = node if isinstance(node, dict) else doc if isinstance(doc, dict) else None
        if target is not None:
            target[data.draw(st.sampled_from(["colour", "sizee", "x", "kind", "1", "robots"]))] = 1
    return yaml.safe_dump(doc, sort_keys=False)


def show(mission: str, file) -> tuple[int, str, str]:
    """Run the CLI in-process; stderr is caught at the file descriptor, so a library's own message counts too."""
    out = io.StringIO()
    with tempfile.TemporaryFile() as caught:
        saved = os.dup(2)
        os.dup2(caught.fileno(), 2)
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.TextIOWrapper(os.fdopen(
                    os.dup(2), "wb"), write_through=True)) as err:
                code = main(["scenario", "show", mission, "--scenario", str(file)])
                err.flush()
                err.close()
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        caught.seek(0)
        return code, out.getvalue(), caught.read().decode()


@pytest.mark.parametrize("mission, text", [("wander", WANDER), ("navigate", NAVIGATE),
                                           ("hazardous-waste", HAZARDOUS_WASTE)])
def test_mutated_files_load_or_fail_in_one_line(tmp_path, mission, text):
    image = np.full((8, 8), 255, np.uint8)
    image[5:7, 0:2] = 0  # a 1 m block: x in [-3, -2], y in [-2.5, -1.5]
    cv2.imwrite(str(tmp_path / "map.png"), image)
    file = tmp_path / "fuzzed.yaml"
    file.write_text(text)
    assert show(mission, file)[0] == 0, "the unmutated file loads"
    outcomes = Counter()

    @settings(max_examples=600, deadline=None, derandomize=True, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(st.data())
    def one_mutation(data):
        file.write_text(mutate(text, data))
        code, out, err = show(mission, file)
        assert "Traceback" not in err
        if code == 0:
            assert err == "" and yaml.safe_load(out)["mission"] == mission
        else:
            assert code == 2, err
            assert err.startswith("teamsim: error: ") and err.count("\n") == 1, err
        outcomes[code] += 1

    one_mutation()
    assert sum(outcomes.values()) >= 600
    assert outcomes[0] > 30 and outcomes[2] > 100, outcomes


# -- every mission: its exported scenario, mutated field by field ------------------------------------------------------
MUTATIONS = {"export": 200, "example": 50}  # per exported scenario, per example file
THROUGH_THE_CLI = 10  # every 10th mutation also runs as a file through `teamsim scenario show --scenario FILE`
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SOURCES = [("export", mission) for mission in MISSIONS] + [("example", p.name) for p in sorted(EXAMPLES.glob("*.yaml"))]
SIZES = ("size", "half_x", "half_y", "half_z", "radius", "height", "wall_height", "wall_thickness", "goal_size",
         "length", "depth", "mass")
WRONG_TYPES = ["x", "1e-3x", [1], {"a": 1}, [], {}]


def source(kind: str, name: str) -> tuple[str, dict]:
    """(mission, scenario data): ``teamsim scenario show MISSION --seed 1`` (every field of the scenario, defaults
    included), or an example file."""
    if kind == "export":
        return name, to_data(scenario_of(trial_config(name, seed=1), MISSIONS[name]))
    data = yaml.safe_load((EXAMPLES / name).read_text())
    return data["mission"], data


def leaves(doc, under=()) -> list[tuple[tuple, object]]:
    """(path, value) of every number, boolean and text in ``doc`` below ``under``."""
    return [(p, v) for p, v in paths(at(doc, under), under) if not isinstance(v, (dict, list)) and v is not None]


def key_of(path: tuple) -> str:
    """The field a path ends in (``pose`` for robots.red.pose[0])."""
    return next(str(k) for k in reversed(path) if isinstance(k, str))


def mutate_data(rng: random.Random, doc: dict) -> tuple[dict, str, str | None]:
    """One mutation of a scenario's data: (the data, what was done, text the error must contain or None when the
    scenario may also load)."""
    doc = copy.deepcopy(doc)
    how = rng.choice(["delete", "wrong-type", "range", "nan", "unknown-key", "negative-size", "outside", "kind",
                      "controller", "task", "fault", "robot-name"])
    robot = rng.choice(list(doc["robots"]))
    if how in ("controller", "task"):  # a field of a robot's controller settings or of the mission's task
        under = ("robots", robot, "controller") if how == "controller" else ("task",)
        numbers = [(p, v) for p, v in leaves(doc, under) if isinstance(v, (int, float))]
        if not numbers:
            return doc, how, None
        path, value = rng.choice(numbers)
        how = rng.choice(["wrong-type", "range", "nan"])
        numbers = [(path, value)]
    else:
        numbers = [(p, v) for p, v in leaves(doc) if isinstance(v, (int, float))]
    path, value = rng.choice(numbers)
    holder = at(doc, path[:-1])
    if how == "delete":
        mapping_paths = [p for p, v in paths(doc) if p and isinstance(at(doc, p[:-1]), dict)]
        path = rng.choice(mapping_paths)
        del at(doc, path[:-1])[path[-1]]
        return doc, f"delete {path}", None
    if how == "wrong-type":  # text, a list or a mapping where a number or a boolean is: an error naming it
        holder[path[-1]] = rng.choice(WRONG_TYPES + ([1] if isinstance(value, bool) else [True]))
        return doc, f"{path} = {holder[path[-1]]!r}", key_of(path)
    if how == "nan":  # NaN is nowhere allowed
        holder[path[-1]] = math.nan
        return doc, f"{path} = nan", key_of(path)
    if how == "range":
        holder[path[-1]] = rng.choice([-value, value * 1e3, value + 1e4, -1e9, 0, math.inf, -math.inf, 1e-12])
        return doc, f"{path} = {holder[path[-1]]!r}", None
    if how == "unknown-key":  # a key no mapping of any scenario has: an error naming it
        path, node = rng.choice([(p, n) for p, n in paths(doc) if isinstance(n, dict)])
        key = rng.choice(["colour", "sizee", "kindd", "speeed"])
        node[key] = 1
        return doc, f"{path} + {key}", key
    if how == "negative-size":
        sizes = [(p, v) for p, v in numbers if key_of(p) in SIZES and v > 0]
        path, value = rng.choice(sizes)
        at(doc, path[:-1])[path[-1]] = -value
        return doc, f"{path} = {-value!r}", key_of(path)
    if how == "outside":  # a robot beyond a wall: an error naming it
        half = doc["arena"].get("size", [10.0])[0] / 2
        doc["robots"][robot]["pose"][0] = rng.choice([-1, 1]) * (half + rng.choice([0.01, 1, 100]))
        return doc, f"robots.{robot} outside", f"robots.{robot}"
    if how == "kind":
        doc["robots"][robot]["kind"] = rng.choice(["hovercraft", "R2", "", "diffdrive ", 7])
        return doc, f"robots.{robot}.kind", "kind"
    if how == "fault":  # a fault no team can have
        entry = rng.choice([{"kind": "explode", "robot": robot, "time": 1}, {"kind": "kill", "robot": "nobody"},
                            {"kind": "kill", "robot": robot, "time": -1}, {"kind": "slow", "robot": robot,
                                                                          "options": {"factor": 2}},
                            {"kind": "kill", "robot": robot, "options": {"colour": 1}}, {"robot": robot, "time": "x"},
                            {"kind": "revive", "robot": robot, "time": 1e9}, "kill:red@1", None])
        doc["faults"] = list(doc.get("faults") or []) + [entry]
        return doc, f"faults + {entry!r}", "faults"
    name = rng.choice(["a b", "ré", "", "x.y", "1:2"])  # robot-name: not a name a fault spec can use
    doc["robots"][name] = doc["robots"].pop(robot)
    return doc, f"robots.{robot} -> {name!r}", "robots"


def configured(mission: str, doc: dict):
    """The trial configuration a scenario file of ``doc`` gives (teamsim.scenario.configure after reading it)."""
    like = TrialConfig(mission=mission, params=None)
    return config_of(load(doc, MISSIONS[mission], EXAMPLES), MISSIONS[mission], like, [])


@pytest.mark.parametrize("kind, name", SOURCES)
def test_every_mission_s_scenario_mutated_loads_or_fails_in_one_line_naming_the_field(tmp_path, kind, name):
    """Seeded mutations of every mission's exported scenario (``scenario show MISSION --seed 1``, 200 each) and of
    every example file (50 each): missing keys, wrong types, out-of-range numbers, NaN, unknown keys, negative sizes,
    robots outside the arena, bad kinds, bad controller and task fields, bad faults, bad robot names. Each loads, or
    raises a one-line ConfigError; one that must fail (a wrong type, NaN, an unknown key, a negative size, a robot
    outside, a bad kind, fault or name) names the field. Every 10th also goes through the command line as a file:
    exit 0, or exit 2 with that very line."""
    mission, doc = source(kind, name)
    configured(mission, doc)  # unmutated, it loads
    rng = random.Random(f"{name}-29")
    outcomes = Counter()
    for k in range(MUTATIONS[kind]):
        data, what, names = mutate_data(rng, doc)
        try:
            configured(mission, data)
            error = None
        except ConfigError as exc:
            error = str(exc)
        assert error is None or "\n" not in error, (what, error)
        assert names is None or (error is not None and names in error), (what, error)
        outcomes["error" if error else "loads"] += 1
        if k % THROUGH_THE_CLI == 0:
            file = tmp_path / f"{k}.yaml"
            file.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
            code, out, err = show(mission, file)
            assert (code, err) == ((2, f"teamsim: error: {error}\n") if error else (0, "")), (what, err)
    assert outcomes["error"] > MUTATIONS[kind] / 2 and outcomes["loads"] > MUTATIONS[kind] / 25, outcomes

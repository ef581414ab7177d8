"""Scenario files: the round trip (a mission run directly and its exported scenario run from the file are the
same trial), the strict loader, and what summary.json records."""
from __future__ import annotations

import json

import pytest
import yaml

from teamsim.cli import main
from teamsim.config import ConfigError, TrialConfig
from teamsim.faults import parse_fault
from teamsim.files import to_json
from teamsim.runner import mission_of, run_trial
from teamsim.scenario import dump, generate, load, parse_yaml, to_data


def cli(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def one_line_error(capsys, *argv) -> str:
    code, _, err = cli(capsys, *argv)
    assert code == 2, err
    assert err.startswith("teamsim: error: ") and err.count("\n") == 1, err
    return err


def outputs(run_dir) -> tuple[dict, bytes]:
    return json.loads((run_dir / "summary.json").read_text()), (run_dir / "events.jsonl").read_bytes()


@pytest.mark.parametrize("mission, params, faults, duration", [
    ("wander", {"robots": 3}, ["kill:green@1", "add-robot:purple@1.5,kind=tracked", "slow:red@0.5,factor=0.5"], 3.0),
    ("navigate", {"robot": "A", "controller": "ODW", "density": 0.15}, [], 4.0),
    ("hazardous-waste", {"robots": 2, "pucks": 6}, ["kill:red@2", "add-robot:blue@1,kind=r2"], 4.0),
])
def test_round_trip_export_then_run_is_the_same_trial(capsys, tmp_path, mission, params, faults, duration):
    m = mission_of(mission)
    direct = run_trial(TrialConfig(mission=mission, params=m.Params(**params), seed=11, duration=duration,
                                   out=str(tmp_path), run_id="direct", faults=[parse_fault(f) for f in faults]))
    sets = [a for k, v in params.items() for a in ("--set", f"{k}={v}")]
    file = tmp_path / "exported.yaml"
    code, _, err = cli(capsys, "scenario", "show", mission, "--seed", 11, "--duration", duration, *sets,
                       *[a for f in faults for a in ("--fault", f)], "--output", file)
    assert code == 0, err
    code, _, err = cli(capsys, "run", mission, "--scenario", file, "--out", tmp_path, "--run-id", "file")
    (a, events_a), (b, events_b) = outputs(direct.run_dir), outputs(tmp_path / mission / "file")
    assert a["status"] == b["status"] and code == {"completed": 0, "failed": 1}[b["status"]], err
    assert a["final_state_sha256"] == b["final_state_sha256"]
    assert events_a == events_b
    assert a["metrics"] == b["metrics"]
    # summary.json records the scenario that ran: the file's, field for field.
    assert a["scenario"] == b["scenario"] == json.loads(to_json(yaml.safe_load(file.read_text())))
    # ... the mission's own faults (the cleanup's blind side IR) first, then the command line's.
    recorded = [(f["kind"], f["robot"], f["time"]) for f in a["scenario"]["faults"]]
    given = [(f.kind, f.robot, f.time) for f in map(parse_fault, faults)]
    assert recorded[len(recorded) - len(given):] == given


def test_scenario_show_is_what_run_records(capsys, tmp_path):
    code, shown, _ = cli(capsys, "scenario", "show", "wander", "--seed", 2, "--set", "robots=2")
    assert code == 0
    code, _, _ = cli(capsys, "run", "wander", "--seed", 2, "--set", "robots=2", "--duration", 60, "--out",
                     tmp_path, "--run-id", "r")
    assert code == 0
    summary = json.loads((tmp_path / "wander" / "r" / "summary.json").read_text())
    assert json.loads(to_json(parse_yaml(shown, "shown"))) == summary["scenario"]
    assert list(summary["scenario"]["robots"]) == ["red", "green"]


def test_generated_scenario_survives_yaml(tmp_path):
    mission = mission_of("navigate")
    scenario = generate(TrialConfig(mission="navigate", params=mission.Params(density=0.2), seed=3), mission)
    again = load(parse_yaml(dump(scenario), "dumped"), mission)
    assert again == scenario
    assert len(again.arena.boxes) > 10


def test_missions_without_scenarios_say_so(capsys, tmp_path, monkeypatch):
    from teamsim.tasks import MISSIONS
    from teamsim.tasks.missions.custom import CustomMission

    monkeypatch.setitem(MISSIONS, "custom", CustomMission(lambda robot, rng: None))  # builds its scene in code
    err = one_line_error(capsys, "scenario", "show", "custom")
    assert "custom: scenarios are not supported yet" in err


def test_a_file_for_another_mission_is_refused(capsys, tmp_path):
    file = tmp_path / "w.yaml"
    assert cli(capsys, "scenario", "show", "wander", "--output", file)[0] == 0
    err = one_line_error(capsys, "run", "navigate", "--scenario", file, "--out", tmp_path)
    assert "mission: the scenario is for 'wander', not 'navigate'" in err


@pytest.mark.parametrize("text, fragment", [
    ("robots: {red: {kind: diffdrive}}\nrobots: {}\n", "not valid YAML at line 2, column 1: duplicate key 'robots'"),
    ("arena: {size: [10, 10], wals: false}\n", "arena.wals: unknown key; allowed: size, walls, wall_height"),
    ("arena: {size: [10, -1]}\n", "arena.size[1]=-1.0: must be in (0, 1000]"),
    ("radio: {loss: 1.5}\n", "radio.loss=1.5: must be in [0, 1]"),
    ("radio: {loss: yes}\n", "radio.loss: expected a number, got 'yes'"),
    ("robots: {red: {pose: [1, 2]}}\n", "robots.red.pose: expected a list of 3 numbers, got [1, 2]"),
    ("robots: {red: {kind: hovercraft}}\n", "robots.red.kind='hovercraft': allowed values are r2, genghis2"),
    ("robots: {'a b': {}}\n", "robots: name 'a b': allowed: letters, digits, '_' and '-'"),
    ("faults: [{kind: kill, robot: red, time: -1}]\n", "faults[0].time=-1.0: must be in [0, 1e+07]"),
    ("[1, 2]\n", "expected a mapping with keys mission, seed, duration"),
    ("seed: 1\n  arena: {\n", "not valid YAML"),
    ("seed: 1.5\n", "seed: expected a whole number, got 1.5"),
])
def test_bad_files_get_one_line_naming_the_field(capsys, tmp_path, text, fragment):
    file = tmp_path / "bad.yaml"
    file.write_text(text)
    assert fragment in one_line_error(capsys, "scenario", "show", "wander", "--scenario", file)


def test_yaml_1_2_numbers_and_booleans():
    assert parse_yaml("a: 1e-3\nb: yes\nc: true\nd: 2\ne: .inf\n", "x") == {
        "a": 0.001, "b": "yes", "c": True, "d": 2, "e": float("inf")}


def test_defaults_fill_a_short_file(capsys, tmp_path):
    file = tmp_path / "short.yaml"
    file.write_text("robots:\n  red: {pose: [1, 1, 0]}\n  blue: {kind: tracked, pose: [-2, -2, 1.5]}\n")
    code, out, err = cli(capsys, "scenario", "show", "wander", "--scenario", file)
    assert code == 0, err
    data = yaml.safe_load(out)
    assert data["arena"]["size"] == [10.0, 10.0] and data["duration"] == 60.0
    assert data["robots"]["blue"]["controller"]["cruise_speed"] == 0.3
    code, _, err = cli(capsys, "run", "wander", "--scenario", file, "--duration", 1, "--out", tmp_path)
    assert code == 0, err


def test_loader_refuses_bad_data_directly():
    with pytest.raises(ConfigError, match="objects.pucks\\[0\\].x: expected a number"):
        load({"objects": {"pucks": [{"x": "left"}]}}, mission_of("wander"))
    assert to_data(load({}, mission_of("navigate")).task) == {"goal": [0.0, 0.0], "time_limit": 450.0,
                                                              "map_resolution": 0.1}


def test_docs_list_every_field_as_the_schema_has_it():
    from pathlib import Path

    from teamsim.cli.scenario import reference
    from teamsim.tasks import MISSIONS

    page = (Path(__file__).resolve().parents[2] / "docs" / "scenarios.md").read_text()
    generated = page.split("<!-- fields: generated -->\n")[1].split("<!-- fields: end -->")[0]
    assert generated == reference(MISSIONS)
    assert "| `map_resolution` | `0.1` | [0.01, 1] |" in generated

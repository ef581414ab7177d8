"""``teamsim study robustness`` (issue 29, part 1): the fault matrix, its seeded draws, the causes of failures and the
report, with stubbed runs; and one real slice of the matrix (:func:`test_a_slice_of_the_matrix_runs_for_real`, the CI
slice)."""
from __future__ import annotations

import csv
import dataclasses

import pytest

from teamsim.cli.main import ROBUSTNESS_MISSIONS, main
from teamsim.config import ConfigError
from teamsim.faults import FAULT_KINDS
from teamsim.tasks import MISSIONS as REGISTRY
from teamsim.tasks.studies.robustness import (COLUMNS, MISSIONS, NOT_SUPPORTED, ROLE_TARGETS, TYPICAL_S,
                                              RobustnessStudy, cause_of, cells, faults_of, run_study, seeds_from,
                                              team_of, trial_configs)


def test_every_mission_and_fault_kind_is_in_the_matrix_or_said_why_not():
    assert set(MISSIONS) == set(REGISTRY) - {"custom"} and MISSIONS == ROBUSTNESS_MISSIONS
    assert all(m in MISSIONS and f in FAULT_KINDS and reason for (m, f), reason in NOT_SUPPORTED.items())
    run = cells(RobustnessStudy())
    assert {m for m, _ in run} == set(MISSIONS) and {f for _, f in run} == set(FAULT_KINDS)
    assert len(run) + len(NOT_SUPPORTED) == len(MISSIONS) * len(FAULT_KINDS)


def test_the_navigate_robot_has_two_drive_motors_so_a_limp_one_leaves_a_single_input():
    """Why navigate x break-motor is not run: with one of its robot's two locomotion motors limp, one input is
    left."""
    from teamsim.models import build_robot

    assert ("navigate", "break-motor") in NOT_SUPPORTED
    kinds = {kind for seed in (0, 1, 2) for _, kind in team_of("navigate", seed)}
    assert kinds and all(len(build_robot(kind, "x").motors) == 2 for kind in kinds)


def test_faults_are_drawn_from_the_seeds_within_the_typical_time():
    study = RobustnessStudy(seeds=(0, 1, 2))
    for mission, fault in cells(study):
        for seed in study.seeds:
            faults = faults_of(study, mission, fault, seed)
            assert faults == faults_of(study, mission, fault, seed)  # deterministic
            assert faults[-1].kind == fault
            assert 0.05 * TYPICAL_S[mission] - 0.1 <= faults[0].time <= 0.6 * TYPICAL_S[mission] + 0.1
            names = dict(team_of(mission, seed))
            if fault == "add-robot":
                assert faults[0].robot not in names and faults[0].options["kind"]
            elif (mission, fault) in ROLE_TARGETS:  # a headline fault by role (kill:@leader@T)
                assert [f.robot for f in faults] == [ROLE_TARGETS[mission, fault]]
            else:
                assert all(f.robot in names for f in faults)
            if fault in ("radio-on", "revive"):
                assert faults[0].kind == {"radio-on": "radio-off", "revive": faults[0].kind}[fault]
                assert faults[0].kind in ("radio-off", "kill", "remove") and faults[0].time < faults[1].time
                assert faults[0].robot == faults[1].robot
    other = dataclasses.replace(study, seed=1)
    assert [faults_of(other, "hazardous-waste", "kill", s) for s in range(3)] != [
        faults_of(study, "hazardous-waste", "kill", s) for s in range(3)]
    assert {faults_of(study, "janitorial", "break-gripper", s)[0].robot for s in range(6)} <= {"r1", "r2", "r3"}


def test_a_short_study_draws_its_faults_within_its_duration():
    study = RobustnessStudy(duration=10.0)
    assert all(f.time <= 10.0 for m, k in cells(study) for f in faults_of(study, m, k, 0))


def test_every_run_of_the_matrix_is_a_valid_trial():
    """Each mission accepts every fault the study gives it (a refused one would be a ConfigError at build time)."""
    from teamsim.runner import mission_of
    from teamsim.scenario import resolve
    from teamsim.world import World

    for config in trial_configs(RobustnessStudy()):
        mission = mission_of(config.mission)
        resolved = resolve(config, mission)
        if getattr(mission, "without_physics", None) and mission.without_physics(resolved):
            from teamsim.tasks.worlds.kinematic_team import KINEMATIC_FAULTS

            assert all(f.kind in KINEMATIC_FAULTS for f in config.faults), config.faults
            continue
        World(resolved, mission).check_faults(config.faults)


def test_seeds():
    assert seeds_from("3") == (0, 1, 2) and seeds_from("10-12") == (10, 11, 12)
    for bad in ("0", "x", "5-2"):
        with pytest.raises(ConfigError, match="--seeds"):
            seeds_from(bad)


@pytest.mark.parametrize("mission, result, expected", [
    ("box-pushing", {"status": "unstable", "error": "MuJoCo warning: Nan, Inf or huge value in QACC at DOF 3"},
     ("physics instability", "MuJoCo warning: Nan, Inf or huge value in QACC at DOF 3")),
    ("wander", {"status": "error", "error": "KeyError: 'red'"}, ("exception (a bug)", "KeyError: 'red'")),
    ("wander", {"status": "crashed", "error": "BrokenProcessPool: gone"}, ("worker crash", "BrokenProcessPool: gone")),
    ("hazardous-waste", {"status": "failed", "sim_time_s": 1800.0, "duration_s": 1800.0,
                         "metrics": {"pucks_at_goal": 5, "target": 8}, "working": ["red", "blue"],
                         "moved_m": {"red": 12.0, "blue": 0.1, "green": 0.0}},
     ("time limit, robots moving (livelock or too slow)",
      "5 of 8 pucks at the goal; moved in the last 60 s: red 12 m, blue 0.1 m")),
    ("janitorial", {"status": "failed", "sim_time_s": 2400.0, "duration_s": 2400.0,
                    "metrics": {"cans_emptied": 3, "cans": 4, "objects_dusted": 2, "objects": 2, "floor_cleaned": 1.0},
                    "working": ["r1"], "moved_m": {"r1": 0.05}},
     ("time limit, robots stuck", "cans 3/4, objects dusted 2/2, floor 100% cleaned; moved in the last 60 s: r1 "
                                  "0.05 m")),
    ("box-pushing", {"status": "failed", "sim_time_s": 900.0, "duration_s": 900.0,
                     "metrics": {"advance_m": 1.25, "pushes": 7}, "working": [], "moved_m": {}},
     ("time limit, no robot working", "box advanced 1.25 m of 3 m (7 pushes); no robot left working")),
    ("navigate", {"status": "failed", "sim_time_s": 300.0, "duration_s": 450.0,
                  "metrics": {"failure": "looping", "loop_period": 12.5, "loop_diameter": 1.5, "path_length": 40.0},
                  "working": ["red"], "moved_m": {"red": 9.0}},
     ("controller livelock", "goal not reached (looping, 40.0 m driven): a loop of 1.5 m every 12.5 s")),
    ("bounding-overwatch", {"status": "failed", "sim_time_s": 100.0, "duration_s": 900.0,
                            "metrics": {"bounds_completed": 2, "groups": {}, "leaders": {}}},
     ("mission logic", "ended at 100 s of 900 s without success: 2 bounds completed (groups {}, leaders {})")),
    ("formation", {"status": "completed"}, ("", "")),
])
def test_the_cause_of_a_run_that_did_not_complete(mission, result, expected):
    assert cause_of(mission, result) == expected
    if result.get("metrics", {}).get("failure") == "looping":
        assert cause_of(mission, result, (("break-motor", "red"),))[0].startswith("disabled drive")


def test_an_exploration_that_lost_its_manager_is_classed_outside_the_architecture():
    """explore x remove, seed 0: the drawn robot, Robot3, held M1; nothing was assigned or explored after it went
    (70 % at 5000 s). Chand's feedback coordination runs on the manager and has no stand-in for it."""
    result = {"status": "failed", "sim_time_s": 5000.0, "duration_s": 5000.0, "working": ["Robot1"],
              "moved_m": {"Robot1": 0.0},
              "metrics": {"explored_share": 0.7, "status": {"UE": 3, "assigned": 3, "PE": 1, "E": 9},
                          "roles": {"Robot2": ["planner"], "Robot3": ["manager"]}}}
    kind, cause = cause_of("explore", result, (("remove", "Robot3"),))
    assert kind == "outside the architecture" and "manager (M1, Robot3)" in cause and cause.startswith("70% explored")
    assert cause_of("explore", result, (("remove", "Robot2"),))[0] == "time limit, robots stuck"


def test_a_navigate_trail_that_ends_on_a_sampling_step_is_classified():
    """The study's first ``error`` (navigate, revive, seed 1: IndexError in looping.failure_kind): np.arange's float
    steps ended a hair past the trail's last time, and searchsorted answered one past the end."""
    import numpy as np

    from teamsim.tasks.missions.looping import failure_kind

    t = np.array([3.22 + 0.1 * k for k in range(71)])  # 3.22 .. 10.22: arange(3.22, 10.22 + 1e-9, 1) ends at 10.22+
    assert failure_kind(t, np.c_[np.cos(t), np.sin(t)], 0.5)["failure"] in ("looping", "wandered", "stalled")


def _stub(config) -> dict:
    """A run decided by its fault: kill fails at the time limit, slow is unstable, the rest complete."""
    fault = config.faults[-1].kind
    status = {"kill": "failed", "slow": "unstable"}.get(fault, "completed")
    return {"status": status, "completed": status == "completed", "sim_time_s": 60.0, "duration_s": 60.0,
            "error": "MuJoCo warning: Nan, Inf or huge value in QACC at DOF 0" if status == "unstable" else None,
            "metrics": {}, "working": ["red"], "moved_m": {"red": 0.0}}


def test_the_report_counts_statuses_and_names_every_failure(tmp_path):
    study = RobustnessStudy(seeds=(0, 1), missions=("wander", "navigate"), faults=("kill", "slow", "blind-ir"),
                            out=tmp_path, workers=1)
    run_study(study, run=_stub)
    with open(tmp_path / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert tuple(rows[0]) == COLUMNS and len(rows) == 2 * 5  # navigate, kill: not run
    kill = [r for r in rows if r["mission"] == "wander" and r["fault"] == "kill"]
    assert [r["status"] for r in kill] == ["failed", "failed"] and kill[0]["fault_spec"].startswith("kill:")
    assert kill[0]["cause_class"] == "time limit, robots stuck"
    report = (tmp_path / "report.md").read_text()
    assert "| wander | kill | 0/2 (0%) |" in report and "| wander | blind-ir | 2/2 (100%) |" in report
    assert "| navigate | slow | 0/2 (0%) |  | 2 |" in report
    assert "- **wander, slow**: seed 0 (`slow:" in report and "physics instability: MuJoCo warning" in report
    assert "- navigate, kill: one robot and no teammate" in report


def test_the_cli_runs_the_study(tmp_path, monkeypatch, capsys):
    import teamsim.tasks.studies.robustness as robustness

    monkeypatch.setattr(robustness, "run_measured", _stub)
    out = tmp_path / "study"
    assert main(["study", "robustness", "--seeds", "2-3", "--missions", "wander", "--faults", "kill,remove",
                 "--workers", "1", "--out", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    assert "Trial seeds 2-3, study seed 0" in (out / "report.md").read_text()
    assert main(["study", "robustness", "--seeds", "2-3", "--missions", "wander", "--faults", "kill,remove",
                 "--workers", "1", "--resume", str(out)]) == 0
    assert main(["study", "robustness", "--faults", "kill,melt"]) == 2
    assert main(["study", "robustness", "--seeds", "0"]) == 2


SLICE_FAULTS = ("kill", "break-motor", "add-robot", "revive")


def test_a_slice_of_the_matrix_runs_for_real(tmp_path):
    """The CI slice: every mission under four fault kinds, two seeds, 10 simulated seconds, faults within them."""
    study = RobustnessStudy(seeds=(0, 1), faults=SLICE_FAULTS, duration=10.0, workers=2, out=tmp_path)
    run_study(study)
    with open(tmp_path / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 2 * len(cells(study)) and {r["mission"] for r in rows} == set(MISSIONS)
    bad = [(r["mission"], r["fault_spec"], r["seed"], r["status"], r["error"]) for r in rows
           if r["status"] in ("error", "crashed", "unstable")]
    assert not bad
    assert all(float(r["sim_time_s"]) <= 10.0 for r in rows)

"""End to end: Chand's exploration (ch.6) with fixed seeds, in the kinematic backend on a small world (four local
environments, 19.2 m: the same controllers and measures as the 38.4 m world, in seconds), and once in physics.

What they check: the allocation makes the roles (§8.2's team from Table 5.22); the team explores the world and
its map matches the true one; a wheeled explorer that drives into a bog reports it and backs out, and a tracked one
maps it; a killed explorer is found by feedback within 2 T_m and its environment handed back; a killed planner's
work passes to another robot; a broken motor is a partial failure; and bad input is one line and exit status 2.
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from teamsim.cli import main
from teamsim.config import ConfigError, TrialConfig
from teamsim.controllers.exploration.manager import FeedbackSystem, GlobalInfo
from teamsim.controllers.exploration.territory import Territory
from teamsim.faults import parse_fault
from teamsim.runner import run_trial
from teamsim.scenario import resolve
from teamsim.tasks.missions.explore import (ExploreMission, ExploreParams, ExploreTask, exploration_outcome,
                                           explorer_feedback, kinematic_trial, role_names, team_allocation)
from teamsim.world import World

SMALL = dict(size=19.2, divisions=2, t_m=30.0)  # four 9.6 m environments; feedback every 30 s


@functools.cache
def small_run(team: str = "1 2", seed: int = 2, bog_share: float = 0.0, faults: tuple[str, ...] = ()) -> dict:
    params = ExploreParams(team=team, bog_share=bog_share, **SMALL)
    config = TrialConfig(mission="explore", params=params, seed=seed, faults=[parse_fault(f) for f in faults])
    return kinematic_trial(config)


def events(run: dict, kind: str) -> list[dict]:
    return [e for e in run["metrics"]["log"] if e["event"] == kind]


# -- roles --------------------------------------------------------------------------------------------------------
def test_the_allocation_staffs_the_thesis_teams_from_table_5_22():
    """§8.2 ([RECON] from Table 5.27): managers on the PC-class robots, Robot4 plans and explores."""
    allocation = team_allocation([f"Robot{k}" for k in range(1, 9)], 1, 5)
    assert allocation.managers == {"M1": "Robot3", "M2": "Robot1"}
    assert allocation.workers["W1"] == ["Robot4"]
    assert allocation.workers["W2"][0] == "Robot4" and len(allocation.workers["W2"]) == 5
    names = role_names(allocation)
    assert names["planner"] == "Robot4" and names["explorer"] == allocation.workers["W2"][1]


# -- the small world, kinematic -----------------------------------------------------------------------------------
def test_a_team_explores_the_world_and_maps_it_right():
    run = small_run()
    metrics = run["metrics"]
    assert run["status"] == "completed"
    assert metrics["status"]["E"] + metrics["status"]["PE"] == 4 and metrics["status"]["UE"] == 0
    assert metrics["explored_share"] >= 0.94  # the thesis's combined-feedback floor
    assert metrics["map_accuracy"] >= 0.90
    explored = {e["environment"] for e in events(run, "explored")}
    assert explored == {0, 1, 2, 3}


def test_same_seed_same_run():
    a = small_run()["metrics"]
    params = ExploreParams(team="1 2", bog_share=0.0, **SMALL)
    b = kinematic_trial(TrialConfig(mission="explore", params=params, seed=2))["metrics"]
    for key in ("exploration_time", "explored_share", "map_accuracy", "explored_cells", "log"):
        assert a[key] == b[key], key


def test_a_killed_explorer_is_found_within_two_feedback_periods_and_its_environment_handed_back():
    run = small_run(faults=("kill:explorer@100",))
    removed = events(run, "explorer removed")
    assert len(removed) == 1 and 100 < removed[0]["t"] <= 100 + 2 * SMALL["t_m"]
    flags = run["metrics"]["feedback_flags"]
    assert [f["flag"] for f in flags if f["robot"] == removed[0]["robot"]] == ["CF"]
    released = [e for e in events(run, "released") if e["robot"] == removed[0]["robot"]]
    assert released and released[0]["t"] == removed[0]["t"]
    assert run["metrics"]["explored_share"] >= 0.9


def test_a_killed_planner_s_work_passes_to_another_robot():
    run = small_run(faults=("kill:planner@60",))
    removed = events(run, "planner removed")
    assert len(removed) == 1 and removed[0]["t"] <= 60 + 2 * SMALL["t_m"]
    later = [e for e in events(run, "assigned") if e["t"] > removed[0]["t"]]
    assert later and all(e["planner"] != removed[0]["robot"] for e in later)
    assert run["status"] == "completed"


def test_a_broken_motor_is_a_partial_failure():
    run = small_run(faults=("break-motor:explorer@60",))
    flags = [f for f in run["metrics"]["feedback_flags"] if f["flag"] == "PF"]
    assert flags and flags[0]["t"] <= 60 + 3 * SMALL["t_m"]
    assert events(run, "explorer removed")[0]["robot"] == flags[0]["robot"]


@pytest.mark.parametrize("feedback", ["none", "scores"])
def test_without_the_feedback_coordination_a_broken_explorer_keeps_its_role(feedback):
    """Table 8.1 levels 1 and 2: nobody flags the explorer whose motor broke, so nothing is reallocated (with
    feedback on, the same fault is a partial failure: the test above)."""
    params = ExploreParams(team="1 2", feedback=feedback, **SMALL)
    config = TrialConfig(mission="explore", params=params, seed=2, duration=200.0,
                         faults=[parse_fault("break-motor:explorer@60")])
    metrics = kinematic_trial(config)["metrics"]
    assert metrics["feedback_flags"] == [] and metrics["reallocations"] == 0
    assert not events({"metrics": metrics}, "explorer removed")


def test_table_8_1_settings_replace_the_explorers_weights_and_thresholds():
    allocation = team_allocation([f"Robot{k}" for k in range(1, 9)], 1, 3)
    table = allocation.tasks["W2"].feedback
    assert explorer_feedback(allocation, ExploreTask()) == table
    chosen = explorer_feedback(allocation, ExploreTask(weights="W3", poor="P1", partial="F2"))
    assert (chosen.ws, chosen.otes_threshold, chosen.tes_threshold) == ((0.2, 0.2, 0.3, 0.3), 0.75, 0.15)
    assert explorer_feedback(allocation, ExploreTask(poor="none")).otes_threshold == -1


def test_a_wheeled_explorer_backs_out_of_a_bog_and_a_tracked_one_maps_it():
    """Seed 6: tricycle Robot2 drives into the bog of environment 0, reports it, backs out and gives the
    environment up; the tracked Robot4 (traversability 1) is later sent there and explores it."""
    run = small_run(team="1 3", seed=6, bog_share=0.05)
    bog, = events(run, "bog")
    assert bog["robot"] == "Robot2" and bog["environment"] in run["metrics"]["boggy_environments"]
    backing = [e for e in run["team"].events if e["event"] == "behaviour" and e["to"] == "explorer: back out of bog"]
    assert backing and backing[0]["robot"] == "Robot2" and backing[0]["t"] == pytest.approx(bog["t"], abs=0.5)
    given_up = [e for e in events(run, "released") if e["robot"] == "Robot2"]
    assert given_up and given_up[0]["environment"] == bog["environment"] and given_up[0]["t"] > bog["t"]
    explored = {e["environment"]: e["robot"] for e in events(run, "explored")}
    assert explored.get(bog["environment"]) == "Robot4"


# -- bad input ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv, fragment", [
    (["--set", "team=3"], "team='3': write it [planners explorers]"),
    (["--set", "team=1 9"], "can be explorers, the team asks for 9"),
    (["--set", "robots=Robot2,Robot4,Robot5"], "no robot among Robot2, Robot4, Robot5 can take management task M1"),
    (["--set", "robots=Robot9"], "robots='Robot9': allowed: Table 5.22's"),
    (["--set", "size=10"], "too small for divisions 4"),
    (["--set", "density=0.2"], "density=0.2: must be in [0, 0.15]"),
    (["--fault", "kill:pilot@60"], "no robot or role 'pilot'; robots: Robot1"),
    (["--set", "backend=kinematic", "--video"], "--video: a physics-free run has nothing to render"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, fragment):
    code = main(["run", "explore", *argv, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert fragment in err


def test_params_check_names_the_field():
    with pytest.raises(ConfigError, match="team="):
        ExploreParams(team="one three").check()


def test_the_measures_on_a_hand_made_map():
    """§8.1's PAE, ET and ER = PAE / ET (8.1), and map accuracy, on a map worked by hand: environment 0 all mapped
    (one 2 x 2 box right, one free cell wrongly marked occupied), environment 1 mapped on its western half only,
    the other two not at all; environment 3 reported boggy."""
    territory = Territory(19.2, 0.3, 2)
    manager = GlobalInfo("Robot3", territory, explorers=[], planners=[], task_scores={}, bog_capable={}, radii={},
                         rates={}, t_m=60.0)
    truth = np.zeros((territory.cells, territory.cells), bool)
    rows, cols = territory.slices(0)
    manager.global_map[rows, cols] = 0.05
    truth[rows.start + 10:rows.start + 12, cols.start + 10:cols.start + 12] = True
    manager.global_map[rows.start + 10:rows.start + 12, cols.start + 10:cols.start + 12] = 0.95
    manager.global_map[rows.start + 20, cols.start + 20] = 0.95
    rows, cols = territory.slices(1)
    manager.global_map[rows, cols.start:cols.start + territory.environment_cells // 2] = 0.05
    manager.boggy[3] = True
    info = {"territory": territory, "truth": truth, "bogs": [],
            "team": {"global_info": manager, "feedback": FeedbackSystem("Robot1", None, 60.0), "robots": {}}}
    completed, metrics = exploration_outcome(info, 400.0)
    assert completed  # no explorer left working, none assigned
    assert metrics["explored_cells"] == 1024 + 512
    assert metrics["explored_share"] == pytest.approx((1.0 + 0.5 + 0 + 0) / 4)
    assert metrics["exploration_time"] == 400.0
    assert metrics["exploration_rate"] == pytest.approx(0.375 / 400.0)
    assert metrics["map_accuracy"] == pytest.approx(round((1536 - 1) / 1536, 4))
    assert metrics["bogs_found"] == [3] and metrics["boggy_environments"] == []
    assert metrics["status"] == {"UE": 4, "assigned": 0, "PE": 0, "E": 0}  # (graded when explorers report)


def first_assignment(latency: float, loss: float) -> float | None:
    params = ExploreParams(team="1 2", bog_share=0.0, latency=latency, loss=loss, **SMALL)
    run = kinematic_trial(TrialConfig(mission="explore", params=params, seed=2), duration=40.0)
    assigned = events(run, "assigned")
    return assigned[0]["t"] if assigned else None


def test_the_network_s_latency_and_loss_are_settings():
    """§6.5's 802.11 link: a request, a job and an assignment each cross it, so 2 s of latency delays the first
    assignment by at least that; with every packet lost no request reaches the manager and nothing is assigned."""
    prompt = first_assignment(0.005, 0.0)
    assert prompt is not None and first_assignment(2.0, 0.0) >= prompt + 2.0
    assert first_assignment(0.005, 1.0) is None


# -- physics ------------------------------------------------------------------------------------------------------
def test_physics_runs_the_same_controllers_and_maps(tmp_path):
    """A short physics run of the small world: the roles start, explorers are sent out and map through MuJoCo's
    rangefinders; the map so far matches the true world."""
    params = ExploreParams(team="1 2", bog_share=0.0, **SMALL)
    result = run_trial(TrialConfig(mission="explore", params=params, seed=2, duration=90.0, out=str(tmp_path)),
                       progress=False)
    metrics = result.summary["metrics"]
    assert result.status in ("completed", "failed") and result.summary["error"] is None
    assert len(events({"metrics": metrics}, "assigned")) >= 2
    assert metrics["explored_share"] > 0.15 and metrics["map_accuracy"] >= 0.9
    assert all((result.run_dir / f"{name}.{kind}").exists() for name in ("map", "coverage") for kind in ("png", "svg"))


def test_the_video_panel_shows_the_manager_s_map_as_it_grows():
    """The video's second panel: the manager's global map with a HUD of roles, redrawn once per period; newly
    mapped cells change its pixels."""
    params = ExploreParams(team="1 2", bog_share=0.0, **SMALL)
    mission = ExploreMission()
    world = World(resolve(TrialConfig(mission="explore", params=params, seed=2), mission), mission)
    world.tick()  # the robots take up their roles
    before = mission.video_panel(world)
    assert before.dtype == np.uint8 and before.ndim == 3 and before.shape[2] == 3
    assert mission.video_panel(world) is None  # within the period: keep the last one
    info = world.scene.info
    rows, cols = info["territory"].slices(0)
    info["team"]["global_info"].global_map[rows, cols] = 0.05  # environment 0 mapped free
    info["panel_time"] = -math.inf
    after = mission.video_panel(world)
    assert after.shape == before.shape and np.count_nonzero(np.any(after != before, axis=2)) > 0.1 * after[..., 0].size


def test_the_physics_world_talks_over_the_scenario_s_network():
    params = ExploreParams(team="1 2", bog_share=0.0, latency=0.25, loss=0.1, **SMALL)
    config = resolve(TrialConfig(mission="explore", params=params, seed=2), ExploreMission())
    network = World(config, ExploreMission()).radio
    assert (network.config.latency, network.config.loss) == (0.25, 0.1)

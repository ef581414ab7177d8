"""Feedback coordination (teamsim.controllers.allocation.feedback_coordination): Chand's worked example (Tables
5.30-5.34), poor performance, partial and complete failure each flagged and reallocated by the rules RL, and rules
5-6."""
from __future__ import annotations

from dataclasses import replace

import pytest

from teamsim.config import ConfigError
from teamsim.controllers.allocation.devolution import allocate
from teamsim.controllers.allocation.feedback_coordination import FeedbackCoordinator, Report
from teamsim.controllers.allocation.spec import load_robots, load_tasks

# Table 5.31: best-case achievement per T_m = 60 s. The thesis gives it for Robot4 and Robot2 only; the other
# explorers are given Robot2's (assumed, for these tests).
EXPLORER = {"Robot4": {"plan": [0.1473, 2.8], "comm": [5270], "sense": [349, 349], "act": [15.26]},
            "Robot2": {"plan": [0.1584, 3.01], "comm": [8580], "sense": [382, 381], "act": [18.27]}}
PLANNER = {"plan": [0.442, 0.442], "comm": [10380]}
WORKERS = ("Robot4", "Robot2", "Robot5", "Robot7", "Robot6")


def expected() -> dict:
    out = {r: {"W2": EXPLORER.get(r, EXPLORER["Robot2"])} for r in WORKERS}
    for r in ("Robot4", "Robot2", "Robot5", "Robot7"):
        out[r]["W1"] = PLANNER
    return out


def explorer(plan, comm, area, accurate, distance, hz) -> Report:
    """Table 5.30's W2 rows and Table 5.32's rates (the same for all four RU entries)."""
    return Report({"plan": plan, "comm": [comm], "sense": [area, accurate], "act": [distance]},
                  {"sense": [hz, hz], "act": [hz, hz]})


PLANNING = Report({"plan": [1, 1], "comm": [12000]})  # a planner doing better than its best case
NOMINAL = explorer([0, 3], 8500, 370, 365, 18.0, 10)  # an explorer near its best case (Robot2's calibration)


@pytest.fixture
def coordinator():
    return FeedbackCoordinator(allocate(load_tasks(), load_robots()), expected())


# Tables 5.30 and 5.32, N = 1, 2, 3
ROBOT4_W1 = [([3, 3], 59999), ([0, 0], 0), ([0, 0], 0)]
ROBOT4_W2 = [([0, 0], 8283, 705, 645, 14.58, 8.86), ([1, 3], 4576, 339, 319, 14.17, 9.93),
             ([0, 2], 3192, 158, 146, 13.42, 9.96)]
ROBOT2_W2 = [([1, 3], 8555, 252, 233, 15.18, 9.7), ([0, 2], 8192, 317, 308, 14.6, 9.96),
             ([0, 3], 0, 289, 272, 16.6, 9.78)]


def worked_example(coordinator) -> list:
    steps = []
    for n in range(3):
        plan, comm = ROBOT4_W1[n]
        reports = {"Robot4": {"W1": Report({"plan": plan, "comm": [comm]}), "W2": explorer(*ROBOT4_W2[n])},
                   "Robot2": {"W2": explorer(*ROBOT2_W2[n])},
                   "Robot5": {"W2": NOMINAL}, "Robot7": {"W2": NOMINAL}}
        steps.append(coordinator.update(reports))
    return steps


def test_worked_example_table_5_33(coordinator):
    steps = worked_example(coordinator)
    value = {(n + 1, robot, task): s for n, step in enumerate(steps) for (robot, task), s in step.success.items()}
    # Robot4 as planner: all plans in the first interval; OTES and RLS stay 1 (over-achievement carries over)
    assert [value[n, "Robot4", "W1"].tes_ind for n in (1, 2, 3)] == [1, 0, 0]
    assert [value[n, "Robot4", "W1"].otes_ind for n in (1, 2, 3)] == [1, 1, 1]
    assert [value[n, "Robot4", "W1"].rls for n in (1, 2, 3)] == [1, 1, 1]
    assert [value[n, "Robot4", "W1"].tes_tm for n in (1, 2, 3)] == [1, 0, 0]  # the only planner
    # Robot2 as explorer: TES_ind as printed
    assert [value[n, "Robot2", "W2"].tes_ind for n in (1, 2, 3)] == pytest.approx([0.7675, 0.8019, 0.7936], abs=1e-3)
    # RLS: the robot's own cumulative RU / RU' (8.86 Hz over 10 Hz -> 0.886 at N = 1)
    assert [value[n, "Robot2", "W2"].rls for n in (1, 2, 3)] == pytest.approx([0.97, 0.9833, 0.9816], abs=1e-3)
    assert [value[n, "Robot4", "W2"].rls for n in (1, 2, 3)] == pytest.approx([0.8866, 0.94, 0.9589], abs=1e-3)
    # Not reproduced exactly (module docstring), so teamsim's own values are pinned: Robot2's OTES_ind by (5.14)
    # against the table's 0.7675 / 0.7847 / 0.7877 (0.017 and 0.012 above it at N = 2, 3); Robot4's explorer
    # TES_ind against 0.90 / 0.9556 / 0.6887 (0.02-0.04 below it).
    assert [value[n, "Robot2", "W2"].otes_ind for n in (1, 2, 3)] == pytest.approx([0.7682, 0.8021, 0.7995], abs=1e-3)
    assert [value[n, "Robot4", "W2"].tes_ind for n in (1, 2, 3)] == pytest.approx([0.8822, 0.9391, 0.6495], abs=1e-3)


def test_worked_example_needs_no_reallocation_and_scores_tasks_5_21(coordinator):
    steps = worked_example(coordinator)
    for step in steps:
        assert not step.flags and not step.reallocated  # §5.6.3: every OTES_ind > 0.65, TES_ind > 0.12
        assert step.workers == {"W1": ["Robot4"], "W2": ["Robot4", "Robot2", "Robot5", "Robot7"]}
        tm = {robot: s.otes_tm for (robot, task), s in step.success.items() if task == "W2"}
        assert step.task_scores["W2"] == pytest.approx({r: v / max(tm.values()) for r, v in tm.items()})
        assert step.task_scores["W1"] == {"Robot4": 1.0}


def run(coordinator, intervals: int, change: dict, pulse=()):
    """``intervals`` nominal intervals with the reports of ``change`` (robot -> task -> Report or None: silent)."""
    for _ in range(intervals):
        reports = {}  # every current worker does about its best case on each of its tasks
        for task, robots in coordinator.workers.items():
            for robot in robots:
                reports.setdefault(robot, {})[task] = PLANNING if task == "W1" else NOMINAL
        for robot, tasks in change.items():
            if tasks is None:
                reports.pop(robot, None)
            else:
                reports[robot] = {**reports.get(robot, {}), **tasks}
        step = coordinator.update(reports, pulse)
    return step


def test_falling_achievement_is_poor_performance_and_the_robot_is_replaced(coordinator):
    assert not run(coordinator, 2, {}).flags
    slow = explorer([0, 1], 4000, 90, 85, 5.0, 10)  # explores at about a quarter of its best case
    step = run(coordinator, 1, {"Robot5": {"W2": slow}})
    assert not step.flags  # one bad interval: OTES_ind over three intervals still above 0.65
    step = run(coordinator, 1, {"Robot5": {"W2": slow}})
    assert step.flags == {("Robot5", "W2"): "PP"}
    assert step.success["Robot5", "W2"].tes_ind > 0.12  # it still works: not a partial failure
    assert step.reallocated and step.workers["W2"] == ["Robot4", "Robot2", "Robot7", "Robot6"]  # rule 4
    assert step.ru["Robot5"]["W2"]["sense"] == (0, 0) and step.ru["Robot6"]["W2"]["sense"] == (10, 10)
    assert coordinator.columns["W2"][-1] == "Robot5"  # bottom of its task's column


def test_a_robot_whose_motors_fail_is_a_partial_failure(coordinator):
    run(coordinator, 2, {})
    stuck = explorer([0, 0], 8000, 0, 0, 0.0, 10)  # alive and talking, explores nothing
    step = run(coordinator, 1, {"Robot2": {"W2": stuck}})
    assert step.flags == {("Robot2", "W2"): "PF"}  # TES_ind 0.05 < 0.12; OTES_ind 0.67 would not flag it
    assert step.workers["W2"] == ["Robot4", "Robot5", "Robot7", "Robot6"]
    assert "Robot2" not in coordinator.columns["W2"]  # rule 2: never this task again
    assert coordinator.columns["W1"][-1] == "Robot2"  # rule 3: bottom of every other task
    assert step.ru["Robot2"]["W2"]["act"] == (0, 0)


def test_a_silent_robot_is_a_complete_failure(coordinator):
    run(coordinator, 1, {})
    step = run(coordinator, 1, {"Robot7": None})
    assert step.flags == {("Robot7", "W2"): "CF"}
    assert step.workers["W2"] == ["Robot4", "Robot2", "Robot5", "Robot6"]
    assert all("Robot7" not in column for column in coordinator.columns.values())  # rule 1
    assert ("Robot7", "W2") not in step.success


def test_a_pulse_without_data_is_not_a_complete_failure(coordinator):
    run(coordinator, 1, {})
    step = run(coordinator, 1, {"Robot7": None}, pulse=["Robot7"])
    assert step.flags == {("Robot7", "W2"): "PF"}  # alive but achieved nothing


def test_a_dead_planner_is_replaced_from_its_column(coordinator):
    step = run(coordinator, 1, {"Robot4": None})
    assert {flag for flag in step.flags.values()} == {"CF"} and len(step.flags) == 2  # both of its tasks
    assert step.workers["W1"] == ["Robot2"]
    assert step.workers["W2"] == ["Robot2", "Robot5", "Robot7", "Robot6"]


def test_rules_5_and_6_promote_and_change_quantities(coordinator):
    step = coordinator.update({r: {"W2": NOMINAL} for r in ("Robot4", "Robot2", "Robot5", "Robot7")} |
                              {"Robot4": {"W1": PLANNING, "W2": NOMINAL}},
                              promote={"W2": ["Robot6"]}, quantities={"W2": 2})
    assert step.reallocated and not step.flags
    assert step.workers["W2"] == ["Robot6", "Robot4"]
    assert step.ru["Robot5"]["W2"]["sense"] == (0, 0)


def test_calibration_is_required_for_every_candidate():
    allocation = allocate(load_tasks(), load_robots())
    partial = expected()
    del partial["Robot6"]
    with pytest.raises(ConfigError, match="expected achievement of Robot6 on W2: missing"):
        FeedbackCoordinator(allocation, partial)
    partial = expected()
    partial["Robot5"]["W2"] = {**EXPLORER["Robot2"], "sense": [382]}
    with pytest.raises(ConfigError, match=r"Robot5 on W2.sense: expected 2 values > 0"):
        FeedbackCoordinator(allocation, partial)


def test_malformed_report_is_rejected(coordinator):
    with pytest.raises(ConfigError, match="report of Robot2 on W2: sense needs 2 values >= 0"):
        run(coordinator, 1, {"Robot2": {"W2": Report({"plan": [0, 1], "comm": [1], "sense": [1], "act": [1]})}})


def test_task_scores_follow_the_new_team(coordinator):
    step = run(coordinator, 1, {"Robot7": None})
    assert set(step.task_scores["W2"]) == {"Robot4", "Robot2", "Robot5", "Robot6"}
    assert step.task_scores["W2"]["Robot6"] > 0  # (5.6) among the new team until it reports
    step = run(coordinator, 1, {"Robot7": None})
    assert set(step.task_scores["W2"]) == {"Robot4", "Robot2", "Robot5", "Robot6"} and not step.flags


def test_without_failure_detection_only_the_task_scores_change():
    """Table 8.1 level 2: the scores follow the reports, but a silent or stuck robot is neither flagged nor
    moved."""
    coordinator = FeedbackCoordinator(allocate(load_tasks(), load_robots()), expected(), detect_failures=False)
    run(coordinator, 1, {})
    stuck = explorer([0, 0], 8000, 0, 0, 0.0, 10)
    step = run(coordinator, 1, {"Robot2": {"W2": stuck}, "Robot7": None})
    assert not step.flags and not step.reallocated
    assert step.workers["W2"] == ["Robot4", "Robot2", "Robot5", "Robot7"]  # as allocated
    assert step.task_scores["W2"]["Robot2"] < step.task_scores["W2"]["Robot5"]  # its score fell all the same


def test_an_experiments_thresholds_replace_the_tasks_own():
    """OTES_T raised to 0.99 (beyond Table 8.1's P1, to make the point): a robot near its best case is poor."""
    allocation = allocate(load_tasks(), load_robots())
    strict = replace(allocation.tasks["W2"].feedback, otes_threshold=0.99)
    coordinator = FeedbackCoordinator(allocation, expected(), feedback={"W2": strict})
    step = run(coordinator, 1, {})
    assert set(step.flags.values()) == {"PP"} and step.reallocated
    assert not run(FeedbackCoordinator(allocation, expected()), 1, {}).flags  # the table's 0.65: none

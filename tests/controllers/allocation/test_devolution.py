"""Primary and secondary task devolution (teamsim.controllers.allocation.devolution): Chand's worked example (Tables
5.27-5.28), the overrating correction (5.5), task diversity, concurrency, RU and task scores."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from teamsim.bench.allocate import random_problem
from teamsim.controllers.allocation.devolution import TIE_TOLERANCE, allocate, rank
from teamsim.controllers.allocation.spec import RobotSpec, TaskSpec, load_robots, load_tasks


@pytest.fixture(scope="module")
def thesis():
    return allocate(load_tasks(), load_robots())


def robot(name, proc=(6, 4, "mc"), comm=(11, 100), ir=10, act=(1.25, 0.4, 0.5, 0.1)) -> RobotSpec:
    return RobotSpec(name, "", proc[2], proc[0], proc[1], *comm, ir, 1.5, 360, *act)


def task(name, role, proc, grades, **kw) -> TaskSpec:
    return TaskSpec(name, role, name, "continuous", proc, grades, "any", kw.pop("vsw", (0.25,) * 4), **kw)


def test_rank_breaks_ties_within_tolerance_by_file_order():
    # robots are file indices; 0.5 and 0.5 + 1e-16 (round-off) tie, so index 1 goes before index 3
    assert rank([3, 1, 2], [0.5 + 1e-16, 0.5, 0.7]) == [2, 1, 3]
    assert rank([3, 1], [0.5 + 1e-16, 0.5], tolerance=0.0) == [3, 1]  # bit-exact comparison would not tie them
    # a real difference keeps value order, however small against the values themselves
    assert rank([1, 2], [0.5, 0.5 + 100 * TIE_TOLERANCE]) == [2, 1]
    # a group is measured from its best value: 0.5 + 0.6 tol ties with 0.5 + 1.2 tol; 0.5, 1.2 tol below, does not
    tol = TIE_TOLERANCE
    assert rank([4, 3, 2, 1], [0.5 + 1.2 * tol, 0.5 + 0.6 * tol, 0.5, 0.1]) == [3, 4, 2, 1]
    assert rank([], []) == []


def test_managers_table_5_27(thesis):
    assert thesis.managers == {"M1": "Robot3", "M2": "Robot1"}
    assert [r for r, _ in thesis.manager_ranking] == ["Robot1", "Robot3"]  # only these two can manage
    assert thesis.overrating == 0 and not thesis.unassigned


def test_workers_table_5_27(thesis):
    assert thesis.workers == {"W1": ["Robot4"], "W2": ["Robot4", "Robot2", "Robot5", "Robot7"]}
    assert not thesis.shortfall


def test_rtcm_rank_orders_table_5_28(thesis):
    assert list(thesis.rtcm) == ["W1", "W2"]  # W1 has fewer capable robots: allocated first
    assert [c.robot for c in thesis.rtcm["W1"]] == ["Robot4", "Robot2", "Robot5", "Robot7"]
    assert [c.robot for c in thesis.rtcm["W2"]] == ["Robot4", "Robot2", "Robot5", "Robot7", "Robot6"]
    everyone = {c.robot for column in thesis.rtcm.values() for c in column}
    assert "Robot8" not in everyone and not everyone & {"Robot1", "Robot3"}  # incapable; managers excluded
    for column in thesis.rtcm.values():
        values = [c.value for c in column]
        assert values == sorted(values, reverse=True)


def test_task_diversity(thesis):
    diversity = {c.robot: c.diversity for c in thesis.rtcm["W2"]}
    assert diversity == {"Robot4": 0.5, "Robot2": 0.5, "Robot5": 0.5, "Robot7": 0.5, "Robot6": 0.0}
    # Robot6 can only explore: TD 0 is what puts it below Robot7 although its VOTSWS is comparable
    w2 = {c.robot: c for c in thesis.rtcm["W2"]}
    assert w2["Robot6"].value < w2["Robot7"].value


def test_vots_is_score_minus_requirement(thesis):
    scores = dict(zip(thesis.suitability.ids, thesis.suitability.scores["any"]))
    r4 = next(c for c in thesis.rtcm["W1"] if c.robot == "Robot4")
    assert r4.vots == pytest.approx(scores["Robot4"] - np.array([0.35, 0.35, 0.0, 0.0]))


def test_task_scores_5_6_and_resource_utilisation(thesis):
    w2 = {c.robot: c.votsws for c in thesis.rtcm["W2"]}
    top = max(w2[r] for r in thesis.workers["W2"])
    assert thesis.task_scores["W2"] == pytest.approx({r: w2[r] / top for r in thesis.workers["W2"]})
    assert thesis.task_scores["W1"] == {"Robot4": 1.0}
    assert thesis.ru["Robot4"]["W1"]["plan"] == (-1, 0) and thesis.ru["Robot4"]["W2"]["sense"] == (10, 10)
    assert thesis.ru["Robot2"]["W1"]["plan"] == (0, 0) and thesis.ru["Robot2"]["W2"]["act"] == (10, 10)
    assert "Robot6" not in thesis.ru


def test_overrating_corrects_the_greedy_bias_toward_small_task_combinations():
    # X can do the big task C, or A and B together; Y and Z can each do A or B only. At w_CO = 0 X takes A+B
    # (closest to 0) and C is left to robots that cannot do it; overrating the pair frees X for C.
    tasks = [task("A", "manager", "pc", ("medium", "medium", "low", "low"), vsw=(0.5, 0.5, 0, 0)),
             task("B", "manager", "pc", ("medium", "medium", "low", "low"), vsw=(0.5, 0.5, 0, 0)),
             task("C", "manager", "pc", ("high", "high", "low", "low"), vsw=(0.5, 0.5, 0, 0))]
    robots = [robot("X", (5, 2, "pc"), (54, 100)), robot("Y", (3.2, 0.5, "pc"), (54, 100)),
              robot("Z", (3.2, 0.5, "pc"), (54, 100))]
    allocation = allocate(tasks, robots)
    assert allocation.overrating > 0
    assert allocation.managers["C"] == "X" and {allocation.managers["A"], allocation.managers["B"]} == {"Y", "Z"}
    without_z = allocate(tasks, robots[:2])  # X alone can do C; A and B then need two robots: one stays out
    assert without_z.overrating == 1.0 and len(without_z.unassigned) == 1


def test_one_robot_takes_a_combination_of_management_tasks_it_can_carry():
    tasks = [task("A", "manager", "pc", ("low", "low", "low", "low")),
             task("B", "manager", "pc", ("low", "medium", "low", "low"))]
    allocation = allocate(tasks, [robot("X", (5, 2, "pc"), (54, 100)), robot("Y", (3.2, 0.5, "pc"), (54, 100))])
    assert allocation.managers == {"A": "X", "B": "X"}  # the fewest managers


def test_concurrency_needs_the_concurrent_list_and_the_summed_requirements():
    explore = task("E", "worker", "mc", ("low", "low", "medium", "medium"), quantity=(2, 1, 2))
    plan = task("P", "worker", "mc", ("medium", "medium", "low", "low"), quantity=(1, 1, 2))
    strong = robot("S", (10, 16, "mc"), ir=14, act=(2.53, 0.6, 0.4, 1))
    weak = robot("W", (6, 2, "mc"))  # processing 0.31: cannot plan
    apart = allocate([explore, plan], [strong, weak])
    assert apart.workers == {"P": ["S"], "E": ["W"]} and apart.shortfall == {"E": 1}  # S may not do both
    together = allocate([replace(explore, concurrent=frozenset({"P"})), plan], [strong, weak])
    assert together.workers == {"P": ["S"], "E": ["S", "W"]}
    heavy = replace(plan, grades=("medium", "medium", "medium", "low"))  # sense 0.35 + 0.35 > Robot S's 0.55
    assert allocate([replace(explore, concurrent=frozenset({"P"})), heavy], [strong, weak]).workers["E"] == ["W"]


def test_processor_class_must_match():
    tasks = [task("E", "worker", "pc", ("low", "low", "low", "low"))]
    allocation = allocate(tasks, [robot("M", (10, 16, "mc"))])
    assert allocation.rtcm["E"] == [] and allocation.shortfall == {"E": 1}


def test_generated_problem_is_seeded_and_allocates():
    tasks, robots = random_problem(100, 20, seed=4)
    again, robots_again = random_problem(100, 20, seed=4)
    assert tasks == again and robots == robots_again
    assert random_problem(100, 20, seed=5)[1] != robots
    allocation = allocate(tasks, robots)
    assert len(allocation.managers) == 4 and sum(map(len, allocation.workers.values())) > 20
    for task_id, robots_on in allocation.workers.items():
        assert robots_on == [c.robot for c in allocation.rtcm[task_id] if c.robot in robots_on]

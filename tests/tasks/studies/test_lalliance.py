"""The abstract L-ALLIANCE allocation study (teamsim.tasks.worlds.abstract_allocation, teamsim.tasks.studies.lalliance):
problem generator, the event-driven team against plain tick stepping, the brute-force optima, the triple
enumeration, and the study's determinism and outputs on tiny scenarios."""
from __future__ import annotations

import csv
import itertools

import numpy as np
import pytest

from teamsim.controllers.alliance.motivation import activity_message
from teamsim.radio import Message
from teamsim.tasks.studies.lalliance import (COLUMNS, ScenarioJob, StudyPlan, variants, heterogeneity_class,
                                             optimal_triples, region_of, run_scenario, run_study)
from teamsim.tasks.worlds.abstract_allocation import (AllocationProblem, TeamSettings, taught_robot, draw_problem,
                                                      greedy_makespan, optimal_energy, optimal_time, run_team,
                                                      task_name)

SETTINGS = TeamSettings()
TINY = StudyPlan(runs=3, triples=((3, 4, 2), (4, 2, 3)), heterogeneity=(0, 800), ordering_triple=(3, 4, 2),
                 optimal_triples=((2, 3, 2), (3, 3, 2)), optimal_runs=7)


def test_problem_has_the_coverage_and_the_spread_of_section_4_5_1():
    rng = np.random.default_rng(5)
    problem = draw_problem(5, 12, 3, 400.0, rng)
    capable = np.isfinite(problem.times)
    assert (capable.sum(axis=0) == 3).all()
    assert set(capable.sum(axis=1)) <= {7, 8}  # 36 capabilities spread evenly over 5 robots
    finite = np.where(capable, problem.times, np.nan)
    ratio = np.nanmax(finite, axis=0) / np.nanmin(finite, axis=0)
    assert (ratio <= 1 + 4.0 + 1e-9).all() and (np.nanmin(finite, axis=0) <= 500 * 5).all()
    same = draw_problem(5, 12, 3, 0.0, np.random.default_rng(5))
    assert all(len(set(same.times[same.capable(j), j])) == 1 for j in range(12))
    with pytest.raises(ValueError, match="coverage"):
        draw_problem(2, 3, 3, 0.0, rng)


def test_optimal_time_is_the_best_assignment():
    rng = np.random.default_rng(11)
    for _ in range(25):
        problem = draw_problem(int(rng.integers(2, 4)), int(rng.integers(1, 6)), 2, 800.0, rng)
        n, m = problem.times.shape
        exhaustive = min(max(sum(problem.times[r, j] for j in range(m) if assignment[j] == r) for r in range(n))
                         for assignment in itertools.product(range(n), repeat=m)
                         if all(np.isfinite(problem.times[assignment[j], j]) for j in range(m)))
        assert optimal_time(problem) == pytest.approx(exhaustive)
        assert optimal_time(problem) <= greedy_makespan(problem) + 1e-9
        assert optimal_energy(problem) == pytest.approx(problem.times.min(axis=0).sum())


def test_optimal_triples_and_regions():
    triples = optimal_triples()
    assert len(triples) == 496  # §4.5.4's count
    counts = [sum(region_of(c, m) == region for _, m, c in triples) for region in (1, 2, 3, 4)]
    assert counts == [331, 139, 26, 0]  # the thesis's, and none in region 4
    # the bounds the thesis states add the six (7, 6, c) triples (7^6 = 117 649), and (2, 17, 2) for n^m <= 2^17
    footnote, text = optimal_triples("footnote"), optimal_triples("text")
    assert sorted(set(footnote) - set(triples)) == [(7, 6, c) for c in range(2, 8)] and set(triples) <= set(footnote)
    assert set(text) - set(footnote) == {(2, 17, 2)}
    assert (4, 8, 3) in triples and region_of(3, 8) == 3 and (5, 6, 5) in triples and region_of(5, 6) == 2
    assert [region_of(c, 10) for c in (11, 10, 4, 3, 1, 0.5)] == [1, 2, 2, 3, 3, 4]
    assert [heterogeneity_class(x) for x in (0, 200, 400, 800)] == ["none", "mild", "between", "high"]


def tick_stepped(problem: AllocationProblem, settings: TeamSettings, strategy: str, dt: float) -> tuple:
    """The same robots stepped at a fixed period, hearing every teammate's activity at every step, with
    Progress When Working: the reference the event-driven engine must agree with."""
    n, m = problem.times.shape
    capable = [problem.capable(j).tolist() for j in range(m)]
    tasks_of = [[j for j in range(m) if i in capable[j]] for i in range(n)]
    params = settings.robot_params(strategy, "per_strategy", 800.0)
    robots = [taught_robot(problem, i, tasks_of[i], capable, params, np.random.default_rng(0)) for i in range(n)]
    remaining, activity, performer = [1.0] * m, [None] * n, [None] * m
    for tick in range(int(200 / dt)):
        t = tick * dt
        for i, robot in enumerate(robots):
            messages = [Message(f"r{k}", t, activity_message(activity[k])) for k in range(n) if k != i]
            chosen, _ = robot.step(t, {task_name(j): remaining[j] > 0 for j in tasks_of[i]}, messages,
                                   frozenset(f"r{k}" for k in range(n) if k != i))
            activity[i] = chosen
        for i, task in enumerate(activity):
            j = None if task is None else int(task[1:])
            if j is not None and remaining[j] > 0:
                remaining[j] -= dt / problem.times[i, j]
                if remaining[j] <= 1e-9:
                    remaining[j], performer[j] = 0.0, i
        if all(r == 0 for r in remaining):
            return t + dt, tuple(performer)
    raise AssertionError("the tick-stepped team did not finish")


@pytest.mark.parametrize("strategy", ["II", "III", "IV"])
def test_event_driven_team_agrees_with_tick_stepping(strategy):
    problem = draw_problem(3, 5, 2, 800.0, np.random.default_rng(2))
    problem = AllocationProblem(problem.times / 40.0)  # tasks of seconds: the reference then steps quickly
    outcome = run_team(problem, SETTINGS.robot_params(strategy, "per_strategy", 800.0), True,
                       np.random.default_rng(0))
    time, performer = tick_stepped(problem, SETTINGS, strategy, dt=0.01)
    assert outcome.performer == performer
    assert outcome.time == pytest.approx(time, abs=0.1)


def test_strategies_i_to_iii_are_identical_without_heterogeneity():
    job = ScenarioJob("strategies", 5, 6, 3, (0,), 8, 7, SETTINGS, variants("strategies", SETTINGS.boredom_delay))
    outcomes = {}
    for row in run_scenario(job):
        outcomes.setdefault((row["pww"], row["run"]), {})[row["strategy"] + str(row["boredom"])] = (
            row["time"], row["energy"])
    for by_strategy in outcomes.values():
        assert by_strategy["I10.0"] == by_strategy["II10.0"] == by_strategy["III10.0"]
    job = ScenarioJob("strategies", 5, 6, 3, (800,), 8, 7, SETTINGS, variants("strategies", SETTINGS.boredom_delay))
    rows = run_scenario(job)
    assert len({(r["time"], r["energy"]) for r in rows if r["strategy"] != "IV"}) > len(rows) // 4


def test_mission_calibrated_delays_use_the_expected_range():
    settings = TeamSettings(delay_calibration="mission")
    assert settings.robot_params("IV", "per_strategy", 100.0).expected_time_range == (0.0, 1000.0)
    assert SETTINGS.robot_params("IV", "per_strategy", 100.0).expected_time_range == ()


def read_rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_study_writes_csv_and_report_and_is_deterministic(tmp_path):
    first = run_study(tmp_path / "a", workers=1, seed=3, study=TINY)
    second = run_study(tmp_path / "b", workers=2, seed=3, study=TINY)
    other = run_study(tmp_path / "c", workers=1, seed=4, study=TINY)
    text = first["results"].read_text()
    assert text == second["results"].read_text()
    assert text != other["results"].read_text()
    rows = read_rows(first["results"])
    assert tuple(rows[0]) == COLUMNS
    parts = {part: [r for r in rows if r["part"] == part] for part in ("strategies", "ordering", "optimal")}
    assert len(parts["strategies"]) == 2 * 2 * 3 * 10  # triples x heterogeneity x runs x variants
    assert len(parts["ordering"]) == 1 * 3 * 14 and len(parts["optimal"]) == 2 * 7 * 2  # both PWW settings
    assert all(r["optimal_time"] == "" for r in parts["strategies"])
    for r in parts["optimal"]:  # without PWW no team beats the best allocation; energy never beats it
        assert r["pww"] == "1" or float(r["time"]) >= float(r["optimal_time"]) - 1e-6
        assert float(r["energy"]) >= float(r["optimal_energy"]) - 1e-6
    assert {r["heterogeneity"] for r in parts["optimal"]} == {"0", "100", "200", "400", "800", "1600", "3200"}
    report = first["report"].read_text()
    for heading in ("Claim 8", "Table 4.2 regenerated", "Table 4.3 regenerated", "Claim 9", "Claims 10-11",
                    "Claim 12", "Disagreements"):
        assert heading in report
    assert "different results on 0 of" in report
    assert "teamsim counts" not in report  # the triple count is the thesis's: not flagged
    assert "| 12: triples | 496 triples, 331/139/26 in regions 1/2/3 | 496 triples, 331/139/26 in regions 1/2/3 | " \
           "1/1 | — | yes |" in report

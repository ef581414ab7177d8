"""Unit tests for the manager's job queue (Chand §6.4.1, eq. 6.11-6.14) and ECT (eq. 5.23, §6.4.3)."""
from __future__ import annotations

import pytest

from teamsim.controllers.exploration.job_queue import (ENVIRONMENT, PATH, Job, JobQueue, ect_acceptable,
                                                       estimated_completion_time)

TASK_SCORES = {"A": 0.9, "B": 0.8, "C": 0.3, "D": 0.5, "E": 0.8}


def queue_of_five() -> JobQueue:
    """Task IDs 1-5: A path, B environment, C environment, D path, E environment."""
    queue = JobQueue()
    for explorer, kind in [("A", PATH), ("B", ENVIRONMENT), ("C", ENVIRONMENT), ("D", PATH), ("E", ENVIRONMENT)]:
        queue.request(explorer, kind)
    return queue


def ids(jobs) -> list[int]:
    return [job.task_id for job in jobs]


def test_requests_get_unique_increasing_task_ids_and_join_ujl():
    queue = JobQueue()
    first, second = queue.request("A", PATH), queue.request("A", ENVIRONMENT)
    assert (first, second) == (Job(1, "A", PATH), Job(2, "A", ENVIRONMENT))
    assert queue.unassigned == [first, second]
    with pytest.raises(ValueError):
        queue.request("A", "charge")


def test_sorting_puts_environment_jobs_first_by_ascending_task_score_then_paths_by_task_id():
    queue = queue_of_five()
    queue.unassigned.reverse()  # arrival order must not matter: task-ID order comes first
    # environment jobs: C (0.3), then B and E (0.8 each, task-ID order kept); then path jobs 1, 4
    assert ids(queue.sorted_jobs(TASK_SCORES)) == [3, 2, 5, 1, 4]
    assert ids(queue.unassigned) == [3, 2, 5, 1, 4]  # sorted in place: dispatch serves this order


def test_purge_drops_the_weakest_explorers_environment_jobs_beyond_those_available():
    queue = queue_of_five()
    # three environment jobs, one environment: C (0.3) goes, then of B and E (0.8) the later request, E (task 5)
    assert queue.purge(1, TASK_SCORES) == ["C", "E"]
    assert ids(queue.unassigned) == [1, 2, 4]


def test_purge_with_enough_environments_changes_nothing():
    queue = queue_of_five()
    assert queue.purge(3, TASK_SCORES) == []
    assert ids(queue.unassigned) == [1, 2, 3, 4, 5]


def test_dispatch_gives_the_sorted_jobs_to_the_free_planners_by_descending_score():
    queue = queue_of_five()
    queue.sorted_jobs(TASK_SCORES)  # 3, 2, 5, 1, 4
    handed = queue.dispatch({"P1": 0.5, "P3": 0.9, "P2": 0.9})  # P2 and P3 tie: by name
    assert [(job.task_id, planner) for job, planner in handed] == [(3, "P2"), (2, "P3"), (5, "P1")]
    assert ids(queue.unassigned) == [1, 4]
    assert {task_id: planner for task_id, (_, planner) in queue.active.items()} == {3: "P2", 2: "P3", 5: "P1"}


def test_dispatch_with_more_planners_than_jobs_hands_out_every_job():
    queue = JobQueue()
    queue.request("A", PATH)
    assert [(job.task_id, planner) for job, planner in queue.dispatch({"P1": 0.2, "P2": 0.4})] == [(1, "P2")]
    assert queue.unassigned == [] and queue.dispatch({"P1": 0.2}) == []


def test_completion_moves_a_job_from_ajl_to_cjl():
    queue = queue_of_five()
    queue.dispatch({"P1": 1.0})
    queue.complete(1)
    assert queue.completed == [Job(1, "A", PATH)] and 1 not in queue.active
    with pytest.raises(KeyError):
        queue.complete(1)


def test_planner_fault_returns_its_active_jobs_to_ujl():
    queue = queue_of_five()
    queue.dispatch({"P1": 0.9, "P2": 0.5, "P3": 0.1})  # 1 -> P1, 2 -> P2, 3 -> P3
    assert ids(queue.requeue_planner("P2")) == [2]
    assert sorted(queue.active) == [1, 3]
    assert ids(queue.unassigned) == [4, 5, 2]
    assert queue.requeue_planner("P2") == []


def test_explorer_fault_purges_its_pending_jobs_from_ujl_and_ajl():
    queue = queue_of_five()
    queue.request("B", PATH)  # task 6, stays in UJL
    queue.dispatch({"P1": 0.9, "P2": 0.5})  # 1 -> P1, 2 (B's environment job) -> P2
    assert queue.pending("B")
    assert ids(queue.drop_explorer("B")) == [2, 6]
    assert not queue.pending("B")
    assert sorted(queue.active) == [1] and ids(queue.unassigned) == [3, 4, 5]
    assert queue.pending("A") and queue.pending("C")  # the others are untouched


# ---------------------------------------------------------------- ECT (5.23)


def test_ect_uses_the_observed_rate_after_t_m():
    # 120 s > T_m = 60 s: 120 * (50 + 100) / 300 = 60 s
    assert estimated_completion_time(120, 50, 100, 300, 2.5, 60) == pytest.approx(60)
    # the observed rate is 300 / 120 = 2.5 cells/s; a faster prediction must not be used
    assert estimated_completion_time(120, 50, 100, 300, 10.0, 60) == pytest.approx(60)


def test_ect_uses_the_predicted_rate_until_t_m_and_with_nothing_explored():
    assert estimated_completion_time(30, 50, 100, 300, 5.0, 60) == pytest.approx(30)  # 150 / 5
    # t_ek = T_m is not yet past it: 150 / 5 = 30, not 60 * 150 / 600 = 15
    assert estimated_completion_time(60, 50, 100, 600, 5.0, 60) == pytest.approx(30)
    assert estimated_completion_time(120, 50, 100, 0, 5.0, 60) == pytest.approx(30)  # A_o = 0


def test_ect_acceptable_within_the_available_environments_by_ascending_rank():
    ects = {"C": 50.0, "B": 20.0, "A": 50.0, "D": 10.0}  # ranks: D 1, B 2, A 3, C 4 (A and C tie: by name)
    assert [ect_acceptable(ects, name, 2) for name in "DBAC"] == [True, True, False, False]
    assert ect_acceptable(ects, "A", 3) and not ect_acceptable(ects, "C", 3)
    assert not ect_acceptable(ects, "D", 0)

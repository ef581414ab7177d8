"""``teamsim bench allocate``: how long Chand's task allocation (2011 ch.5) takes, and one FIS evaluation.

1. The thesis's example, 8 robots x 4 tasks (Tables 5.20-5.22), and a generated problem of 100 robots x 20
   tasks (:func:`random_problem`, seeded): the wall time of capability scoring plus primary and secondary
   devolution (:func:`~teamsim.controllers.allocation.devolution.allocate`), best of several repeats, files already
   read.
2. One evaluation of the communication FIS: this package's numpy Mamdani for one input row, per row in a batch of
   1000, and scikit-fuzzy's control API on the same rule table (max aggregation, its only mode; see
   :mod:`teamsim.controllers.allocation.fuzzy_capability`).
"""
from __future__ import annotations

import time

import numpy as np

from teamsim.controllers.allocation.devolution import allocate
from teamsim.controllers.allocation.fuzzy_capability import control_api, systems
from teamsim.controllers.allocation.spec import GRADES, RobotSpec, TaskSpec, load_robots, load_tasks
from teamsim.rng import RandomStreams

GRADE_NAMES = tuple(GRADES)


def random_problem(robots: int, tasks: int, seed: int = 0) -> tuple[list[TaskSpec], list[RobotSpec]]:
    """A seeded allocation problem like ch.7's: robots drawn from the practical values of Table 7.3 (and a few
    weaker and stronger ones), one task in five a management task (PC processing), the rest worker tasks (MC)
    with random grades, VSW, quantities 1-5 and random concurrency."""
    rng = RandomStreams(seed).get("bench", "allocate")
    made_robots = []
    for j in range(robots):
        pc = rng.random() < 0.25
        processing = ([rng.choice([1.5, 2.1, 3.1, 3.2, 4.0]), rng.choice([0.25, 0.5, 1.0, 2.0])] if pc else
                      [rng.choice([3.0, 6.0, 10.0]), rng.choice([2.0, 4.0, 10.0, 16.0])])
        communication = [[54, 100], [11, 100], [11, 30], [3, 10]][rng.integers(4)]
        made_robots.append(RobotSpec(
            f"R{j + 1}", "generated", "pc" if pc else "mc", *map(float, processing), *map(float, communication),
            float(rng.integers(6, 17)), float(rng.choice([0.8, 1.5, 3.0])), float(rng.choice([180, 270, 360])),
            float(rng.uniform(0.8, 2.6)), float(rng.choice([0.15, 0.25, 0.4, 0.5, 0.6])),
            float(rng.choice([0.3, 0.4, 0.5, 1.0])), float(rng.choice([0.1, 0.3, 1.0]))))
    managers = max(1, tasks // 5)
    workers = [f"W{k + 1}" for k in range(tasks - managers)]
    concurrent = {w: set() for w in workers}
    for a in range(len(workers)):
        for b in range(a + 1, len(workers)):
            if rng.random() < 0.3:
                concurrent[workers[a]].add(workers[b])
                concurrent[workers[b]].add(workers[a])
    made_tasks = []
    for k in range(tasks):
        manager = k < managers
        grades = tuple(GRADE_NAMES[g] for g in rng.integers(0, 2, 4))
        vsw = rng.dirichlet(np.ones(4))
        vsw = tuple(float(v) for v in np.append(vsw[:3], 1.0 - vsw[:3].sum()))
        if manager:
            made_tasks.append(TaskSpec(f"M{k + 1}", "manager", f"manager {k + 1}", "continuous", "pc", grades,
                                       "any", vsw))
        else:
            name = workers[k - managers]
            count = int(rng.integers(1, 6))
            made_tasks.append(TaskSpec(name, "worker", f"worker {name}", "continuous", "mc", grades, "any", vsw,
                                       quantity=(count, 1, 5), concurrent=frozenset(concurrent[name])))
    return made_tasks, made_robots


def best_time(call, repeats: int) -> float:
    """Fastest of ``repeats`` calls, s."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


def bench_allocate() -> dict:
    """Print and return the allocation times and the FIS evaluation times."""
    figures = {}
    systems()  # build (and cache) every FIS once, as a run would before its first allocation
    print("bench allocate: capability scoring + primary + secondary devolution, best of repeats")
    problems = {"8x4": (load_tasks(), load_robots(), "thesis example, Tables 5.20-5.22"),
                "100x20": (*random_problem(100, 20, seed=0), "generated, seed 0")}
    for key, (tasks, robots, what) in problems.items():
        seconds = best_time(lambda: allocate(tasks, robots), 20 if key == "8x4" else 5)
        allocation = allocate(tasks, robots)
        figures[f"allocate_{key}_ms"] = seconds * 1e3
        print(f"  {len(robots):>3} robots x {len(tasks):>2} tasks ({what}): {seconds * 1e3:8.1f} ms  "
              f"({len(allocation.managers)} manager tasks placed, "
              f"{sum(map(len, allocation.workers.values()))} worker places filled)", flush=True)
    system = systems()["communication"]
    rng = np.random.default_rng(0)
    rows = np.column_stack([rng.uniform(0, 54, 1000), rng.uniform(0, 100, 1000)])
    single = best_time(lambda: system.evaluate(rows[:1]), 200)  # numpy has no cache; the same row is fair
    batch = best_time(lambda: system.evaluate(rows), 20) / len(rows)
    simulation = control_api(system)
    fresh = iter(rows)

    def control_once():
        simulation.input["bandwidth_mbit_s"], simulation.input["range_m"] = next(fresh)
        simulation.compute()

    api = best_time(control_once, 200)
    figures.update(fis_single_us=single * 1e6, fis_batch_row_us=batch * 1e6, skfuzzy_control_us=api * 1e6)
    print("  one evaluation of the communication FIS (2 inputs, 6 rules, 101-point centroid):")
    print(f"    numpy Mamdani, one row:            {single * 1e6:9.1f} us")
    print(f"    numpy Mamdani, per row of 1000:    {batch * 1e6:9.1f} us")
    print(f"    scikit-fuzzy control API, one row: {api * 1e6:9.1f} us  ({api / single:.0f}x the numpy row)")
    return figures

"""The chapter 4 study (teamsim.tasks.studies.two_tier_astar): its worlds, its grid of planners, the figures of one
plan, the paired comparisons and the claims' verdicts on made-up rows, and a tiny study end to end."""
from __future__ import annotations

import csv

import numpy as np
import pytest

from teamsim.tasks.studies.two_tier_astar import (BYTES_PER_NODE, COLUMNS, MONOLITHIC, WORLD_NODES, Planner, Results,
                                                  TwoTierStudy, claims, grid_world, jobs, plan, run_planner, run_study,
                                                  world_label)


def test_world_sizes_are_named_as_in_section_4_6():
    assert [world_label(n) for n in WORLD_NODES] == ["78 KB", "390 KB", "781 KB", "3.81 MB", "7.63 MB",
                                                     "38.15 MB"]


@pytest.mark.parametrize("density", [0.05, 0.25])
def test_grid_world_has_the_density_and_free_corners(density):
    world = grid_world(40_000, density, np.random.default_rng(3))
    assert world.probabilities.shape == (200, 200)
    assert density <= world.density < density + 0.01  # the last rectangle overshoots by at most its area
    assert set(np.unique(world.probabilities)) == {0.05, 0.95}
    assert world.start == (5, 5) and world.goal == (194, 194)
    assert (world.probabilities[:10, :10] == 0.05).all() and (world.probabilities[-10:, -10:] == 0.05).all()
    again = grid_world(40_000, density, np.random.default_rng(3))
    np.testing.assert_array_equal(world.probabilities, again.probabilities)


def test_planner_grid_of_the_default_and_the_full_study():
    default = plan()
    planners = default.planners()
    assert planners[0] == MONOLITHIC
    assert len(planners) == 1 + 3 * 2 + 3  # Q = 1 with both cost methods, Q = 5 with cost method 1
    assert {p.cost_method for p in planners if p.memories == 5} == {1}
    full = plan(full=True)
    assert len(full.planners()) == 1 + 8 * 2 + 2 * 3
    assert all(p.local_map_kb <= 256 for p in full.planners() if p.memories > 1)
    # §4.6: 30 worlds per density, 10 at 25 % in the 7.63 MB and 38.15 MB worlds; --trials overrides.
    assert full.worlds(500_000, 0.25) == 30 and full.worlds(1_000_000, 0.25) == 10
    assert plan(full=True, trials=2).worlds(5_000_000, 0.05) == 2
    assert len(jobs(default)) == 2 * 3 * 3


def test_figures_of_one_plan():
    world = grid_world(10_000, 0.15, np.random.default_rng(0))
    mono = run_planner(world, MONOLITHIC)
    assert mono["reached"] and mono["fetches"] == 1
    assert mono["bytes_received"] == 10_000 * BYTES_PER_NODE  # charged the whole global map
    assert mono["transmission_time"] == pytest.approx(80_000 * 8 / 5.5e6)
    straight = np.hypot(*np.subtract(world.goal, world.start))
    assert straight * 0.1 <= mono["path_length"] <= straight * 0.1 * 1.5  # metres, at 10 cm a node
    tiered = run_planner(world, Planner(64, 1, 1))
    assert tiered["reached"] and tiered["row_col"] == 90 and tiered["local_maps"] == 4
    assert tiered["bytes_received"] % BYTES_PER_NODE == 0 and tiered["bytes_received"] >= 90 * 90 * 8
    assert tiered["transmission_time"] == pytest.approx(tiered["bytes_received"] * 8 / 5.5e6)


def row(nodes, density, planner, trial, **figures):
    base = {"nodes": nodes, "density": density, "trial": trial, "reached": True,
            "planner": "monolithic" if planner.monolithic else "two-tier",
            "local_map_kb": planner.local_map_kb, "memories": planner.memories, "cost_method": planner.cost_method,
            "planning_time": 1.0, "bytes_received": 1.0, "path_length": 1.0, "overall_time": 1.0,
            "transmission_time": 0.0, "expansions": 100}
    return {**base, **figures}


def test_paired_comparison_skips_worlds_a_planner_did_not_finish():
    a, b = Planner(64, 1, 2), Planner(64, 1, 1)
    rows = [row(500_000, 0.05, a, t, bytes_received=v) for t, v in enumerate([2.0, 4.0, 6.0, 100.0])]
    rows += [row(500_000, 0.05, b, t, bytes_received=v) for t, v in enumerate([1.0, 2.0, 3.0, 1.0])]
    rows[3]["reached"] = False
    ratio, p, worlds = Results(rows).compare(500_000, 0.05, a, b, "bytes_received")
    assert worlds == 3 and ratio == pytest.approx(2.0)
    assert p < 0.2  # differences 1, 2, 3: t = 3.46 on 2 degrees of freedom, p = 0.074
    assert Results(rows).compare(500_000, 0.10, a, b, "bytes_received") == (pytest.approx(np.nan, nan_ok=True),
                                                                            pytest.approx(np.nan, nan_ok=True), 0)


def test_claims_verdicts_on_made_up_rows():
    study = TwoTierStudy(world_nodes=(500_000,), densities=(0.05, 0.25), local_map_kb=(64, 128), memories=(1,),
                         trials=4)
    rows = []
    for d in study.densities:
        for t in range(4):
            noise = 0.01 * t
            rows.append(row(500_000, d, MONOLITHIC, t, overall_time=10.0))
            for kb in (64, 128):
                # CM2 receives 20 % more everywhere; 64 KB is best; planning grows with density.
                base = (1.0 if kb == 64 else 1.5) + noise
                rows.append(row(500_000, d, Planner(kb, 1, 1), t, bytes_received=base, overall_time=base * 10,
                                planning_time=d + noise, expansions=1000 * d + t))
                rows.append(row(500_000, d, Planner(kb, 1, 2), t, bytes_received=1.2 * base,
                                overall_time=base * 12, planning_time=d + noise, expansions=1100 * d + t))
    found = {c.claim: c for c in claims(study, Results(rows))}
    data = found["cost method 1 cheaper than 2: map data received"]
    assert (data.agree, data.total, data.verdict) == (4, 4, "yes")
    assert found["64 KB local maps do best (overall time)"].verdict == "yes"
    assert found["planning time grows with obstacle density (CM1, Q = 1)"].verdict == "yes"
    assert found["planning work (node expansions) grows with obstacle density (CM1, Q = 1)"].verdict == "yes"
    work = found["cost method 1 cheaper than 2: planning work (node expansions)"]
    assert (work.agree, work.total, work.verdict) == (4, 4, "yes")
    # Two-tier / monolithic is about 1 for 64 KB (not significantly worse: comparable) and 1.5 for 128 KB (worse): the
    # thesis expects worse at 5 % and comparable at 25 %, so one cell of each size agrees.
    versus = found["memory-constrained vs monolithic overall time (CM1)"]
    assert (versus.agree, versus.total, versus.verdict) == (2, 4, "partly")
    assert versus.cause


def test_tiny_study_end_to_end(tmp_path):
    study = TwoTierStudy(world_nodes=(10_000,), densities=(0.05, 0.25), local_map_kb=(64, 128), memories=(1, 5),
                         trials=2, seed=4)
    written = run_study(study, tmp_path, workers=1)
    with open(written["results"]) as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == list(COLUMNS)
    assert written["rows"] == len(rows) == 2 * 2 * len(study.planners())
    assert all(r["reached"] == "True" for r in rows)
    report = written["report"].read_text()
    assert "## Orderings against the thesis" in report and "| 78 KB | 25% | monolithic (Inf) |" in report
    assert all((tmp_path / f"{name}.{kind}").stat().st_size > 0 for name in ("overall_time", "planning_time")
               for kind in ("png", "svg"))
    again = run_study(study, tmp_path / "again", workers=1)
    with open(again["results"]) as handle:
        repeat = list(csv.DictReader(handle))
    deterministic = ("bytes_received", "path_length", "fetches", "backtracks", "reached", "expansions")
    assert [[r[k] for k in deterministic] for r in rows] == [[r[k] for k in deterministic] for r in repeat]

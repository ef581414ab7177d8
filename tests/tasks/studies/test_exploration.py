"""The exploration study (Chand §8.2-8.3, Table 8.1 level 1.1): its design is paired by world and seed, its
verdicts follow the thesis's ratios, and a small run through the CLI writes every output."""
from __future__ import annotations

import csv
import math

import pytest

from teamsim.cli import main
from teamsim.tasks.studies.exploration import ExplorationStudy, claims, judged, run_study, trial_configs


def test_every_team_runs_the_same_worlds_and_seeds_and_each_environment_type_its_own_worlds():
    configs = trial_configs(ExplorationStudy(worlds=2, repeats=2))
    assert len(configs) == 3 * 2 * 2 * 2 * 3  # densities x bogs x worlds x repeats x teams
    by_run = {}
    for c in configs:
        p = c.params
        assert p.backend == "kinematic" and p.feedback == "none"
        assert p.bog_share == (0.05 if "_bog_" in c.run_id else 0.0)
        by_run.setdefault(c.run_id.split("_", 1)[1], set()).add((p.world_seed, c.seed, p.density, p.bog_share))
    assert len(by_run) == 3 * 2 * 2 * 2 and all(len(v) == 1 for v in by_run.values())  # one world per pair key
    worlds = {(c.params.density, c.params.bog_share, c.run_id.split("_")[3]): c.params.world_seed for c in configs}
    assert len(set(worlds.values())) == len(worlds) == 3 * 2 * 2  # repeats share a world, nothing else does
    assert {c.seed for c in configs} == {0, 1}


@pytest.mark.parametrize("ratio, thesis, verdict", [(0.32, 0.321, "yes"), (0.6, 0.321, "yes"), (0.8, 0.321, "partly"),
                                                    (1.1, 0.321, "**no**"), (4.0, 4.80, "yes"), (1.5, 4.80, "partly"),
                                                    (1.0, 1.036, "**no**"), (math.nan, 0.321, "n/a")])
def test_a_change_of_the_thesiss_sign_and_half_to_twice_its_size_reproduces_it(ratio, thesis, verdict):
    assert judged(ratio, thesis) == verdict


def rows_for(team: str, times: list[float], shares: list[float]) -> list[dict]:
    return [{"team": team, "density": 0.05, "bogs": False, "world": k, "repeat": 0, "status": "completed",
             "finished": True, "exploration_time": t, "explored_share": s, "exploration_rate": s / t}
            for k, (t, s) in enumerate(zip(times, shares))]


def test_claims_pair_runs_by_world_and_leave_out_runs_that_did_not_end_validly():
    rows = (rows_for("1 1", [9000, 10000, 11000, 12000], [0.6, 0.62, 0.58, 0.6])
            + rows_for("1 3", [2900, 3200, 3500, 3900], [0.95, 0.97, 0.96, 0.98]))
    rows[3]["status"] = "unstable"  # [1 1] world 3: its pair drops out
    found = {f.claim: f for f in claims(rows, ("1 1", "1 3"))}
    et = found["[1 3] vs [1 1]: ET"]
    assert et.teamsim == "x 0.32 (3 pairs)" and et.verdict == "yes" and et.p < 0.01
    assert found["[1 3] vs [1 1]: area (PAE)"].verdict == "yes"  # x 1.61 against 1.589
    assert found["[1 1] explores at most about 80 % (mean PAE)"].verdict == "**no**"  # 60 %
    assert "[1 5] vs [1 1]: ET" not in found  # a team not run


def test_a_small_study_writes_its_report_table_and_figure(tmp_path, capsys):
    out = tmp_path / "study"
    code = main(["study", "exploration", "--worlds", "1", "--teams", "1-3,1-5", "--duration", "20",
                 "--workers", "2", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert len(rows) == 12 and {r["team"] for r in rows} == {"1 3", "1 5"}
    assert all(r["status"] == "failed" and float(r["exploration_time"]) == 20.0 for r in rows)  # cut at 20 s
    report = (out / "report.md").read_text()
    et = next(line for line in report.splitlines() if line.startswith("| [1 5] vs [1 3]: ET |"))
    assert "| x 1 (6 pairs) |" in et  # every run cut at 20 s: the same ET
    assert "Runs cut at 20 s" in report and "explores at most about 80 %" not in report  # no MET claim when cut
    assert all((out / f"exploration.{kind}").stat().st_size > 0 for kind in ("png", "svg"))


@pytest.mark.parametrize("argv, fragment", [(["--teams", "2-2"], "team '2 2' not allowed"),
                                            (["--worlds", "0"], "--worlds must be a whole number >= 1"),
                                            (["--duration", "-5"], "--duration must be a number")])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, fragment):
    assert main(["study", "exploration", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err and len(err.splitlines()) == 1


def test_the_cli_picks_densities_terrain_and_backend(monkeypatch):
    import teamsim.tasks.studies.exploration as exploration

    studies = []
    monkeypatch.setattr(exploration, "run_study", lambda study: studies.append(study) or study.out)
    assert main(["study", "exploration", "--densities", "5", "--terrain", "bog", "--teams", "1-3",
                 "--backend", "physics", "--worlds", "5"]) == 0
    configs = trial_configs(studies[0])
    assert len(configs) == 5 and {(c.params.density, c.params.bog_share, c.params.backend, c.params.team)
                                  for c in configs} == {(0.05, 0.05, "physics", "1 3")}


def test_the_study_on_ray_writes_what_the_worker_processes_write(tmp_path):
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        rows = {}
        for name, on_ray in (("ray", True), ("pool", False)):
            study = ExplorationStudy(worlds=1, teams=("1 3",), densities=(0.05,), duration=10.0, ray=on_ray,
                                     out=tmp_path / name, workers=2)
            run_study(study)
            rows[name] = [{k: v for k, v in r.items() if k != "real_time_factor"}
                          for r in csv.DictReader((study.out / "results.csv").open())]
    finally:
        ray.shutdown()
    assert len(rows["ray"]) == 2 and rows["ray"] == rows["pool"]

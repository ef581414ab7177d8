"""The formation study (Parker §7.2): its conditions, its verdicts against the thesis's figures, and a small run
through the CLI that writes every output."""
from __future__ import annotations

import csv
import math

import pytest

from teamsim.cli import main
from teamsim.tasks.studies.formation import FormationStudy, change, claims, condition, judged, trial_configs


def test_runs_alternate_sharp_and_smooth_routes_and_add_a_crossing_team_every_other_pair():
    assert [condition(k) for k in range(4)] == [("sharp", 0), ("smooth", 0), ("sharp", 2), ("smooth", 2)]
    configs = trial_configs(FormationStudy(runs=2, strategies=("I", "IV")))
    assert [(c.params.strategy, c.seed) for c in configs] == [("I", 0), ("I", 1), ("IV", 0), ("IV", 1)]


@pytest.mark.parametrize("measured, thesis, verdict", [(-15.0, -15.0, "yes"), (-8.0, -15.0, "yes"),
                                                       (-31.0, -15.0, "partly"), (-3.0, -15.0, "partly"),
                                                       (4.0, -15.0, "**no**"), (math.nan, -15.0, "n/a")])
def test_a_reduction_within_half_to_twice_the_thesiss_figure_reproduces_it(measured, thesis, verdict):
    assert judged(measured, thesis) == verdict


def rows_of(errors: dict[str, list[float]], broken: dict[str, int]) -> list[dict]:
    return [{"strategy": s, "seed": k, "completed": True, "normalised_error": e, "normalised_error_route": e,
             "mission_time_s": 100.0 + k, "route": "sharp", "order_broken_s": broken[s]} for s, values in errors.items()
            for k, e in enumerate(values)]


def test_changes_are_paired_by_seed_and_the_broken_line_is_judged_on_sharp_routes():
    rows = rows_of({"I": [2.0, 2.2, 1.8], "II": [1.7, 1.9, 1.5], "III": [1.6, 1.7, 1.4], "IV": [1.4, 1.5, 1.2]},
                   {"I": 30, "II": 2, "III": 1, "IV": 0})
    measured, vs, pairs = change(rows, "I", "II", "normalised_error")
    assert measured == pytest.approx(-15.0) and pairs == 3 and vs.p < 0.05
    # II is I less 0.3 in every run: Fieller's interval of II/I is (mean(I) - 0.3 -+ 0) / mean(I) scaled by I's
    # spread, and lies below 1 as the p says.
    assert vs.ratio.startswith("II/I 0.85 [") and float(vs.ratio.split(", ")[1].rstrip("]")) < 1
    found = {f.claim: f for f in claims(rows, ("I", "II", "III", "IV"))}
    assert found["II vs I: normalised error"].verdict == "yes"
    assert found["II vs I: normalised error, route reading"].verdict == "yes"
    assert found["I fails on sharp turns: the line breaks"].verdict == "yes"
    assert found["IV vs III: mission time"].verdict == "yes"  # equal times: "little gain"


def test_a_small_study_writes_its_report_table_and_figures(tmp_path, capsys):
    out = tmp_path / "study"
    code = main(["study", "formation", "--runs", "1", "--strategies", "I,IV", "--duration", "15", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [r["strategy"] for r in rows] == ["I", "IV"] and all(r["status"] == "failed" for r in rows)  # 15 s: short
    report = (out / "report.md").read_text()
    assert "| IV vs I: normalised error | -32 % |" in report
    assert all((out / f"{name}.{kind}").stat().st_size > 0 for name in ("fig7-2", "error-over-time")
               for kind in ("png", "svg"))


def test_bad_strategy_list_is_one_line_and_exit_2(capsys):
    code = main(["study", "formation", "--strategies", "I,V"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "strategy 'V' not allowed" in err

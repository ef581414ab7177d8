"""The feedback study (Chand §8.4-8.5, Table 8.1 levels 2-3.4): each level's settings, forced failures drawn alike
with and without feedback, the tuning order's choice of the best variant, and a small run through the CLI."""
from __future__ import annotations

import csv

import pytest

from teamsim.cli import main
from teamsim.config import ConfigError
from teamsim.faults import parse_fault
from teamsim.sweep import JournalError
from teamsim.tasks.studies.exploration import runs
from teamsim.tasks.studies.feedback import (LEVELS, THESIS_BEST, FeedbackStudy, actions, baseline_configs,
                                            best_variant, claims, detection_delay, failable_explorers, forced_fault,
                                            level_configs, run_study, settings_of)


def test_each_level_tunes_its_own_setting_and_keeps_the_best_of_the_levels_before():
    best = {"weights": "W2", "poor": "P3", "partial": "F4"}
    assert settings_of(LEVELS["task-score"], "W1", best) == {"weights": "W1", "poor": "none", "partial": "none"}
    assert settings_of(LEVELS["poor"], "P4", best) == {"weights": "W2", "poor": "P4", "partial": "F2"}  # TES_T 0.15
    assert settings_of(LEVELS["partial"], "F1", best) == {"weights": "W2", "poor": "P3", "partial": "F1"}
    assert settings_of(LEVELS["combined"], "best", best) == best


def test_a_forced_failure_strikes_an_explorer_that_is_not_the_planner_the_same_with_and_without_feedback():
    study = FeedbackStudy(levels=("partial",), densities=(0.05, 0.10))
    assert failable_explorers("1 3") == ["Robot2", "Robot5"]  # Robot4 plans and explores
    faults = {forced_fault(study, "1 5", run, "complete") for run in runs(study)}
    assert len(faults) == len(runs(study))  # drawn per world
    assert all(f.startswith("kill:Robot") and "Robot4" not in f and 200 <= float(f.split("@")[1]) <= 600
               for f in faults)
    baselines = {c.run_id.split("_", 1)[1]: c.faults for c, _ in baseline_configs(study, ["partial"], 60.0)}
    tuned = level_configs(study, LEVELS["partial"], {t: dict(THESIS_BEST) for t in ("1 3", "1 5")}, 60.0)
    assert {c.params.feedback for c, _ in tuned} == {"full"}
    assert {meaning["failure"] for _, meaning in tuned} == {"partial"}
    for config, _ in tuned:
        assert config.faults == baselines[config.run_id.split("_", 1)[1]] and config.faults[0].kind == "break-motor"


def rows_for(level: str, team: str, variant: str, rates: list[float]) -> list[dict]:
    base = {"level": level, "team": team, "variant": variant, "t_m": 60.0,
            "failure": "none", "density": 0.05, "bogs": False, "repeat": 0, "status": "completed"}
    return [{**base, "world": k, "exploration_rate": r} for k, r in enumerate(rates)]


def test_the_best_variant_has_the_highest_exploration_rate_against_no_feedback():
    rows = (rows_for("baseline", "1 3", "-", [1.0, 2.0, 3.0]) + rows_for("poor", "1 3", "P1", [1.1, 2.1, 3.3])
            + rows_for("poor", "1 3", "P2", [1.3, 2.4, 3.5]) + rows_for("poor", "1 3", "P3", [0.9, 2.0, 2.9])
            + rows_for("poor", "1 3", "P4", []))
    assert best_variant(rows, LEVELS["poor"], "1 3") == "P2"


def test_a_small_study_writes_its_report_table_and_figure(tmp_path, capsys):
    out = tmp_path / "study"
    code = main(["study", "feedback", "--levels", "task-score", "--densities", "5", "--terrain", "dry",
                 "--duration", "30", "--no-retune", "--workers", "2", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    rows = list(csv.DictReader((out / "results.csv").open()))
    # [1 3] and [1 5]: without feedback (level 1.1) and with task scores under W1-W4 (level 2)
    assert len(rows) == 10 and {r["level"] for r in rows} == {"baseline", "task-score"}
    assert {r["weights"] for r in rows if r["level"] == "task-score"} == {"W1", "W2", "W3", "W4"}
    report = (out / "report.md").read_text()
    assert "## Task-score feedback (level 2)" in report and "| task-score feedback (level 2), [1 3] W3: area" in report
    assert all((out / f"feedback.{kind}").stat().st_size > 0 for kind in ("png", "svg"))


def test_a_killed_explorer_is_flagged_with_feedback_and_the_same_kill_strikes_without(tmp_path):
    study = FeedbackStudy(levels=("complete",), densities=(0.05,), bogs=(False,), duration=130.0,
                          failure_window=(5.0, 10.0), retune_t_m=False, workers=2, out=tmp_path / "study")
    run_study(study)
    rows = list(csv.DictReader((study.out / "results.csv").open()))
    assert len(rows) == 4
    for team in ("1 3", "1 5"):
        without, with_feedback = (next(r for r in rows if r["team"] == team and r["level"] == level)
                                  for level in ("baseline", "complete"))
        assert without["fault"] == with_feedback["fault"] and with_feedback["fault"].startswith("kill:")
        assert without["flags"] == "PP:0 PF:0 CF:0" and without["detected_s"] == ""
        assert "CF:1" in with_feedback["flags"] and 0 < float(with_feedback["detected_s"]) <= 60  # the first T_m


def test_a_run_too_short_for_its_forced_failures_or_a_resume_with_nothing_to_resume_is_refused(tmp_path):
    with pytest.raises(ConfigError, match="duration=100: the forced failures strike at 200-600 s"):
        run_study(FeedbackStudy(levels=("partial",), duration=100.0, out=tmp_path))
    with pytest.raises(JournalError, match="nothing to resume"):
        run_study(FeedbackStudy(levels=("poor",), out=tmp_path, resume=True))


@pytest.mark.parametrize("argv, fragment", [(["--levels", "bogus"], "level 'bogus' not allowed"),
                                            (["--densities", "7"], "density 7 not allowed")])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, fragment):
    assert main(["study", "feedback", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert fragment in err and len(err.splitlines()) == 1


def test_the_report_says_how_soon_the_failed_explorer_was_flagged_and_judges_the_thesiss_ratios():
    fault = [parse_fault("break-motor:Robot5@300")]
    flags = [{"t": 240.0, "robot": "Robot5", "flag": "PP"}, {"t": 360.0, "robot": "Robot2", "flag": "PP"},
             {"t": 420.0, "robot": "Robot5", "flag": "PF"}]
    assert detection_delay(fault, flags) == 120.0 and detection_delay(fault, flags[:2]) is None
    base = {"team": "1 3", "density": 0.05, "bogs": False, "repeat": 0, "status": "completed", "failure": "partial"}
    rows = [{**base, "level": "baseline", "variant": "-", "t_m": 60.0, "world": k, "exploration_rate": 1.0 + k,
             "exploration_time": 3000.0, "explored_share": 0.9} for k in range(3)]
    rows += [{**base, "level": "partial", "variant": "F2", "t_m": 60.0, "world": k, "exploration_rate": 1.3 + k,
              "exploration_time": 2650.0 + k, "explored_share": 0.99, "reallocations": 1, "flags": "PP:0 PF:1 CF:0",
              "detected_s": 60.0 + 60 * k} for k in range(3)]
    assert "| partial | [1 3] | F2 | 3 | 3 | 0 / 3 / 0 | 3 of 3 | 120 |" in actions(rows, {"partial": {"1 3": "F2"}})
    found = {f.claim: f for f in claims(rows, {"partial": {"1 3": "F2"}})}
    er = found["partial-failure feedback (level 3.2), [1 3] F2: ER"]
    assert er.teamsim == "x 1.15 (3 pairs)" and er.verdict == "yes"  # +15 % against +29.4 %: half to twice
    assert found["partial-failure feedback (level 3.2), [1 3] F2: ET"].verdict == "yes"  # x 0.884 against 0.881

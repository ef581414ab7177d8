"""Resumable studies (issue 29, part 4): every ``teamsim study`` killed after some trials and resumed with
``--resume`` writes ``report.md`` and ``results.csv`` byte for byte as an uninterrupted run of it.

The trials are real but short (a few simulated seconds), with their wall-clock figures pinned, so that the two runs
can be compared byte for byte; the kill is a KeyboardInterrupt (Ctrl-C) raised as trial k starts.
"""
from __future__ import annotations

import dataclasses
import types
from pathlib import Path

import pytest

import teamsim.sweep as sweep
from teamsim.cli.main import main
from teamsim.sweep import JOURNAL_NAME, JournalError

SHORT_S = 2.0  # simulated seconds of each physics trial here


def _short(config) -> dict:
    """A physics trial cut to SHORT_S, its wall-clock figures pinned."""
    from teamsim.runner import run_trial

    summary = run_trial(dataclasses.replace(config, duration=SHORT_S), progress=False).summary
    summary.update(wall_time_s=1.0, real_time_factor=1.0, pid=0)
    return summary


class _KilledAt:
    """Runs trials with ``run`` until call ``at`` (never if negative), which is interrupted as by Ctrl-C; counts
    the trials run."""

    def __init__(self, run, at: int):
        self.run, self.at, self.calls = run, at, 0

    def __call__(self, config):
        if self.calls == self.at:
            raise KeyboardInterrupt
        self.calls += 1
        return self.run(config)


def _pinned(run_world):
    def run(job):
        result = run_world(job)
        for row in result["rows"]:
            row.update(planning_time=0.001, overall_time=0.001 + row["transmission_time"])
        return result
    return run


_NO_CLOCK = types.SimpleNamespace(perf_counter=lambda: 0.0)


def _studies():
    """(name, run the study into a folder with resume or not, the module attribute that runs one trial, how a trial
    is run here, modules whose clock is pinned)."""
    from teamsim.tasks.studies import (awareness, box_pushing, cleanup_faults, exploration, feedback, formation,
                                       janitorial_rho, lalliance, navigation, robustness, two_tier_astar)

    return {
        "awareness": (lambda out, resume: awareness.run_study(awareness.AwarenessStudy(
            missions=1, duration=SHORT_S, workers=1, out=out, resume=resume)), (sweep, "_run_one"), _short, ()),
        "cleanup-faults": (lambda out, resume: cleanup_faults.run_study(cleanup_faults.CleanupFaultStudy(
            missions=1, conditions=("none", "kill-red", "radio-off"), workers=1, out=out, resume=resume)),
            (sweep, "_run_one"), _short, ()),
        "box-pushing": (lambda out, resume: box_pushing.run_study(box_pushing.BoxPushingStudy(
            trials=2, experiments=("robot-failure",), workers=1, out=out, resume=resume)),
            (sweep, "_run_one"), _short, ()),
        "exploration": (lambda out, resume: exploration.run_study(exploration.ExplorationStudy(
            worlds=1, teams=("1 3",), densities=(0.05,), duration=SHORT_S, workers=1, out=out, resume=resume)),
            (sweep, "_run_one"), _short, (exploration,)),
        "feedback": (lambda out, resume: feedback.run_study(feedback.FeedbackStudy(
            levels=("task-score",), densities=(0.05,), bogs=(False,), duration=SHORT_S, retune_t_m=False, workers=1,
            out=out, resume=resume)), (sweep, "_run_one"), _short, (feedback,)),
        "formation": (lambda out, resume: formation.run_study(formation.FormationStudy(
            runs=2, strategies=("I", "IV"), duration=SHORT_S, workers=1, out=out, resume=resume)),
            (sweep, "_run_one"), _short, ()),
        "janitorial-rho": (lambda out, resume: janitorial_rho.run_study(janitorial_rho.JanitorialRhoStudy(
            rhos=(0.0, 0.5), missions=1, duration=SHORT_S, workers=1, out=out, resume=resume)),
            (sweep, "_run_one"), _short, ()),
        "navigation": (lambda out, resume: navigation.run_study(navigation.NavigationStudy(
            robots=("B",), densities=(0.05,), controllers=("FRC", "ODW"), trials=2, workers=1, out=out,
            resume=resume)), (navigation.BACKENDS, "kinematic"), navigation.kinematic_trial, (navigation,)),
        "two-tier-astar": (lambda out, resume: two_tier_astar.run_study(two_tier_astar.TwoTierStudy(
            world_nodes=(10_000,), densities=(0.05, 0.25), local_map_kb=(64,), memories=(1,), trials=2), out,
            workers=1, resume=resume), (two_tier_astar, "run_world"), _pinned(two_tier_astar.run_world),
            (two_tier_astar,)),
        "lalliance": (lambda out, resume: lalliance.run_study(out, workers=1, seed=3, resume=resume,
                                                              study=lalliance.StudyPlan(
            runs=2, triples=((3, 4, 2), (4, 2, 3)), heterogeneity=(0, 800), ordering_triple=None)),
            (lalliance, "run_scenario"), lalliance.run_scenario, (lalliance,)),
        "robustness": (lambda out, resume: robustness.run_study(robustness.RobustnessStudy(
            missions=("wander", "navigate"), faults=("kill", "slow"), duration=SHORT_S, workers=1, out=out,
            resume=resume)), (robustness, "run_measured"), robustness.run_measured, ()),
    }


def _set(monkeypatch, where, run) -> None:
    owner, name = where
    if isinstance(owner, dict):
        monkeypatch.setitem(owner, name, run)
    else:
        monkeypatch.setattr(owner, name, run)


@pytest.mark.parametrize("name", list(_studies()))
def test_a_killed_study_resumes_to_the_same_report(name, tmp_path, monkeypatch):
    run_study, where, run, clocks = _studies()[name]
    for module in clocks:
        monkeypatch.setattr(module, "time", _NO_CLOCK)
    whole = _KilledAt(run, at=-1)  # (never killed: counts the trials)
    _set(monkeypatch, where, whole)
    run_study(tmp_path / "whole", False)
    killed = _KilledAt(run, at=1)
    _set(monkeypatch, where, killed)
    with pytest.raises(KeyboardInterrupt):
        run_study(tmp_path / "resumed", False)
    journals = (tmp_path / "resumed").glob(f"{Path(JOURNAL_NAME).stem}*.jsonl")  # a study may keep one per stage
    assert killed.calls == 1 and sum(len(j.read_text().splitlines()) for j in journals) == 1
    _set(monkeypatch, where, run)
    with pytest.raises(JournalError, match="--resume"):  # not without being asked
        run_study(tmp_path / "resumed", False)
    resumed = _KilledAt(run, at=-1)
    _set(monkeypatch, where, resumed)
    run_study(tmp_path / "resumed", True)
    assert resumed.calls == whole.calls - killed.calls  # only the trials the journal lacked ran again
    for file in ("report.md", "results.csv"):
        assert (tmp_path / "resumed" / file).read_bytes() == (tmp_path / "whole" / file).read_bytes(), file
    assert malformed_table_rows((tmp_path / "whole" / "report.md").read_text()) == []


def malformed_table_rows(markdown: str) -> list[str]:
    """The rows of the report's markdown tables with another number of cells than their header (a '|' inside a
    cell's text splits it: the box-pushing report's first row once had five cells under four columns)."""
    bad, columns = [], None
    for line in markdown.splitlines():
        if not line.startswith("|"):
            columns = None
            continue
        cells = line.strip().strip("|").count("|") + 1
        if columns is None:
            columns = cells
        elif cells != columns:
            bad.append(line)
    return bad


def test_the_cli_resumes_in_the_folder_and_refuses_a_changed_study(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sweep, "_run_one", _short)
    out = tmp_path / "study"
    args = ["study", "formation", "--runs", "1", "--duration", "2", "--workers", "1", "--strategies", "I"]
    assert main(args + ["--out", str(out)]) == 0
    assert main(args + ["--out", str(out)]) == 2
    assert "--resume" in capsys.readouterr().err
    assert main(args + ["--resume", str(out)]) == 0
    assert main(args[:-1] + ["III", "--resume", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("teamsim: error:") and "\n" not in err and "params.strategy='I' there, 'III' now" in err
    assert main(args + ["--resume", str(out), "--out", str(tmp_path / "other")]) == 2
    assert main(args + ["--resume", str(tmp_path / "none")]) == 2
    assert "nothing to resume" in capsys.readouterr().err


def test_the_cli_interrupted_mid_study_says_in_one_line_how_to_continue(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sweep, "_run_one", _KilledAt(_short, at=0))  # Ctrl-C (or SIGTERM) in the first trial
    out = tmp_path / "study"
    assert main(["study", "formation", "--runs", "1", "--duration", "2", "--workers", "1", "--strategies", "I",
                 "--out", str(out)]) == 130
    assert capsys.readouterr().err.strip() == f"teamsim: interrupted: continue it with --resume {out}"


def test_every_study_subcommand_takes_resume():
    from teamsim.cli.main import _build_parser

    parser = _build_parser()
    studies = parser._subparsers._group_actions[0].choices["study"]._subparsers._group_actions[0].choices
    assert set(studies) == {"navigation", "two-tier-astar", "lalliance", "awareness", "janitorial-rho",
                            "cleanup-faults", "box-pushing", "formation", "robustness", "exploration", "feedback"}
    for name in studies:
        assert parser.parse_args(["study", name, "--resume", "x"]).resume == Path("x")

"""The hazardous-waste studies' plumbing, without physics: which trials they run (faults, seeds, teams) and what
their reports conclude from given rows. Their measured results are in docs/hazardous-waste.md."""
from __future__ import annotations

import csv

import pytest

from teamsim.cli.main import CLEANUP_CONDITIONS, main
from teamsim.tasks.studies import awareness as aw
from teamsim.tasks.studies import cleanup_faults as cf


def test_cli_conditions_are_the_studys():
    assert CLEANUP_CONDITIONS == cf.CONDITIONS


def test_fault_study_runs_every_condition_on_the_same_seeds():
    study = cf.CleanupFaultStudy(missions=4, seed=7)
    configs = cf.trial_configs(study)
    assert len(configs) == 4 * len(cf.CONDITIONS)
    for condition in cf.CONDITIONS:
        chosen = [c for c in configs if c.run_id.startswith(condition + "-")]
        assert [c.seed for c in chosen] == [7, 8, 9, 10]
        assert all(c.params.robots == 3 for c in chosen)
    by_id = {c.run_id: c for c in configs}
    assert by_id["none-0"].faults == []
    assert {(f.kind, f.robot, f.time) for f in by_id["radio-off-2"].faults} == {
        ("radio-off", name, 0.0) for name in ("red", "blue", "green")}
    assert [(f.kind, f.robot, f.time) for f in by_id["break-gripper-1"].faults] == [("break-gripper", "green", 100.0)]


def test_red_dies_at_a_reproducible_random_time_during_its_search():
    study = cf.CleanupFaultStudy(missions=10)
    times = [cf.faults_of(study, "kill-red", k)[1] for k in range(10)]
    assert all(study.kill_window[0] <= t <= study.kill_window[1] for t in times)
    assert len(set(times)) == 10  # a different moment in every mission
    assert times == [cf.faults_of(study, "kill-red", k)[1] for k in range(10)]
    assert times != [cf.faults_of(cf.CleanupFaultStudy(seed=1), "kill-red", k)[1] for k in range(10)]


def row(condition, completed=True, **extra):
    base = {"condition": condition, "mission": 0, "seed": 0, "fault_time": None, "status": "completed",
            "completed": completed, "mission_time_s": 500.0, "energy_parker_units": 1000.0, "pucks_at_goal": 8,
            "transports": 6, "reports": 1, "reporters": "blue", "find_robots": "red", "takeover": "",
            "green_transports": 2, "green_move_spill_s": 300.0, "real_time_factor": 15.0}
    return {**base, **extra}


def test_fault_report_counts_each_conditions_finding(tmp_path):
    study = cf.CleanupFaultStudy(missions=2, out=tmp_path)
    rows = [row("none"), row("none", find_robots="red+green"),
            row("kill-red", takeover="green", fault_time=40.0, find_robots="green+red"),
            row("kill-red", completed=False, status="failed", pucks_at_goal=5, fault_time=60.0),
            row("radio-off", find_robots="blue+green+red", reporters="blue+red"),
            row("radio-off", find_robots="blue+green+red", reporters="red"),
            row("break-gripper", fault_time=100.0, green_move_spill_s=120.0),
            row("break-gripper", fault_time=100.0, green_move_spill_s=80.0)]
    text = cf.report(study, rows)
    assert "| none | 2/2 |" in text and "red alone searched in 1/2" in text
    assert "| kill-red | 1/2 |" in text and "took the search over (find-locations-wander) in 1/2" in text
    assert "every robot searched for itself in 2/2; more than one robot reported in 1/2" in text
    assert "mean 100 s, max 120 s (gripper broken at 100 s)" in text
    assert "kill-red seed 0 (failed, 5 pucks)" in text


def test_awareness_versions_and_their_claims():
    configs = aw.trial_configs(aw.AwarenessStudy(missions=3))
    assert len(configs) == 12
    version_iv = [c for c in configs if c.run_id.startswith("IV-")]
    assert all(len(c.faults) == 3 and {f.kind for f in c.faults} == {"radio-off"} for c in version_iv)
    assert all(c.faults == [] for c in configs if c.run_id.startswith("II-"))

    def mission(version, seed, time, energy, reports, transports, find):
        robots, aware = aw.VERSIONS[version]
        return {"version": version, "robots": robots, "awareness": aware, "completed": True, "status": "completed",
                "seed": seed, "mission_time_s": time + seed, "energy_parker_units": energy + 3 * seed,
                "pucks_at_goal": 8, "transports": transports, "reports": reports,
                "reports_per_move": reports / transports, "find_robots": find}

    rows = [row for seed in range(3) for row in (
        mission("I", seed, 900, 1200, 3, 6, 1), mission("II", seed, 600, 1300, 2, 6, 1),
        mission("III", seed, 1000, 1400, 5, 6, 2), mission("IV", seed, 650, 1900, 4, 6, 3))]
    found = {f.claim: f for f in aw.claims(rows)}
    assert found["energy: IV is the worst version"].verdict == "yes"
    assert found["energy: IV is the worst version"].p < 0.001  # 500 more in every mission
    assert found["time: III (2 robots, no awareness) is the slowest"].verdict == "yes"
    assert found["time: three robots beat two, even IV against I"].verdict == "yes"
    assert found["without awareness every capable robot runs find-locations; with it, one"].verdict == "yes"
    # Reports per move 0.5 (I) and 0.83 (III): the ordering holds, I is 0.08 off the thesis's 0.58, III 0.03
    assert found["reports per move, 2 robots: about 0.58 with awareness (I), 0.86 without (III)"].verdict == "yes"
    for row in rows:
        if row["version"] == "IV":
            row["energy_parker_units"] = 1250  # IV now dearer than I (1200) only
    found = {f.claim: f for f in aw.claims(rows)}
    assert found["energy: IV is the worst version"].verdict == "partly"  # only I is below IV now
    assert found["energy: III better than IV; I and II better than IV"].verdict == "partly"


def test_bad_conditions_are_refused(capsys):
    assert main(["study", "cleanup-faults", "--conditions", "kill-red,melt"]) == 2
    assert "condition 'melt' not allowed; allowed: none, kill-red, radio-off, break-gripper" in capsys.readouterr().err


@pytest.mark.parametrize("columns", [cf.COLUMNS, aw.COLUMNS])
def test_results_tables_have_their_columns(tmp_path, columns):
    from teamsim.files import write_csv

    write_csv(tmp_path / "r.csv", columns, [dict.fromkeys(columns, 1)])
    with open(tmp_path / "r.csv", newline="") as handle:
        assert tuple(csv.DictReader(handle).fieldnames) == tuple(columns)


def test_fault_report_gives_the_theses_findings_with_verdicts_and_p(tmp_path):
    """Radio-off's reports per move above the radio's in every mission: yes, decided; its energy above in one of
    two with the mean below: no. A takeover in one of two kill-red missions: partly."""
    rows = [row("none", seed=0, reports=1, transports=7, energy_parker_units=1000.0),
            row("none", seed=1, reports=1, transports=7, energy_parker_units=1200.0),
            row("kill-red", seed=0, takeover="green"), row("kill-red", seed=1),
            row("radio-off", seed=0, reports=3, transports=7, energy_parker_units=1100.0,
                find_robots="blue+green+red"),
            row("radio-off", seed=1, reports=4, transports=7, energy_parker_units=900.0,
                find_robots="blue+green+red")]
    found = {f.claim.split(" (")[0].split(":")[0]: f for f in cf.claims(rows)}
    reports = found["without awareness report-progress is repeated"]
    assert reports.verdict == "yes" and "higher in 2/2" in reports.teamsim and reports.p < 0.2
    # radio-off's mean over the radio's, 0.5 / (1/7), with t(0.975, 1) = 12.706 times its standard error (none's
    # reports per move are the same in both missions, so the interval is the mean's, scaled).
    assert reports.ratio == "radio-off/none 3.50 [-2.85, 9.85]"
    energy = found["awareness saves energy"]
    assert energy.verdict == "**no**" and "higher in 1/2" in energy.teamsim
    assert found["red killed during its search"].verdict == "partly"
    assert found["without awareness every capable robot runs find-locations"].verdict == "yes"
    text = cf.report(cf.CleanupFaultStudy(missions=2, conditions=("none", "kill-red", "radio-off"), out=tmp_path),
                     rows)
    assert "## Findings against the thesis" in text and "| yes |" in text
    assert "| claim | thesis | teamsim | ratio [95 % CI] | p | reproduced |" in text
    assert "| radio-off/none 3.50 [-2.85, 9.85] | 0.13 | yes, not decided by this sample |" in text
    assert "| radio-off/none 0.91 [unbounded] | 0.7 | **no** |" in text


def test_fault_results_read_back_as_written(tmp_path):
    from teamsim.files import write_csv
    rows = [row("none", seed=3, fault_time=None), row("kill-red", seed=3, fault_time=42.5, takeover="green")]
    write_csv(tmp_path / "results.csv", cf.COLUMNS, rows)
    back = cf.read_results(tmp_path / "results.csv")
    assert [(r["condition"], r["seed"], r["fault_time"], r["completed"], r["transports"]) for r in back] == [
        ("none", 3, None, True, 6), ("kill-red", 3, 42.5, True, 6)]

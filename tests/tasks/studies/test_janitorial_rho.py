"""The communication-rate study's plumbing (Parker §6.2.3), without physics but for one tiny run: which trials it runs
and what its report concludes from given summaries, censored runs included."""
from __future__ import annotations

import csv

from teamsim.cli import main
from teamsim.cli.main import JANITORIAL_RHOS
from teamsim.tasks.studies import janitorial_rho as jr


def test_cli_default_rates_are_the_studys():
    assert JANITORIAL_RHOS == jr.JanitorialRhoStudy().rhos


def test_every_rate_runs_the_same_seeds():
    study = jr.JanitorialRhoStudy(missions=3, seed=5, duration=60.0)
    configs = jr.trial_configs(study)
    assert len(configs) == 3 * 4
    for rho in (0.0, 0.1, 0.5, 2.0):
        chosen = [c for c in configs if c.params.rho == rho]
        assert [c.seed for c in chosen] == [5, 6, 7]
        assert [c.run_id for c in chosen] == [f"rho{rho:g}-{k}" for k in range(3)]
        assert all(c.mission == "janitorial" and c.duration == 60.0 and c.faults == [] for c in chosen)
    assert {c.run_id for c in configs} >= {"rho0-0", "rho0.1-2", "rho2-1"}


def summary(seed: int, time: float | None, status: str = "completed") -> dict:
    """A summary as ``run_trials`` returns it: a finished run's (completed or not), or a dead worker's."""
    if status == "crashed":
        return {"mission": "janitorial", "seed": seed, "status": "crashed", "completed": False, "error": "boom"}
    done = status == "completed"
    return {"mission": "janitorial", "seed": seed, "status": status, "completed": done, "duration_s": 1500.0,
            "real_time_factor": 6.0, "metrics": {"mission_time_s": time if done else 1500.0, "cans_emptied": 3 if done
                                                 else 2, "cans": 3, "objects_dusted": 3, "objects": 3,
                                                 "floor_cleaned": 0.96 if done else 0.7}}


def fake_study(tmp_path, time_of) -> tuple[jr.JanitorialRhoStudy, str, list[dict]]:
    """Write a 10-mission study whose summaries come from ``time_of(rho, k)`` (a time, or a status for a run
    that has none); the report's text and the CSV's rows."""
    study = jr.JanitorialRhoStudy(missions=10, out=tmp_path, duration=1500.0)  # (the fakes ran 1500 s)
    configs = jr.trial_configs(study)
    summaries = []
    for config in configs:
        value = time_of(config.params.rho, config.seed)
        summaries.append(summary(config.seed, None, value) if isinstance(value, str) else summary(config.seed, value))
    out = jr.write_results(study, configs, summaries)
    with open(out / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert (out / "times.png").stat().st_size > 1000 and (out / "times.svg").stat().st_size > 1000
    return study, (out / "report.md").read_text(), rows


def ci(low: float, high: float) -> str:
    """How the report gives the 95 % confidence interval of a paired ratio of mean times."""
    return f"[95 % CI of the paired ratio: x{low:.2f} to x{high:.2f}]"


FACTOR = {0.0: 1.0, 0.1: 0.78, 0.5: 0.78 * 0.9, 2.0: 0.78 * 0.9 * 1.01}


def test_report_reproduces_thesis_like_times(tmp_path):
    """Every run completes; 22 % and then 10 % less time, none at rho = 2, in every mission: all yes, decided."""
    _, text, rows = fake_study(tmp_path, lambda rho, k: round((500 + 10 * k) * FACTOR[rho], 1))
    assert tuple(rows[0]) == jr.COLUMNS and len(rows) == 40
    assert rows[0]["mission_time_s"] == "500.0" and rows[0]["rho"] == "0.0" and rows[0]["completed"] == "True"
    assert "| 0 | 10 | 10 | 545 | 30 | - | - | - |" in text
    assert "| rho = 0 (no messages): the mission still completes | every run completed, mean 438 time units | " \
           "10/10 completed, mean 545 s | - | - | yes |" in text
    assert f"| rho 0 -> 0.1: mean mission time | about 22 % less time | x0.78 (-22 %) {ci(0.78, 0.78)} | 10 | " \
           "0.002 | yes |" in text
    assert f"| rho 0.1 -> 0.5: mean mission time | a further 10 % less | x0.90 (-10 %) {ci(0.9, 0.9)} | 10 | 0.002 | " \
           "yes |" in text
    assert "| rho 0.5 -> 2: mean mission time | \"not getting closer to the optimal\" | x1.01 (+1 %) " \
           f"{ci(1.01, 1.01)} | 10 | 0.002 | yes |" in text
    table = [line for line in text.splitlines() if line.startswith("| ")]
    assert not any("biased" in line or "too few" in line or "not decided" in line for line in table)


def test_censored_runs_have_no_time_and_make_means_biased_or_undecided(tmp_path):
    """rho = 0: 3 runs time out (biased mean, a lower bound); rho = 2: 6 time out and one crashes (too few)."""
    def time_of(rho, k):
        if rho == 0.0 and k < 3 or rho == 2.0 and k < 6:
            return "failed"
        if rho == 2.0 and k == 9:
            return "crashed"
        noise = 0.75 if rho >= 0.5 and k % 2 else 1.05 if rho >= 0.5 else 1.0  # 0.1 -> 0.5: mixed directions
        return round((500 + 10 * k) * (1.0 if rho == 0.0 else 0.819) * noise, 1)

    _, text, rows = fake_study(tmp_path, time_of)
    failed = [r for r in rows if r["status"] == "failed"]
    assert len(failed) == 9 and all(r["mission_time_s"] == "" and r["completed"] == "False" for r in failed)
    crashed = [r for r in rows if r["status"] == "crashed"]
    assert len(crashed) == 1 and crashed[0]["mission_time_s"] == "" and crashed[0]["cans"] == ""
    rho0 = next(line for line in text.splitlines() if line.startswith("| 0 |"))
    # mean of the 7 completed (k = 3..9): 560; with the 3 timed-out runs at 1500 s: 842
    assert rho0 == "| 0 | 10 | 7 | 560 | 22 | 3 ran out of time | 842 | mean biased low (3 of 10 runs left out) |"
    rho2 = next(line for line in text.splitlines() if line.startswith("| 2 |"))
    assert "| 2 | 10 | 3 |" in rho2 and "6 ran out of time, 1 ended in error (crashed)" in rho2
    assert "too few completed runs to decide" in rho2 and rho2.split(" | ")[6] == "-"  # no bound: a time unknown
    assert "7/10 completed, mean 560 s (biased low) | - | - | partly |" in text
    step_01 = next(line for line in text.splitlines() if line.startswith("| rho 0 -> 0.1"))
    # 0.819 x the completed rho = 0 runs, but 0.80 x their (biased) mean; every pair lower: p = 2 / 2**7
    assert f"x0.80 (-20 %) {ci(0.82, 0.82)}, biased: not every run completed | 7 | 0.016 | yes |" in step_01
    step_05 = next(line for line in text.splitlines() if line.startswith("| rho 0.1 -> 0.5"))
    assert f"| x0.90 (-10 %) {ci(0.79, 1.01)} | 10 |" in step_05
    assert step_05.endswith("| yes, not decided by this sample |")
    step_2 = next(line for line in text.splitlines() if line.startswith("| rho 0.5 -> 2"))
    assert "| 3 |" in step_2 and step_2.endswith("| too few completed runs to decide |")


def test_report_says_where_the_teams_time_went(tmp_path):
    """Each run's robot-seconds summed by task family over the robots and every instance; per rate the median and
    the paired p against rho = 0. Here messages halve the dusting and turn the time saved into verification."""
    study = jr.JanitorialRhoStudy(missions=10, out=tmp_path, duration=1500.0)
    configs = jr.trial_configs(study)
    summaries = []
    for config in configs:
        k, talking = config.seed, config.params.rho > 0
        run = summary(k, 900.0)
        run["metrics"]["task_time_s"] = {
            "r1": {"empty-garbage f1": 40.0, "empty-garbage f2": 10.0 + k, "dust-furniture": (300.0 if talking
                                                                                             else 600.0) + k},
            "r2": {"clean-floor lower-left": 200.0, "clean-floor upper-right": 100.0, "idle": 5.0},
            "r3": {"dust-furniture": 100.0, "verify-dusting": (400.0 if talking else 100.0) + k,
                   "verify-floor": 50.0}}
        summaries.append(run)
    text = (jr.write_results(study, configs, summaries) / "report.md").read_text()
    with open(tmp_path / "results.csv", newline="") as handle:
        first = next(csv.DictReader(handle))
    assert (first["empty_garbage_s"], first["dust_furniture_s"], first["clean_floor_s"], first["verification_s"],
            first["idle_s"]) == ("50.0", "700.0", "300.0", "150.0", "5.0")
    assert "| rho | empty garbage | dust furniture | clean floor | verification | idle |" in text
    assert "| 0 | 54 | 704 | 300 | 154 | 5 |" in text  # medians over seeds 0..9: k = 4.5
    # every seed's dusting 300 s less and verification 300 s more at each rate: p = 2 / 2**10; the rest equal: 1
    assert "| 0.5 | 54 (p 1) | 404 (p 0.002) | 300 (p 1) | 454 (p 0.002) | 5 (p 1) |" in text


def test_wilcoxon_p_is_exact_and_safe():
    assert jr.wilcoxon_p([1.0, 2.0, 3.0, 4.0, 5.0], [2.0, 3.0, 4.0, 5.0, 6.0]) == 0.0625  # 2 / 2**5
    assert jr.wilcoxon_p([1.0, 2.0], [1.0, 2.0]) == 1.0
    assert jr.wilcoxon_p([1.0], [2.0]) != jr.wilcoxon_p([1.0], [2.0])  # nan: one pair decides nothing


def test_bad_rates_are_one_line_and_exit_2(capsys):
    for argv, fragment in ((["--rhos=-1"], "--rhos: each must be a number of broadcasts per second in [0, 100]"),
                           (["--rhos", "0,fast"], "rhos must be floats separated by commas"),
                           (["--rhos", "nan"], "--rhos: each must be")):
        assert main(["study", "janitorial-rho", *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("teamsim: error: ") and fragment in err, err


def test_one_tiny_mission_runs_end_to_end(tmp_path, capsys):
    """One 5 s mission at rho = 0.5 in this process: the CLI runs it and writes the three files."""
    assert main(["study", "janitorial-rho", "--missions", "1", "--rhos", "0.5", "--duration", "5", "--workers", "1",
                 "--out", str(tmp_path)]) == 0
    assert "report.md" in capsys.readouterr().out
    with open(tmp_path / "results.csv", newline="") as handle:
        (row,) = csv.DictReader(handle)
    assert row["rho"] == "0.5" and row["status"] == "failed" and row["mission_time_s"] == ""
    assert "| 0.5 | 1 | 0 | - | - | 1 ran out of time | 5 | too few completed runs to decide |" in (
        tmp_path / "report.md").read_text()

"""Claims 8-12 of the spec (§7), asserted on small fixed-seed subsets of the L-ALLIANCE allocation study, run
through its public functions (:func:`study_rows`, :func:`claim_verdicts`, :func:`report`).

Where teamsim reproduces a claim, the test asserts the figures, computed here from the rows. Where it does not, the
test asserts the figures that show it and that ``report.md`` lists the claim under Disagreements with its cause
(and, where the cause states a mechanism, the figures that show the mechanism)."""
from __future__ import annotations

from collections import defaultdict

import numpy as np
import pytest

from teamsim.tasks.studies.lalliance import (CAUSES, LONG_BOREDOM, MUCH_BETTER, TIE_TOLERANCE, UNDER_OPTIMAL,
                                             StudyPlan, claim_verdicts, heterogeneity_class, optimal_triples,
                                             over_optimal, region_of, report, study_rows)

SEED = 0
# Region 1: the thesis's exemplar (4, 2, 3) (Figs 4-5/4-6) and (6, 4, 5); 0 % for claim 8's identical strategies.
REGION1 = StudyPlan(runs=30, triples=((4, 2, 3), (6, 4, 5)), heterogeneity=(0, 100, 800, 3200),
                    ordering_triple=None, optimal_triples=())
# Claim 9: exemplars of regions 1-3, one mild and one high heterogeneity level.
STRATEGY_IV = StudyPlan(runs=20, triples=((4, 2, 3), (6, 4, 5), (2, 3, 2), (5, 6, 5), (6, 12, 4), (4, 8, 3)),
                        heterogeneity=(200, 1600), ordering_triple=None, optimal_triples=())
# Claim 12: every region-3 triple (the region closest to 20 %) and a spread of the region-1 and -2 triples.
_ALL = optimal_triples()
OPTIMAL_MEANS = StudyPlan(runs=1, triples=(), ordering_triple=None, optimal_runs=14, optimal_triples=tuple(
    t for k, t in enumerate(_ALL) if region_of(t[2], t[1]) == 3 or k % 9 == 0))
# Claim 12's worst cases: the thesis's two worst triples with the thesis's 200 runs.
OPTIMAL_WORST = StudyPlan(runs=1, triples=(), ordering_triple=None, optimal_triples=((4, 8, 3), (5, 6, 5)),
                          optimal_runs=200)


@pytest.fixture(scope="module")
def region1_rows():
    return study_rows(REGION1, SEED)


@pytest.fixture(scope="module")
def strategy_iv_rows():
    return study_rows(STRATEGY_IV, SEED)


def verdicts_of(rows, study) -> dict:
    return {v.claim: v for v in claim_verdicts(rows, study)}


def listed(text: str) -> dict[str, list[str]]:
    """The report's Disagreements: cause key -> the bullet lines listed under that cause."""
    section = text.split("## Disagreements", 1)[1]
    by_text = {f"Cause: {explanation}.": key for key, explanation in CAUSES.items()}
    found, pending = defaultdict(list), []
    for line in section.splitlines():
        if line.startswith("- "):
            pending.append(line[2:])
        elif line.startswith("Cause: "):
            found[by_text[line]] += pending
            pending = []
    assert not pending, f"bullets without a cause: {pending}"
    return found


def cell_means(rows: list[dict], metric: str, keep, boredom: float = 10.0) -> dict[str, float]:
    """Per strategy, the mean over the kept problems of its metric divided by the mean of I-III on the same
    problem (``keep(pww, region, heterogeneity class)``); strategy IV with ``boredom`` (IV@1000: the long one)."""
    problems = defaultdict(dict)
    for r in rows:
        if r["part"] == "strategies":
            label = r["strategy"] if r["boredom"] == boredom else f"{r['strategy']}@{r['boredom']:g}"
            problems[(r["n"], r["m"], r["coverage"], r["heterogeneity"], r["pww"], r["run"])][label] = r[metric]
    ratios = defaultdict(list)
    for (n, m, c, x, pww, _), values in problems.items():
        if keep(bool(pww), region_of(c, m), heterogeneity_class(x)):
            reference = np.mean([values[s] for s in ("I", "II", "III")])
            for label, value in values.items():
                ratios[label].append(value / reference)
    return {label: float(np.mean(v)) for label, v in ratios.items()}


def test_claim_8_strategies_identical_at_zero_heterogeneity(region1_rows):
    outcomes = defaultdict(dict)
    for r in region1_rows:
        if r["part"] == "strategies" and r["strategy"] != "IV":
            key = (r["n"], r["m"], r["coverage"], r["heterogeneity"], r["pww"], r["run"])
            outcomes[key][r["strategy"]] = (r["time"], r["energy"])
    zero = [v for k, v in outcomes.items() if k[3] == 0]
    assert len(zero) == 2 * 2 * 30  # triples x PWW settings x runs
    assert all(v["I"] == v["II"] == v["III"] for v in zero)
    heterogeneous = [v for k, v in outcomes.items() if k[3] == 800]
    assert sum(not v["I"] == v["II"] == v["III"] for v in heterogeneous) > len(heterogeneous) // 2
    verdict = verdicts_of(region1_rows, REGION1)["8: 0 % heterogeneity"]
    assert verdict.reproduced is True and verdict.teamsim == "different results on 0 of 120 problems"


def test_claim_8_region_1_ii_and_iii_much_better_than_i(region1_rows):
    """Reproduced in energy in both PWW settings; in time only by II with PWW and III without: the other two
    are listed as disagreements, with the mechanisms their causes name shown in the same runs."""
    change = {}
    for pww in (True, False):
        for metric in ("time", "energy"):
            means = cell_means(region1_rows, metric, lambda p, region, x: p == pww and region == 1 and x != "none")
            for s in ("II", "III"):
                change[(pww, metric, s)] = means[s] / means["I"] - 1
    for pww in (True, False):
        for s in ("II", "III"):
            assert change[(pww, "energy", s)] < -0.10  # much better in energy: reproduced
    assert change[(True, "time", "II")] < -MUCH_BETTER and change[(False, "time", "III")] < -MUCH_BETTER
    assert change[(True, "time", "III")] > -MUCH_BETTER and change[(False, "time", "II")] > -MUCH_BETTER

    verdict = verdicts_of(region1_rows, REGION1)["8: region 1"]
    assert verdict.reproduced is False
    assert sorted(cause for cause, _ in verdict.flags) == ["region1_ii", "region1_iii"]
    text = report(region1_rows, REGION1, SEED, 0.0, 1)
    found = listed(text)
    assert any(line.startswith("Claim 8: region 1: PWW yes, time: III") for line in found["region1_iii"])
    assert any(line.startswith("Claim 8: region 1: PWW no, time: II") for line in found["region1_ii"])
    glance_row = text.split("| 8: region 1 |")[1].split("\n")[0]
    assert glance_row.endswith(" | partly |") or glance_row.endswith(" | **no** |")
    assert f"| {verdict.holding}/{verdict.cells} |" in glance_row and verdict.holding < verdict.cells
    # The table rows behind the same claim ("II or III" in region 1) are listed too, not only marked "overlaps".
    assert any(line.startswith("Claim 8: Table 4.2: PWW yes, region 1") for line in found["table"])

    # The causes' mechanisms: with PWW, I's impatient faster robots join and finish what a slower robot started
    # under III; without PWW, II hands tasks to the fastest robot, who restarts them.
    share = defaultdict(list)
    for r in region1_rows:
        if r["part"] == "strategies" and r["heterogeneity"] > 0 and r["boredom"] == 10.0:
            share[(r["pww"], r["strategy"])].append(r["best_share"])
    share = {k: np.nanmean(v) for k, v in share.items()}
    assert share[(1, "I")] > share[(1, "III")] + 0.05
    assert share[(0, "II")] > 0.95 > share[(0, "I")] + 0.2
    energy_with_pww = cell_means(region1_rows, "energy", lambda p, region, x: p and region == 1 and x != "none")
    assert energy_with_pww["I"] > energy_with_pww["III"] * 1.1  # I buys its time with energy


def test_claim_9_strategy_iv_as_good_or_better_in_time_not_energy(strategy_iv_rows):
    cells = {}
    for pww in (True, False):
        for region in (1, 2, 3):
            for x in ("mild", "high"):
                keep = lambda p, r, h, key=(pww, region, x): (p, r, h) == key
                ratio = {}
                for metric in ("time", "energy"):
                    means = cell_means(strategy_iv_rows, metric, keep)
                    ratio[metric] = means["IV"] / min(means[s] for s in ("I", "II", "III"))
                cells[(pww, region, x)] = ratio
    good_time = {k for k, r in cells.items() if r["time"] <= 1 + TIE_TOLERANCE}
    assert {k for k in cells if k[0]} <= good_time  # with PWW: as good or better in time everywhere
    assert len(good_time) >= 10  # of 12: "almost everywhere" in time
    for key in set(cells) - good_time:  # the exceptions: without PWW, mild heterogeneity (thesis: region 2)
        assert key[0] is False and key[2] == "mild"
    worse_energy = {k for k, r in cells.items() if r["energy"] > 1 + TIE_TOLERANCE}
    assert len(worse_energy) >= 2  # not reproduced in energy with the default boredom

    verdict = verdicts_of(strategy_iv_rows, STRATEGY_IV)["9: strategy IV"]
    assert verdict.reproduced is False
    found = listed(report(strategy_iv_rows, STRATEGY_IV, SEED, 0.0, 1))
    for pww, region, x in sorted(set(cells) - good_time | worse_energy):
        if (pww, region, x) == (False, 2, "mild"):
            continue  # the thesis's own exception: not a disagreement
        where = f"PWW {'yes' if pww else 'no'}, region {region}, {x} heterogeneity"
        cause = "iv_override" if (pww, region, x) not in good_time else "iv_energy"
        assert any(line.startswith("Claim 9: strategy IV:") and where in line for line in found[cause]), where

    # The iv_energy cause: a long boredom delay trades IV's time back for energy (pooled heterogeneous cells).
    for pww in (True, False):
        keep = lambda p, r, h, pww=pww: p == pww and h in ("mild", "high")
        time, energy = cell_means(strategy_iv_rows, "time", keep), cell_means(strategy_iv_rows, "energy", keep)
        long = f"IV@{LONG_BOREDOM:g}"
        assert energy[long] < min(energy[s] for s in ("I", "II", "III")) < energy["IV"]
        assert time[long] > time["IV"]


def test_claim_12_mean_within_20_percent_of_optimal_and_best_in_region_1():
    regions = [region_of(c, m) for _, m, c in OPTIMAL_MEANS.optimal_triples]
    assert [regions.count(k) for k in (1, 2, 3)] == [37, 16, 26]
    rows = study_rows(OPTIMAL_MEANS, SEED)
    over = over_optimal(rows)
    for pww in (0, 1):
        for metric in ("time", "energy"):
            means = {region: np.mean([d[metric] for (p, t), d in over.items()
                                      if p == pww and region_of(t[2], t[1]) == region]) for region in (1, 2, 3)}
            assert all(0 <= mean < UNDER_OPTIMAL for mean in means.values()), (pww, metric, means)
            assert means[1] < min(means[2], means[3])  # "much better performance in region 1"
    verdicts = verdicts_of(rows, OPTIMAL_MEANS)
    assert verdicts["12: mean over optimal"].reproduced is True
    assert verdicts["12: best in region 1"].reproduced is True
    assert verdicts["12: triples"].reproduced is True


def test_claim_12_worst_cases_bracket_the_thesis_and_are_flagged():
    """At the thesis's worst triples (200 runs), teamsim without PWW is above the thesis's figure and with PWW
    below it (the cause: the thesis does not say which held); the claim is listed as a disagreement."""
    rows = study_rows(OPTIMAL_WORST, SEED)
    over = over_optimal(rows)
    for metric, triple, thesis in (("time", (4, 8, 3), 28.0), ("energy", (5, 6, 5), 25.0)):
        assert over[(0, triple)][metric] > thesis > over[(1, triple)][metric], (metric, over)
    assert 30 < over[(0, (4, 8, 3))]["time"] < 45 and 8 < over[(1, (4, 8, 3))]["time"] < 20
    assert 25 < over[(0, (5, 6, 5))]["energy"] < 35 and 10 < over[(1, (5, 6, 5))]["energy"] < 20
    verdict = verdicts_of(rows, OPTIMAL_WORST)["12: worst cases"]
    assert verdict.reproduced is False
    found = listed(report(rows, OPTIMAL_WORST, SEED, 0.0, 1))
    for metric, triple in (("time", "(4, 8, 3)"), ("energy", "(5, 6, 5)")):
        assert any(line.startswith(f"Claim 12: worst cases: worst triple in {metric}:") and triple in line
                   for line in found["optimal_worst"]), metric


def test_every_claim_not_reproduced_is_listed_with_its_cause(region1_rows, strategy_iv_rows):
    rows = region1_rows + strategy_iv_rows
    study = StudyPlan(runs=20, triples=REGION1.triples + STRATEGY_IV.triples, heterogeneity=(0, 100, 200, 800),
                      ordering_triple=None, optimal_triples=())
    verdicts = claim_verdicts(rows, study)
    found = listed(report(rows, study, SEED, 0.0, 1))
    listed_lines = {(cause, line) for cause, lines in found.items() for line in lines}
    assert any(v.reproduced is False for v in verdicts) and any(v.reproduced is True for v in verdicts)
    for v in verdicts:
        mine = {(cause, line) for cause, line in listed_lines if line.startswith(f"Claim {v.claim}: ")}
        if v.reproduced is False:
            assert mine == {(cause, f"Claim {v.claim}: {text}") for cause, text in v.flags}
        else:
            assert not mine and not v.flags


def test_a_verdict_says_yes_partly_or_no_by_the_cells_that_hold():
    from teamsim.tasks.studies.lalliance import Verdict
    held_everywhere = Verdict("c", "t", "f", cells=4, held=4)
    assert (held_everywhere.word, held_everywhere.holding) == ("yes", 4)
    some = Verdict("c", "t", "f", cells=4, held=1)
    some.flag("unexplained", "three cells do not hold")
    assert some.word == "partly"
    none = Verdict("c", "t", "f", cells=2, held=0)
    none.flag("unexplained", "no cell holds")
    assert none.word == "**no**"
    one_cell = Verdict("c", "t", "f")  # a single check: a disagreement leaves no cell holding
    one_cell.flag("unexplained", "it does not hold")
    assert (one_cell.holding, one_cell.word) == (0, "**no**")
    assert Verdict("c", "t", "f", measured=False).word == "n/a"

"""A study's findings against a thesis, as its ``report.md`` prints them: each claim in the thesis's words, teamsim's
figure, for the comparison it turns on (paired over the seeds the conditions share) the ratio of the means with its
95 % confidence interval and a p-value, and a verdict by the thesis's own criterion: **yes** where the statement
holds as worded, **partly** where some of it does, **no** where none does, "n/a" where it was not measured. A
comparison with p >= 0.05 is "not decided by this sample".
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from teamsim.stats import paired_t_test, ratio_ci


@dataclass(frozen=True)
class Finding:
    claim: str
    thesis: str
    teamsim: str
    verdict: str  # "yes", "partly", "**no**" or "n/a"
    p: float = math.nan  # paired two-sided t-test over the seeds, for the comparison the claim turns on
    ratio: str = ""  # that comparison's ratio of the means with its 95 % confidence interval (ratio_text)


class Comparison(NamedTuple):
    """Group a against group b over the seeds both completed, as a :class:`Finding` takes it (``*comparison``)."""
    p: float
    ratio: str


def verdict(held: int, of: int) -> str:
    return "n/a" if of == 0 else "yes" if held == of else "partly" if held else "**no**"


def per_seed(rows: list[dict], key: str, group: str, value: str) -> dict[int, float]:
    """``key`` per seed in the rows whose ``group`` column is ``value``, completed missions only."""
    return {r["seed"]: r[key] for r in rows if r[group] == value and r["completed"] and r[key] is not None}


def paired(rows: list[dict], key: str, group: str, a: str, b: str) -> tuple[list[float], list[float]]:
    """``key`` of groups a and b over the seeds where both completed, in seed order."""
    first, second = per_seed(rows, key, group, a), per_seed(rows, key, group, b)
    seeds = sorted(set(first) & set(second))
    return [first[s] for s in seeds], [second[s] for s in seeds]


def compare(rows: list[dict], key: str, group: str, a: str, b: str) -> Comparison:
    """Groups a and b in ``key``, paired by seed (both completed): the paired t-test's p and a's mean over b's with
    its 95 % confidence interval."""
    first, second = paired(rows, key, group, a, b)
    return Comparison(paired_t_test(first, second)[1], ratio_text(f"{a}/{b}", *ratio_ci(first, second)))


def weakest(comparisons) -> Comparison:
    """The comparison of an ordering with the largest p: the one the ordering's p stands for."""
    return max(comparisons, key=lambda c: c.p)


def ratio_text(label: str, ratio: float, low: float, high: float) -> str:
    """"a/b 0.85 [0.80, 0.91]": a ratio of means with its confidence interval ("-" when there is none)."""
    return "-" if math.isnan(ratio) else f"{label} {ratio:.2f} {interval_text(low, high)}"


def interval_text(low: float, high: float) -> str:
    """"[0.80, 0.91]", "[unbounded]", or "" for no interval."""
    if math.isnan(low):
        return ""
    return "[unbounded]" if math.isinf(low) else f"[{low:.2f}, {high:.2f}]"


def table(findings: list[Finding], criterion: str = "") -> list[str]:
    """The findings as a markdown table, with the legend above it (``criterion``: what "as worded" means here)."""
    lines = [f"**yes** where the thesis's statement holds as worded{criterion}, **partly** where some of it does, "
             "**no** where none does. p: paired two-sided t-test over the seeds for the comparison the claim turns "
             "on (the weakest pair of an ordering); p >= 0.05 means this sample does not decide it. Ratio: the "
             "same pair's ratio of the means over those seeds, with its 95 % confidence interval (Fieller's, "
             "paired; unbounded when the denominator's mean is not clearly above zero).", "",
             "| claim | thesis | teamsim | ratio [95 % CI] | p | reproduced |", "|---|---|---|---|---|---|"]
    for found in findings:
        undecided = found.p >= 0.05 and found.verdict != "**no**"
        lines.append(f"| {found.claim} | {found.thesis} | {found.teamsim} | {found.ratio or '-'} | "
                     f"{'-' if math.isnan(found.p) else f'{found.p:.2g}'} | "
                     f"{found.verdict}{', not decided by this sample' if undecided else ''} |")
    return lines

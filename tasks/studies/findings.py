"""A study's findings against a thesis, as its ``report.md`` prints them: each claim in the thesis's words, teamsim's
figure, a p-value for the comparison it turns on (paired over the seeds the conditions share) and a verdict by the
thesis's own criterion: **yes** where the statement holds as worded, **partly** where some of it does, **no** where
none does, "n/a" where it was not measured. A comparison with p >= 0.05 is "not decided by this sample".
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from teamsim.stats import paired_t_test


@dataclass(frozen=True)
class Finding:
    claim: str
    thesis: str
    teamsim: str
    verdict: str  # "yes", "partly", "**no**" or "n/a"
    p: float = math.nan  # paired two-sided t-test over the seeds, for the comparison the claim turns on


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


def paired_p(rows: list[dict], key: str, group: str, a: str, b: str) -> float:
    """p of groups a and b differing in ``key``, paired by seed (both completed)."""
    return paired_t_test(*paired(rows, key, group, a, b))[1]


def table(findings: list[Finding], criterion: str = "") -> list[str]:
    """The findings as a markdown table, with the legend above it (``criterion``: what "as worded" means here)."""
    lines = [f"**yes** where the thesis's statement holds as worded{criterion}, **partly** where some of it does, "
             "**no** where none does. p: paired two-sided t-test over the seeds for the comparison the claim turns "
             "on (the weakest pair of an ordering); p >= 0.05 means this sample does not decide it.", "",
             "| claim | thesis | teamsim | p | reproduced |", "|---|---|---|---|---|"]
    for found in findings:
        undecided = found.p >= 0.05 and found.verdict != "**no**"
        lines.append(f"| {found.claim} | {found.thesis} | {found.teamsim} | "
                     f"{'-' if math.isnan(found.p) else f'{found.p:.2g}'} | "
                     f"{found.verdict}{', not decided by this sample' if undecided else ''} |")
    return lines

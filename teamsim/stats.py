"""Statistics for study reports, from ``scipy.stats``: the paired two-sided t-test Chand uses (§3.6.2) and a
confidence interval for the ratio of two paired means."""
from __future__ import annotations

import math
import warnings

import numpy as np
from scipy import stats


def paired_t_test(a, b) -> tuple[float, float]:
    """(t, two-sided p) for the mean of the paired differences a - b; p = nan with fewer than two pairs,
    p = 1 (or 0) when every difference is the same zero (or non-zero) value."""
    diff = np.asarray(a, float) - np.asarray(b, float)
    if len(diff) < 2:
        return math.nan, math.nan
    if diff.std() == 0.0:  # scipy returns nan here
        mean = float(diff.mean())
        return (0.0, 1.0) if mean == 0.0 else (math.copysign(math.inf, mean), 0.0)
    with warnings.catch_warnings():  # differences equal but for rounding: a huge t, and scipy warns of it
        warnings.filterwarnings("ignore", "Precision loss", RuntimeWarning)
        result = stats.ttest_rel(a, b)
    return float(result.statistic), float(result.pvalue)


def ratio_ci(a, b, level: float = 0.95) -> tuple[float, float, float]:
    """(mean(a) / mean(b), low, high): Fieller's confidence interval for the ratio of two paired means, the ratios
    R that the paired t-test of a against R b does not reject at 1 - ``level``. Low and high are infinite when
    mean(b) itself is not clearly away from zero (the interval is unbounded); all three nan with fewer than two
    pairs or mean(b) = 0."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    n = len(a)
    if n < 2 or b.mean() == 0.0:
        return math.nan, math.nan, math.nan
    ratio = float(a.mean() / b.mean())
    (s_aa, s_ab), (_, s_bb) = np.cov(a, b, ddof=1)
    q = stats.t.ppf(0.5 + level / 2, n - 1) ** 2 / n
    # (mean(a) - R mean(b))^2 <= q var(a - R b), a quadratic in R: A R^2 - 2 B R + C <= 0.
    quad = b.mean() ** 2 - q * s_bb
    half = b.mean() * a.mean() - q * s_ab
    const = a.mean() ** 2 - q * s_aa
    if quad <= 0.0:
        return ratio, -math.inf, math.inf
    root = math.sqrt(max(half * half - quad * const, 0.0))
    return ratio, float((half - root) / quad), float((half + root) / quad)

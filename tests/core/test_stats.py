"""The paired t-test against textbook values and scipy, and Fieller's interval for a ratio of paired means."""
import math

import numpy as np
import pytest
from scipy import stats

from teamsim.stats import paired_t_test, ratio_ci


def test_paired_t_test_matches_tables():
    # Differences 1, 2, 3, 4, 5: mean 3, sd 1.5811, t = 4.2426 on 4 dof, two-sided p = 0.01324.
    t, p = paired_t_test([2, 4, 6, 8, 10], [1, 2, 3, 4, 5])
    assert t == pytest.approx(4.2426, abs=1e-4)
    assert p == pytest.approx(0.01324, abs=1e-4)
    # t = 2.262157 is the 5 % two-sided critical value on 9 dof: build differences with exactly that t.
    spread = [-1.5, -1, -0.5, -0.2, 0, 0, 0.2, 0.5, 1, 1.5]
    sd = math.sqrt(sum(e * e for e in spread) / 9)
    t, p = paired_t_test([2.262157 * sd / math.sqrt(10) + e for e in spread], [0.0] * 10)
    assert t == pytest.approx(2.262157, abs=1e-6)
    assert p == pytest.approx(0.05, abs=1e-5)


def test_paired_t_test_student_1908_sleep_data():
    # Student's (1908) hours of extra sleep under two drugs, 10 patients (R's `sleep`): t = -4.0621 on 9 dof,
    # p = 0.002833.
    drug_1 = [0.7, -1.6, -0.2, -1.2, -0.1, 3.4, 3.7, 0.8, 0.0, 2.0]
    drug_2 = [1.9, 0.8, 1.1, 0.1, -0.1, 4.4, 5.5, 1.6, 4.6, 3.4]
    t, p = paired_t_test(drug_1, drug_2)
    assert t == pytest.approx(-4.0621, abs=1e-4)
    assert p == pytest.approx(0.002833, abs=1e-6)


def test_paired_t_test_is_scipys_with_the_degenerate_cases_defined():
    rng = np.random.default_rng(4)
    a, b = rng.normal(10, 2, 12), rng.normal(9, 2, 12)
    expected = stats.ttest_rel(a, b)
    assert paired_t_test(a, b) == pytest.approx((expected.statistic, expected.pvalue), rel=1e-12)
    assert paired_t_test([0.0] * 10, [0.0] * 10) == (0.0, 1.0)
    assert paired_t_test([2.0, 3.0], [1.0, 2.0]) == (math.inf, 0.0)
    assert math.isnan(paired_t_test([1.0], [0.0])[1])


def test_ratio_ci_is_the_paired_t_test_inverted():
    """Fieller's interval holds the ratios R that the paired t-test of a against R b does not reject: at its ends
    p is exactly 0.05, and it holds 1 exactly when a and b themselves do not differ at the 5 % level."""
    rng = np.random.default_rng(1)
    b = rng.normal(10, 2, 12)
    a = 0.8 * b + rng.normal(0, 1, 12)
    ratio, low, high = ratio_ci(a, b)
    assert ratio == pytest.approx(a.mean() / b.mean())
    assert low < ratio < high
    assert stats.ttest_rel(a, low * b).pvalue == pytest.approx(0.05)
    assert stats.ttest_rel(a, high * b).pvalue == pytest.approx(0.05)
    for shift in (0.0, 0.5, 2.0):
        _, low, high = ratio_ci(a + shift, b)
        assert (low <= 1 <= high) == (paired_t_test(a + shift, b)[1] >= 0.05)


def test_ratio_ci_against_a_constant_is_the_means_interval_scaled():
    a = [7.1, 8.4, 9.0, 7.7, 8.8, 9.6]
    expected = stats.ttest_1samp(a, 0.0).confidence_interval(0.95)
    _, low, high = ratio_ci(a, [4.0] * 6)
    assert (low, high) == pytest.approx((expected.low / 4, expected.high / 4))


def test_ratio_ci_unbounded_and_undefined():
    assert ratio_ci([1.0, 2.0, 3.0], [-1.0, 1.0, 0.5])[1:] == (-math.inf, math.inf)  # mean(b) not clear of zero
    assert all(math.isnan(v) for v in ratio_ci([1.0], [2.0]))
    assert all(math.isnan(v) for v in ratio_ci([1.0, 2.0], [1.0, -1.0]))

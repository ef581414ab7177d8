"""The paired t-test against values from standard tables."""
import math

import pytest

from teamsim.stats import incomplete_beta, paired_t_test


def test_incomplete_beta_known_values():
    assert incomplete_beta(1, 1, 0.3) == pytest.approx(0.3)
    assert incomplete_beta(2, 3, 0.4) == pytest.approx(0.5248, abs=1e-4)  # 1 - sum binomial tail
    assert incomplete_beta(0.5, 0.5, 0.5) == pytest.approx(0.5)


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
    t, p = paired_t_test([0.0] * 10, [0.0] * 10)
    assert (t, p) == (0.0, 1.0)
    assert math.isnan(paired_t_test([1.0], [0.0])[1])

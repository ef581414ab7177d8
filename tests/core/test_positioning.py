"""Unit tests for teamsim.positioning.PositioningService.

Statistical tolerance used below: for n independent N(0, sigma^2) draws the sample standard deviation s
satisfies s/sigma ~ 1 +- 1/sqrt(2(n-1)) (normal approximation of chi-square with n-1 degrees of freedom).
We accept |s/sigma - 1| <= 4/sqrt(2(n-1)) and |mean| <= 4 sigma/sqrt(n), with fixed seeds.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamsim.config import PositioningConfig
from teamsim.positioning import PositioningService
from teamsim.rng import RandomStreams

SEED = 42


def make_service(names, seed=SEED, **cfg):
    streams = RandomStreams(seed)
    return PositioningService(PositioningConfig(**cfg), {n: streams.get("robot", n, "positioning") for n in names})


def collect_errors(speed, n_fixes, **cfg):
    """Errors (dx, dy, dheading) of n_fixes fixes spread over 20 robots at the given speed."""
    names = [f"r{i}" for i in range(20)]
    service = make_service(names, **cfg)
    rng = np.random.default_rng(7)
    truth = {n: np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-3, 3)]) for n in names}
    period = service.config.period
    errors = []
    for k in range(n_fixes // len(names)):
        assert service.update(k * period, truth, {n: speed for n in names})
        for n in names:
            fix = service.fix(n)
            errors.append((fix.x - truth[n][0], fix.y - truth[n][1], fix.heading - truth[n][2]))
    return np.array(errors)


def assert_std(samples, sigma):
    n = samples.size
    s = samples.std(ddof=1)
    assert abs(s / sigma - 1) <= 4 / math.sqrt(2 * (n - 1)), (s, sigma)
    assert abs(samples.mean()) <= 4 * sigma / math.sqrt(n), (samples.mean(), sigma)


def test_defaults_match_parker():
    cfg = PositioningConfig()
    assert cfg.period == pytest.approx(0.6)
    assert cfg.noise_still == pytest.approx(0.0127)
    assert cfg.noise_moving == pytest.approx(0.15)


@pytest.mark.parametrize("speed", [0.0, 0.01, 0.02])  # 0.02 == moving_speed still counts as still
def test_still_noise_std(speed):
    errors = collect_errors(speed, 2000)
    assert len(errors) == 2000
    # x and y pooled: 4000 samples -> tolerance 4/sqrt(7998) = 4.5 %
    assert_std(errors[:, :2].ravel(), PositioningConfig().noise_still)


@pytest.mark.parametrize("speed", [0.021, 0.3])
def test_moving_noise_std(speed):
    errors = collect_errors(speed, 2000)
    assert_std(errors[:, 0], PositioningConfig().noise_moving)  # 2000 samples: 6.3 %
    assert_std(errors[:, 1], PositioningConfig().noise_moving)


def test_heading_noise_std():
    errors = collect_errors(0.0, 2000)  # true headings in [-3, 3]; noise 0.05 never wraps
    assert_std(errors[:, 2], PositioningConfig().heading_noise)


def test_axes_are_independent():
    errors = collect_errors(0.3, 2000)
    r = np.corrcoef(errors[:, 0], errors[:, 1])[0, 1]
    assert abs(r) <= 4 / math.sqrt(2000)


def test_no_fix_before_first_update():
    service = make_service(["a"])
    assert service.fix("a") is None


def test_fix_updates_only_every_period_and_holds_between():
    service = make_service(["a"])
    pose = {"a": np.array([1.0, 2.0, 0.5])}
    updates = []
    previous = None
    for k in range(61):  # 0 .. 6 s in 0.1 s steps
        now = k / 10
        updated = service.update(now, pose, {"a": 0.0})
        fix = service.fix("a")
        if updated:
            updates.append(now)
            assert fix.time == now
            assert fix != previous
        else:
            assert fix == previous  # holds its last fix
        previous = fix
    np.testing.assert_allclose(updates, np.arange(11) * 0.6, atol=1e-12)


def test_update_skipped_when_called_early_and_resumes_on_schedule():
    service = make_service(["a"], period=0.6)
    pose = {"a": np.zeros(3)}
    assert service.update(0.0, pose, {"a": 0.0})
    assert not service.update(0.599, pose, {"a": 0.0})
    assert service.update(0.6, pose, {"a": 0.0})
    # A long gap: one update at 5.0, next due at 5.4 (next multiple of the period), not 5.6.
    assert service.update(5.0, pose, {"a": 0.0})
    assert not service.update(5.39, pose, {"a": 0.0})
    assert service.update(5.4, pose, {"a": 0.0})


def test_fix_tracks_true_pose_when_moving_changes():
    service = make_service(["a"], noise_still=0.0, noise_moving=0.0, heading_noise=0.0)
    service.update(0.0, {"a": np.array([1.0, 2.0, 0.3])}, {"a": 0.0})
    fix = service.fix("a")
    assert (fix.x, fix.y) == (1.0, 2.0)
    assert fix.heading == pytest.approx(0.3)
    # Robot moves, but no update is due yet: fix is stale.
    service.update(0.3, {"a": np.array([4.0, 5.0, 0.3])}, {"a": 1.0})
    assert (service.fix("a").x, service.fix("a").y) == (1.0, 2.0)
    service.update(0.6, {"a": np.array([4.0, 5.0, 0.3])}, {"a": 1.0})
    assert (service.fix("a").x, service.fix("a").y) == (4.0, 5.0)


def test_same_seed_same_fixes():
    def fixes(seed):
        service = make_service(["a", "b"], seed=seed)
        out = []
        for k in range(5):
            service.update(k * 0.6, {"a": np.zeros(3), "b": np.ones(3)}, {"a": 0.0, "b": 1.0})
            out += [service.fix("a"), service.fix("b")]
        return out
    assert fixes(1) == fixes(1)
    assert fixes(1) != fixes(2)


def wrapped_heading(true_heading, heading_noise=0.0):
    service = make_service(["a"], heading_noise=heading_noise)
    service.update(0.0, {"a": np.array([0.0, 0.0, true_heading])}, {"a": 0.0})
    return service.fix("a").heading


@settings(max_examples=300, deadline=None)
@given(st.floats(min_value=-100.0, max_value=100.0, allow_nan=False))
def test_heading_wrapped_into_half_open_interval(heading):
    wrapped = wrapped_heading(heading)
    assert -math.pi <= wrapped < math.pi
    # Same direction as the true heading.
    assert math.cos(wrapped) == pytest.approx(math.cos(heading), abs=1e-9)
    assert math.sin(wrapped) == pytest.approx(math.sin(heading), abs=1e-9)


@pytest.mark.parametrize("heading", [math.pi, -math.pi, 3 * math.pi, 2 * math.pi, 0.0])
def test_heading_wrap_at_boundaries(heading):
    wrapped = wrapped_heading(heading)
    assert -math.pi <= wrapped < math.pi


def test_heading_just_below_minus_pi_wraps_into_range():
    # The float just below -pi: (h + pi) % 2pi rounds up to exactly 2pi, giving +pi, outside [-pi, pi).
    heading = float(np.nextafter(-np.pi, -np.inf))
    wrapped = wrapped_heading(heading)
    assert -math.pi <= wrapped < math.pi, wrapped


def test_heading_near_pi_with_noise_wraps():
    service = make_service([f"r{i}" for i in range(50)])
    names = [f"r{i}" for i in range(50)]
    service.update(0.0, {n: np.array([0.0, 0.0, math.pi - 0.01]) for n in names}, {n: 0.0 for n in names})
    headings = np.array([service.fix(n).heading for n in names])
    assert np.all((headings >= -math.pi) & (headings < math.pi))
    assert np.any(headings < 0)  # some noisy fixes crossed +pi and wrapped to near -pi
    assert np.all(np.abs(np.angle(np.exp(1j * (headings - (math.pi - 0.01))))) < 0.3)

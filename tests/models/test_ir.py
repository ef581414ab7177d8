"""Unit tests for the IR range sensor model (teamsim.models.ir).

Statistical tolerance: for n draws the sample std s of readings with true std sigma satisfies
|s/sigma - 1| <= 4/sqrt(2(n-1)) (4 sigma, normal approximation of chi-square); the quantisation to
``resolution`` adds variance resolution^2/12, which is included in sigma.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamsim.models.ir import IRModel

MAX_RANGE = 1.5
FULL_SCALE = 1023.0


@pytest.fixture(scope="module")
def model():
    return IRModel.for_range(MAX_RANGE)


def test_for_range_scales_table(model):
    assert model.max_range == pytest.approx(MAX_RANGE)
    assert model.distances[0] == 0.0
    assert model.responses[0] == pytest.approx(FULL_SCALE)
    assert model.responses[-1] == 0.0
    assert model.resolution == 1.0


def test_response_at_table_points(model):
    np.testing.assert_allclose(model.response(np.array(model.distances[:-1])), model.responses[:-1])


def test_response_strictly_falling_on_grid(model):
    d = np.linspace(0.0, MAX_RANGE, 1501)[:-1]
    r = model.response(d)
    assert np.all(np.diff(r) < 0)
    assert r[0] == pytest.approx(FULL_SCALE)
    assert np.all(r > 0)


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=0.0, max_value=2 * MAX_RANGE), st.floats(min_value=0.0, max_value=2 * MAX_RANGE))
def test_response_monotone_non_increasing(model, a, b):
    lo, hi = sorted((a, b))
    assert model.response(lo) >= model.response(hi)
    assert 0.0 <= model.response(hi) <= FULL_SCALE


@pytest.mark.parametrize("distance", [MAX_RANGE, MAX_RANGE + 1e-9, 2.0, 100.0, math.inf, -1.0, -1e-9, -math.inf])
def test_response_zero_at_or_beyond_max_range_and_on_miss(model, distance):
    assert model.response(distance) == 0.0
    assert model.read(distance, 0.0) == 0.0
    assert model.read(distance, 3.0) == 0.0  # no signal, so no noise either
    assert model.to_range(model.read(distance, 3.0)) == math.inf


def test_response_vectorised(model):
    d = np.array([-1.0, 0.0, 0.75, 1.5, 3.0])
    r = model.response(d)
    assert r.shape == d.shape
    assert r[0] == 0 and r[-1] == 0 and r[-2] == 0
    assert r[1] > r[2] > 0


def test_read_without_noise_is_quantised_clean_response(model):
    d = np.linspace(-0.5, 2.0, 401)
    clean = model.response(d)
    np.testing.assert_array_equal(model.read(d, np.zeros_like(d)), np.round(clean))


@pytest.mark.parametrize("distance", [0.3, 0.6, 1.2])
def test_read_noise_std_is_noise_fraction_of_response(model, distance):
    n = 20_000
    noise = np.random.default_rng(2024).standard_normal(n)
    raw = model.read(np.full(n, distance), noise)
    clean = float(model.response(distance))
    fraction = float(np.interp(distance, model.distances, model.noise_fractions))
    sigma = math.sqrt((fraction * clean) ** 2 + model.resolution ** 2 / 12)
    s = raw.std(ddof=1)
    assert abs(s / sigma - 1) <= 4 / math.sqrt(2 * (n - 1)), (s, sigma)
    assert abs(raw.mean() - clean) <= 4 * sigma / math.sqrt(n) + 0.05  # small quantisation bias allowed


def test_noise_grows_with_distance_as_fraction(model):
    # Noise fraction rises with distance (1 % at contact to 12 % at the far end).
    fractions = np.interp([0.0, 0.3, 0.6, 1.2], model.distances, model.noise_fractions)
    assert np.all(np.diff(fractions) > 0)


@pytest.mark.parametrize("resolution", [1.0, 0.5, 10.0, 2.0])
def test_readings_quantised_and_within_full_scale(resolution):
    model = IRModel.for_range(MAX_RANGE, resolution=resolution)
    rng = np.random.default_rng(5)
    d = rng.uniform(-0.2, 1.8, 5000)
    d[:50] = 0.0  # full-scale readings pushed above full scale by noise: must clip
    noise = 40.0 * rng.standard_normal(d.size)  # huge noise: exercises both clipping ends
    raw = model.read(d, noise)
    assert np.all(raw >= 0.0)
    assert np.all(raw <= FULL_SCALE), raw.max()
    np.testing.assert_allclose(raw / resolution, np.round(raw / resolution), atol=1e-9)
    assert np.any(raw == 0.0)


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=0.001, max_value=1.4))
def test_to_range_inverts_clean_reading(model, distance):
    estimate = float(model.to_range(model.read(distance, 0.0)))
    # Quantisation error 0.5 count over the flattest slope below 1.4 m (51 counts per 0.3 m) < 0.003 m.
    assert abs(estimate - distance) <= 0.005


def test_to_range_inverts_response_exactly_without_quantisation(model):
    d = np.linspace(0.0, MAX_RANGE, 301)[:-1]
    np.testing.assert_allclose(model.to_range(model.response(d)), d, atol=1e-9)


def test_to_range_special_values(model):
    assert model.to_range(0.0) == math.inf
    assert model.to_range(FULL_SCALE) == pytest.approx(0.0)
    raw = np.arange(1, 1024, dtype=float)
    ranges = model.to_range(raw)
    assert np.all(np.isfinite(ranges))
    assert np.all(np.diff(ranges) < 0)  # more light -> nearer
    assert np.all((ranges >= 0) & (ranges < MAX_RANGE))


def test_read_and_to_range_preserve_shape(model):
    d = np.full((3, 4), 0.5)
    raw = model.read(d, np.zeros((3, 4)))
    assert raw.shape == (3, 4)
    assert model.to_range(raw).shape == (3, 4)


@pytest.mark.parametrize("distances, responses, noise", [
    ((0.0,), (0.0,), (0.1,)),                               # one row
    ((), (), ()),                                           # empty
    ((0.0, 1.0), (10.0, 0.0), (0.1,)),                      # noise length mismatch
    ((0.0, 1.0, 2.0), (10.0, 0.0), (0.1, 0.1, 0.1)),        # response length mismatch
    ((0.0, 1.0, 1.0), (10.0, 5.0, 0.0), (0.1, 0.1, 0.1)),   # repeated distance
    ((1.0, 0.5, 2.0), (10.0, 5.0, 0.0), (0.1, 0.1, 0.1)),   # decreasing distance
    ((0.0, 1.0, 2.0), (10.0, 10.0, 0.0), (0.1, 0.1, 0.1)),  # flat response
    ((0.0, 1.0, 2.0), (5.0, 10.0, 0.0), (0.1, 0.1, 0.1)),   # rising response
    ((0.0, 1.0, 2.0), (10.0, 5.0, 1.0), (0.1, 0.1, 0.1)),   # does not end at 0
])
def test_invalid_tables_raise(distances, responses, noise):
    with pytest.raises(ValueError):
        IRModel(distances, responses, noise)


def test_valid_custom_table():
    model = IRModel((0.1, 0.5, 1.0), (100.0, 20.0, 0.0), (0.0, 0.0, 0.0))
    assert model.max_range == 1.0
    assert model.response(0.3) == pytest.approx(60.0)
    assert model.read(0.3, 5.0) == 60.0  # zero noise fraction: noise has no effect
    assert model.to_range(60.0) == pytest.approx(0.3)

"""Unit tests for teamsim.rng.RandomStreams."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamsim.rng import RandomStreams

PATH = ("robot", "red", "ir")


def draws(seed, *path, n=16):
    return RandomStreams(seed).get(*path).random(n)


def test_same_seed_and_path_identical():
    np.testing.assert_array_equal(draws(7, *PATH), draws(7, *PATH))


def test_get_returns_fresh_generator_each_time():
    streams = RandomStreams(7)
    a = streams.get(*PATH)
    first = a.random(8)
    b = streams.get(*PATH)  # not the same, already-advanced generator
    assert b is not a
    np.testing.assert_array_equal(b.random(8), first)


@pytest.mark.parametrize("other", [
    ("robot", "red", "radio"),
    ("robot", "blue", "ir"),
    ("robot", "red"),
    ("robot", "red", "ir", "x"),
    ("red", "robot", "ir"),        # order of parts matters
    ("robot", "redir", ""),        # concatenation does not collide
    ("robotred", "ir"),
    (),
])
def test_different_path_different_draws(other):
    assert not np.array_equal(draws(7, *PATH), draws(7, *other))


@pytest.mark.parametrize("seed_a, seed_b", [(0, 1), (7, 8), (1, 2**32 + 1), (2**63 - 1, 2**63 - 2)])
def test_different_seed_different_draws(seed_a, seed_b):
    assert not np.array_equal(draws(seed_a, *PATH), draws(seed_b, *PATH))


def test_independent_of_creation_order_and_other_streams():
    names = [("robot", n, s) for n in ("red", "green", "blue") for s in ("ir", "radio", "positioning")]
    forward = RandomStreams(3)
    got_forward = {p: forward.get(*p).standard_normal(10) for p in names}
    backward = RandomStreams(3)
    # Create in reverse order and draw heavily from unrelated streams in between.
    got_backward = {}
    for p in reversed(names):
        backward.get("world", "obstacles").random(1000)
        got_backward[p] = backward.get(*p).standard_normal(10)
    for p in names:
        np.testing.assert_array_equal(got_forward[p], got_backward[p])
    # Adding a robot leaves the others unchanged.
    with_newcomer = RandomStreams(3)
    with_newcomer.get("robot", "purple", "ir").random(100)
    np.testing.assert_array_equal(with_newcomer.get("robot", "red", "ir").standard_normal(10),
                                  got_forward[("robot", "red", "ir")])


def test_streams_are_statistically_uncorrelated():
    streams = RandomStreams(11)
    a = streams.get("robot", "red", "ir").standard_normal(10_000)
    b = streams.get("robot", "green", "ir").standard_normal(10_000)
    assert abs(np.corrcoef(a, b)[0, 1]) < 4 / np.sqrt(10_000)


def test_seed_stored_as_int():
    assert RandomStreams(np.int64(5)).seed == 5
    assert type(RandomStreams(np.int64(5)).seed) is int
    np.testing.assert_array_equal(draws(np.int64(5), *PATH), draws(5, *PATH))


@settings(max_examples=50, deadline=None)
@given(st.integers(min_value=0, max_value=2**63 - 1),
       st.lists(st.text(min_size=1, max_size=8), min_size=1, max_size=4))
def test_reproducible_for_any_seed_and_path(seed, path):
    np.testing.assert_array_equal(draws(seed, *path), draws(seed, *path))
    assert not np.array_equal(draws(seed, *path), draws(seed, *path, "extra"))

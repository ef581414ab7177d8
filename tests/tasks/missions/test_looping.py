"""The failure classification of navigate trials (teamsim.tasks.missions.looping) on made-up trails."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.tasks.missions.looping import failure_kind


def test_a_circle_driven_again_and_again_is_a_loop_with_its_period_and_diameter():
    t = np.arange(0.0, 300.0, 0.1)
    period, radius = 20.0, 1.0
    xy = np.column_stack([radius * np.cos(2 * math.pi * t / period), radius * np.sin(2 * math.pi * t / period)])
    kind = failure_kind(t, xy, v_max=0.5)
    assert kind["failure"] == "looping"
    assert kind["loop_period"] == pytest.approx(period, abs=1.0)
    assert kind["loop_diameter"] == pytest.approx(2 * radius, abs=0.05)


def test_a_robot_that_barely_moves_stalled():
    t = np.arange(0.0, 300.0, 0.1)
    xy = np.column_stack([0.01 * np.sin(t), 0.01 * np.cos(t)])  # 1 cm wobble: 0.01 m/s, 2 % of v_max
    assert failure_kind(t, xy, v_max=0.5) == {"failure": "stalled", "loop_period": None, "loop_diameter": None}


def test_moving_on_without_coming_back_is_wandering():
    t = np.arange(0.0, 300.0, 0.1)
    xy = np.column_stack([0.2 * t, 2.0 * np.sin(t / 10)])  # a long zig-zag: never back where it was
    assert failure_kind(t, xy, v_max=0.5)["failure"] == "wandered"


def test_only_the_last_window_counts():
    t = np.arange(0.0, 450.0, 0.1)
    circling = t >= 250.0  # wanders first, then circles for the last 200 s
    xy = np.column_stack([np.where(circling, np.cos(t / 3), 0.2 * t), np.where(circling, np.sin(t / 3), 0.0)])
    assert failure_kind(t, xy, v_max=0.5)["failure"] == "looping"

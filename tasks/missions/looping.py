"""How a navigate trial that did not arrive failed, from the robot's trail: stalled, looping or wandering.

A navigator caught in a limit cycle (issue 22: FRC circling in an open pocket beside boxes for the rest of the
trial) is a livelock, not a slow robot, and the study counts it apart. Over the trail's last ``window`` seconds,
sampled once a second:
  - **stalled**: the mean speed stayed under ``stalled_share`` of v_max (the study's old "stalled");
  - **looping**: the robot keeps coming back to where it was: at least ``recurrent_share`` of the window's
    first-half samples are revisited (within ``revisit_radius``, after an excursion of at least twice that)
    later in the window. The loop's **period** is the median time to such a return, its **diameter** the
    largest distance between two samples of the window;
  - **wandered**: anything else (moving, not repeating itself).
The thresholds are choices (docs/decisions.md, "Looping"); the thesis only reports success.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LoopCriteria:
    window: float = 200.0  # s of trail examined, from its end
    sample_period: float = 1.0  # s between the samples compared
    stalled_share: float = 0.1  # of v_max
    revisit_radius: float = 0.3  # m
    recurrent_share: float = 0.5


def failure_kind(times, xy, v_max: float, criteria: LoopCriteria = LoopCriteria()) -> dict:
    """{"failure": "stalled" | "looping" | "wandered", "loop_period": s, "loop_diameter": m} for a trail of
    ``times`` (n,) and positions ``xy`` (n, 2); period and diameter are None unless looping."""
    times, xy = np.asarray(times, float), np.asarray(xy, float).reshape(-1, 2)
    kind = {"failure": "wandered", "loop_period": None, "loop_diameter": None}
    if times.size < 2:
        return kind | {"failure": "stalled"}
    in_window = times >= times[-1] - criteria.window
    t, p = times[in_window], xy[in_window]
    duration = t[-1] - t[0]
    travelled = float(np.hypot(*np.diff(p, axis=0).T).sum())
    if duration <= 0 or travelled / duration < criteria.stalled_share * v_max:
        return kind | {"failure": "stalled"}
    # (np.arange's float steps can end a hair past t[-1], where searchsorted answers len(t): clip to the last sample)
    picks = np.minimum(np.searchsorted(t, np.arange(t[0], t[-1] + 1e-9, criteria.sample_period)), len(t) - 1)
    t, p = t[picks], p[picks]
    returns = [_return_time(t, p, i, criteria.revisit_radius) for i in range(len(t) // 2)]
    found = [r for r in returns if r is not None]
    if len(found) >= criteria.recurrent_share * len(returns) and found:
        gaps = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
        return {"failure": "looping", "loop_period": round(float(np.median(found)), 1),
                "loop_diameter": round(float(gaps.max()), 2)}
    return kind


def _return_time(t: np.ndarray, p: np.ndarray, i: int, radius: float) -> float | None:
    """Seconds from sample i until the trail comes back within ``radius`` of it, having first left by twice
    that; None if it never does."""
    distance = np.hypot(p[i + 1:, 0] - p[i, 0], p[i + 1:, 1] - p[i, 1])
    left = np.flatnonzero(distance > 2 * radius)
    if left.size == 0:
        return None
    back = np.flatnonzero(distance[left[0]:] <= radius)
    return None if back.size == 0 else float(t[i + 1 + left[0] + back[0]] - t[i])

"""The direction sensor, Chand's "polar histogram technique" (§3.4, eq. 3.9-3.10, Table 3.2).

The first stage of reactive control: it turns the heading to the target into a modified target heading that keeps
clear of obstacles. Kinematics, dynamics and the robot's shape are ignored here: the robot is a point and every
obstacle is enlarged by r_m, the radius of the circle enclosing the robot. ``N_theta`` candidate directions,
evenly spread over the full circle starting straight ahead, are scored by
  (3.10) o_ds(theta_dir) = alpha1 (1 - |theta_dir - theta_t| / pi) + beta smooth(d_ob) / d_obmax
and the best becomes theta_tmod. d_ob(theta_dir) is the distance to the nearest obstacle along the candidate
direction, limited to [r_m, d_obmax] (d_obmax the sensing range).

Frames and choices where the thesis is silent:
  - (3.9) prints theta_t = atan((x_g - x_c)/(y_g - y_c)): the thesis measures headings from the y axis. teamsim
    measures them from the world x axis, counter-clockwise (the positioning fix's heading), so here
    theta_t = atan2(y_g - y_c, x_g - x_c), the same direction in this frame. Angles are normalised to [-pi, pi).
  - everything below works in the robot frame (x forward, y left) centred on the robot's physical centre, as
    §3.4 subtracts theta_c; |theta_dir - theta_t| is the wrapped angular difference, in [0, pi].
  - d_ob is measured from the robot's centre to the obstacle's surface along the direction: r_m plus the free
    distance the point robot can travel before entering an enlarged obstacle, limited to [r_m, d_obmax]. An
    obstacle touching the rim gives r_m, the stated minimum. (The other reading, the free distance alone clipped
    to [r_m, d_obmax], scored the same in the kinematic trials within their noise.) Every direction against
    every point runs compiled (numba): the same arithmetic as the numpy form, a third of the time.
  - smooth() is "a weighted average of adjacent obstacle distances"; its weights are not given: a circular
    [1/4, 1/2, 1/4] kernel is used.
  - near-ties are broken towards the previous choice (``modified_target_heading``); the thesis takes the plain
    maximum, which swings between the two ways round an obstacle straight ahead.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True)
class DirectionSensorParams:
    alpha1: float = 0.5  # Table 3.2: weight of goal-directedness
    beta: float = 1.0  # Table 3.2: weight of obstacle clearance
    max_distance: float = 1.5  # Table 3.2: d_obmax, m, the IR range
    directions: int = 41  # Table 3.2: N_theta, candidate directions over 360 degrees
    smoothing: tuple[float, ...] = (0.25, 0.5, 0.25)  # smooth()'s kernel: not given, chosen
    tie_tolerance: float = 0.02  # objective difference treated as a tie (not in the thesis; see below); below
    # alpha1 2 pi / (41 pi) = 0.024, one candidate step of goal-directedness, so open space still aims exactly


def wrap(angle):
    """Angles in [-pi, pi)."""
    if isinstance(angle, float):  # one angle: the same arithmetic without numpy's overhead
        return (angle + math.pi) % (2 * math.pi) - math.pi
    return (np.asarray(angle, float) + np.pi) % (2 * np.pi) - np.pi


def target_heading(x_c: float, y_c: float, x_g: float, y_g: float) -> float:
    """(3.9), measured from the world x axis (see the module notes)."""
    return float(wrap(np.arctan2(y_g - y_c, x_g - x_c)))


def candidate_directions(count: int) -> np.ndarray:
    """``count`` directions evenly over the circle, the first straight ahead, in [-pi, pi)."""
    return wrap(2 * np.pi * np.arange(count) / count)


@functools.lru_cache(maxsize=8)
def _candidates(count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``candidate_directions(count)`` and their cosines and sines: constants, computed once per count."""
    directions = candidate_directions(count)
    return directions, np.cos(directions), np.sin(directions)


def obstacle_distances(points: np.ndarray, directions: np.ndarray, robot_radius: float,
                       max_distance: float) -> np.ndarray:
    """d_ob per direction: r_m plus the free travel of the point robot before an enlarged obstacle, limited to
    [r_m, d_obmax]. ``points`` are obstacle points (m, 2) relative to the robot's centre, in the robot frame."""
    return _distances_along(points, np.cos(directions), np.sin(directions), robot_radius, max_distance)


def _distances_along(points: np.ndarray, cos: np.ndarray, sin: np.ndarray, robot_radius: float,
                     max_distance: float) -> np.ndarray:
    """``obstacle_distances`` for directions given by their cosines and sines."""
    points = np.asarray(points, float).reshape(-1, 2)
    return _obstacle_distances(cos, sin, np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1]),
                               robot_radius, robot_radius ** 2, max_distance)


@njit("f8[::1](f8[::1], f8[::1], f8[::1], f8[::1], f8, f8, f8)", cache=True)
def _obstacle_distances(ux, uy, px, py, radius, radius_squared, max_distance):  # noqa: PLR0913
    out = np.empty(ux.shape[0])
    for i in range(ux.shape[0]):
        free = math.inf
        for j in range(px.shape[0]):
            along = ux[i] * px[j] + uy[i] * py[j]
            across = ux[i] * py[j] - uy[i] * px[j]
            if along > 0 and abs(across) < radius:
                free = min(free, max(along - math.sqrt(max(radius_squared - across * across, 0.0)), 0.0))
        out[i] = min(max(radius + free, radius), max_distance)
    return out


def smooth(distances: np.ndarray, kernel: tuple[float, ...]) -> np.ndarray:
    """Circular weighted average of each direction's distance with its neighbours' (odd-length kernel)."""
    return _smooth(np.ascontiguousarray(distances, dtype=float), np.asarray(kernel, float))


@njit("f8[::1](f8[::1], f8[::1])", cache=True)
def _smooth(distances, kernel):
    n, half = distances.shape[0], kernel.shape[0] // 2
    out = np.empty(n)
    for i in range(n):
        total = 0.0
        for k in range(kernel.shape[0]):
            total += kernel[k] * distances[(i - (half - k)) % n]
        out[i] = total
    return out


def direction_objective(directions: np.ndarray, target: float, smoothed: np.ndarray,
                        params: DirectionSensorParams) -> np.ndarray:
    """(3.10) for every candidate direction; ``target`` is theta_t in the robot frame."""
    goal_directedness = 1.0 - np.abs(wrap(directions - target)) / np.pi
    return params.alpha1 * goal_directedness + params.beta * smoothed / params.max_distance


def modified_target_heading(points: np.ndarray, target: float, robot_radius: float,
                            params: DirectionSensorParams = DirectionSensorParams(),
                            previous: float | None = None) -> float:
    """theta_tmod, in the robot frame, for target heading ``target`` (robot frame) and obstacle ``points``.

    Directions scoring within ``params.tie_tolerance`` of the best count as ties, broken towards ``previous``
    (the last theta_tmod, in the current robot frame): an obstacle dead ahead scores both ways round it almost
    equally, and re-deciding every cycle would swing the robot between them. Compiled as one call: the same
    arithmetic as ``obstacle_distances``, ``smooth`` and ``direction_objective`` composed (tested to the bit)."""
    directions, cos, sin = _candidates(params.directions)
    points = np.asarray(points, float).reshape(-1, 2)
    return _heading(directions, cos, sin, np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1]),
                    robot_radius, params.max_distance, _kernel(params.smoothing), target, params.alpha1, params.beta,
                    params.tie_tolerance, math.nan if previous is None else previous)


@functools.lru_cache(maxsize=8)
def _kernel(smoothing: tuple[float, ...]) -> np.ndarray:
    return np.asarray(smoothing, float)


@njit("f8(f8)", cache=True)
def wrap_one(angle):
    """``wrap`` of one angle, compiled."""
    return (angle + np.pi) % (2 * np.pi) - np.pi


@njit("f8(f8[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8, f8, f8[::1], f8, f8, f8, f8, f8)", cache=True)
def _heading(directions, ux, uy, px, py, radius, max_distance, kernel, target, alpha1, beta,  # noqa: PLR0913
             tie_tolerance, previous):
    """``modified_target_heading``'s choice; ``previous`` NaN for none."""
    smoothed = _smooth(_obstacle_distances(ux, uy, px, py, radius, radius ** 2, max_distance), kernel)
    scores = np.empty(directions.shape[0])
    for i in range(directions.shape[0]):  # (3.10), as direction_objective
        goal_directedness = 1.0 - abs(wrap_one(directions[i] - target)) / np.pi
        scores[i] = alpha1 * goal_directedness + beta * smoothed[i] / max_distance
    best = np.argmax(scores)
    if previous != previous:
        return directions[best]
    floor = scores[best] - tie_tolerance
    chosen, nearest = -1, math.inf
    for i in range(directions.shape[0]):  # ties broken towards the previous choice, the first of equals
        if scores[i] >= floor:
            off = abs(wrap_one(directions[i] - previous))
            if off < nearest:
                chosen, nearest = i, off
    return directions[chosen]

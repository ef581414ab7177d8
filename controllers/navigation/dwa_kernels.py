"""The dynamic-window controller's innermost loops, compiled (numba): candidates against obstacle points.

- :func:`collision_distances`: DC_cd of §3.5, how far the centre travels along each candidate's arc (3.11)
  before the robot's circle touches a point, capped at DC_cdmax;
- :func:`stops_clear`: ST_v (3.33) by integration, whether the robot, holding a candidate one cycle and then
  braking along its curvature, keeps its circle clear of every point;
- :func:`best_primary`: the choice by a primary objective ((3.35) FRC, (3.38) ODW and ODWDS, (3.39) RFRC),
  measuring DC_cd and ST_v only for the candidates that could still win (docs/decisions.md, "The primary
  objective without measuring every candidate");
- :func:`sector_nearest` and :func:`primary_terms`: a decision's nearest obstacles ahead and behind, and its
  candidates' heading and speed terms;
- :func:`reading_points`: an IR reading's obstacle points in the robot frame;
- :func:`thin_to_robot_frame`: the obstacle memory, one point per 2 cm square, in the robot frame.
- :func:`path_blocked`: HRDU's re-planning trigger, an impassable cell near the path ahead.

The first two are :class:`~teamsim.controllers.navigation.dynamic_window.DynamicWindow`'s methods of the same
names, whose docstrings give the reasoning; here the same arithmetic runs as plain loops, one candidate and one
point at a time, and a candidate stops at the first point that settles it. Vectorised numpy spent most of a
decision creating arrays for a few thousand pairs (docs/decisions.md, "Navigation decisions compiled").
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamsim.controllers.navigation.polar_histogram import wrap_one

STILL = 1e-9  # |v| or |omega| at or below this is zero
BAND_SLACK = 1e-9  # relative: the squared pre-test against an arc's band never drops a point the exact test keeps


@njit("b1(f8, f8, f8)", cache=True)
def in_place(v: float, omega: float, offset: float) -> bool:
    return abs(v) <= STILL and (abs(omega) <= STILL or abs(offset) <= STILL)


@njit(cache=True)
def _points_outside(px, py, radius, margin, dc_max):
    """The points' distances from the centre, their indices outside the robot's circle nearest first, and the
    clearance a candidate that stays in place keeps (the enlarged circle's distance to the nearest point)."""
    distance = np.hypot(px, py)
    kept = min(max(distance.min() - (radius + margin), 0.0), dc_max) if px.shape[0] else dc_max
    # A point at distance d cannot be touched before the centre has travelled d - r, so the search along a
    # candidate ends at the first point beyond its best.
    order = np.argsort(distance)
    return distance, order[distance[order] >= radius], kept


@njit(cache=True)
def _collision_distance(v, omega, px, py, distance, order, radius, margin, offset, dc_max, kept):  # noqa: PLR0913
    """DC_cd of one candidate (v, omega); ``distance``, ``order``, ``kept`` from ``_points_outside``."""
    if in_place(v, omega, offset):
        return kept
    enlarged = radius + margin
    travel = dc_max
    turning = abs(omega) > STILL
    icr_y = rho = centre_angle = turn = forward = 0.0
    if turning:
        icr_y = v / omega
        rho = math.hypot(offset, icr_y)
        centre_angle = math.atan2(-icr_y, offset)
        turn = 1.0 if omega > 0 else -1.0
    else:
        forward = np.sign(v)
    for j in order:
        if distance[j] - enlarged >= travel:
            break
        r = enlarged if distance[j] >= enlarged else radius
        if turning:
            qx, qy = px[j] + offset, py[j] - icr_y
            # Far outside the band |d - rho| < r, by squares (no square root); the exact test follows.
            d2 = qx * qx + qy * qy
            if d2 > (rho + r) ** 2 * (1 + BAND_SLACK) or (rho > r and d2 < (rho - r) ** 2 * (1 - BAND_SLACK)):
                continue
            d = math.hypot(qx, qy)
            if abs(d - rho) < r:
                ahead = np.mod(turn * (math.atan2(qy, qx) - centre_angle), 2 * np.pi)
                cos_touch = (rho ** 2 + d ** 2 - r * r) / max(2 * rho * d, 1e-12)
                touch = math.acos(min(max(cos_touch, -1.0), 1.0))
                travel = min(travel, rho * max(ahead - touch, 0.0))
        else:
            ahead = forward * px[j]
            if ahead > 0 and abs(py[j]) < r:
                travel = min(travel, ahead - math.sqrt(max(r * r - py[j] * py[j], 0.0)))
    return travel


@njit("f8[::1](f8[::1], f8[::1], f8[::1], f8[::1], f8, f8, f8, f8)", cache=True)
def collision_distances(v, omega, px, py, radius, margin, offset, dc_max):  # noqa: PLR0913
    """DC_cd per candidate (v[k], omega[k]) for points (px, py) in the robot frame, centre at the origin."""
    distance, order, kept = _points_outside(px, py, radius, margin, dc_max)
    out = np.empty(v.shape[0])
    for k in range(v.shape[0]):
        out[k] = _collision_distance(v[k], omega[k], px, py, distance, order, radius, margin, offset, dc_max, kept)
    return out


@njit(cache=True)
def _stop_points(v, all_x, all_y, radius, margin, reach, dt, brake):  # noqa: PLR0913
    """The points a stop can reach (outside the robot's circle, nearer than ``reach``) with each one's squared
    clearance threshold, and the steps of the held cycle and the braking until the fastest candidate has stopped."""
    enlarged = radius + margin
    px, py, threshold = np.empty(all_x.shape[0]), np.empty(all_x.shape[0]), np.empty(all_x.shape[0])
    m = 0
    for j in range(all_x.shape[0]):
        distance = math.hypot(all_x[j], all_y[j])
        if radius <= distance < reach:
            px[m], py[m] = all_x[j], all_y[j]
            r = enlarged if distance >= enlarged else radius
            threshold[m] = (px[m] ** 2 + py[m] ** 2 - r ** 2) / 2
            m += 1
    top = 0.0
    for k in range(v.shape[0]):
        top = max(top, abs(v[k]))
    steps = 1  # the held cycle; then braking until the fastest candidate has stopped
    speed = top
    while True:
        speed = max(speed - brake * 2 * dt, 0.0)
        steps += 1
        if speed == 0.0:
            break
    return px[:m], py[:m], threshold[:m], steps


@njit(cache=True)
def _stop_clear(v, omega, px, py, threshold, steps, offset, dt, brake, turn):  # noqa: PLR0913
    """ST_v of one candidate (v, omega) against ``_stop_points``'s points."""
    speed_now, w_now = abs(v), omega
    curvature = omega / v if speed_now > STILL else 0.0
    direction = np.sign(v)
    th = x = y = 0.0
    for s in range(steps):
        if s == 0:
            speed_next, w_next, step_dt = speed_now, w_now, dt
        else:
            speed_next = max(speed_now - brake * 2 * dt, 0.0)
            w_next = min(max(curvature * direction * speed_next, w_now - turn), w_now + turn)
            step_dt = 2 * dt
        step = direction * (speed_now + speed_next) / 2 * step_dt
        mean_w = (w_now + w_next) / 2
        mid = th + mean_w * step_dt / 2
        th += mean_w * step_dt
        x += step * math.cos(mid)
        y += step * math.sin(mid)
        cx, cy = x + offset * (math.cos(th) - 1.0), y + offset * math.sin(th)
        half_c2 = (cx ** 2 + cy ** 2) / 2
        for j in range(px.shape[0]):
            if cx * px[j] + cy * py[j] - half_c2 > threshold[j]:
                return False
        speed_now, w_now = speed_next, w_next
    return True


@njit("b1[::1](f8[::1], f8[::1], f8[::1], f8[::1], f8, f8, f8, f8, f8, f8, f8)", cache=True)
def stops_clear(v, omega, all_x, all_y, radius, margin, reach, offset, dt, brake, turn):  # noqa: PLR0913
    """ST_v per candidate: the centre's path, one cycle at (v, omega) then braking at ``brake`` two cycles a step
    (the turn rate following the curvature, changing at most ``turn`` a step), clear of the points outside the
    robot's circle and nearer than ``reach``: by the circle enlarged by ``margin``, or by the robot's own circle
    for a point between the two."""
    px, py, threshold, steps = _stop_points(v, all_x, all_y, radius, margin, reach, dt, brake)
    clear = np.ones(v.shape[0], np.bool_)
    if px.shape[0] == 0:
        return clear
    for k in range(v.shape[0]):
        clear[k] = _stop_clear(v[k], omega[k], px, py, threshold, steps, offset, dt, brake, turn)
    return clear


@njit("Tuple((i8, f8))(f8[::1], f8[::1], f8[::1], b1[::1], f8[::1], f8[::1], f8[::1], f8, f8, f8, f8, f8, f8, f8, "
      "f8, f8, f8, f8, b1, f8)", cache=True)
def best_primary(v, omega, base, admissible, dc_scale, all_x, all_y, radius, margin, reach, offset, dt,  # noqa: PLR0913
                 brake, turn, dc_max, dc_min, near_scale, clearance_weight, turn_stop, alpha_min):
    """The argmax of a primary objective and its value, or (-1, 0) when no admissible candidate qualifies:
    ``base`` (``near_scale`` times ``base`` once DC_cd <= DC_cdmin) plus ``clearance_weight`` DC_cd / DC_cdmax,
    for candidates whose stop is clear (ST_v) and, with ``turn_stop``, whose turn can be stopped at ``alpha_min``
    (ST_omega, (3.34); with alpha_min 0, as numpy's division by zero gives, none can). Candidates are taken best
    ``base`` first, and DC_cd and ST_v found only for those that could still win: the same choice as scoring
    every candidate (np.argmax's, the lowest index among equals), at a few candidates' cost. ``dc_scale``: the
    factor on each candidate's DC_cd (the tricycle's DCF). The search may stop early because a candidate's bound
    never rises as ``base`` falls: that needs finite ``base``, ``near_scale``, ``clearance_weight`` and
    ``dc_scale`` >= 0, and scores above -1 (the objectives' INVALID), as every method's are."""
    distance, order, kept = _points_outside(all_x, all_y, radius, margin, dc_max)
    px, py, threshold, steps = _stop_points(v, all_x, all_y, radius, margin, reach, dt, brake)
    # The most the clearance term can add, in the score's own arithmetic: rounding is monotone, so no score exceeds
    # its bound (weight * max / dc_max rounded apart from weight * (dc_max * max) / dc_max by an ulp, and a lower
    # candidate that tied the best was skipped, issue 21 review)
    bonus = clearance_weight * (dc_max * dc_scale.max()) / dc_max
    best, best_score = -1, 0.0
    for k in np.argsort(-base, kind="mergesort"):  # stable: equal bases in index order
        bound = max(base[k], near_scale * base[k]) + bonus
        if best >= 0 and bound < best_score:
            break
        if not admissible[k]:
            continue
        dc = _collision_distance(v[k], omega[k], all_x, all_y, distance, order, radius, margin, offset, dc_max,
                                 kept) * dc_scale[k]
        if not (in_place(v[k], omega[k], offset)
                or (dc > 0 and _stop_clear(v[k], omega[k], px, py, threshold, steps, offset, dt, brake, turn))):
            continue
        if turn_stop and not (dc > 0 and alpha_min > 0 and dc > omega[k] ** 2 / (2 * alpha_min)):
            continue
        score = (base[k] if dc > dc_min else near_scale * base[k]) + clearance_weight * dc / dc_max
        if best < 0 or score > best_score or (score == best_score and k < best):
            best, best_score = k, score
    return best, best_score


@njit("UniTuple(f8, 3)(f8[::1], f8[::1], f8, f8, f8)", cache=True)
def sector_nearest(distance, bearing, front_half_angle, rear_from, immediate_rear_from):
    """The nearest ``distance`` of the points whose |bearing| is at most ``front_half_angle`` ((3.15)-(3.16)), at
    least ``rear_from`` ((3.19)-(3.20)) and at least ``immediate_rear_from`` ((3.21)-(3.22)); inf where none."""
    front = rear = immediate_rear = math.inf
    for j in range(distance.shape[0]):
        if bearing[j] <= front_half_angle:
            front = min(front, distance[j])
        if bearing[j] >= rear_from:
            rear = min(rear, distance[j])
        if bearing[j] >= immediate_rear_from:
            immediate_rear = min(immediate_rear, distance[j])
    return front, rear, immediate_rear


@njit("UniTuple(f8[::1], 2)(f8[::1], f8[::1], f8, f8, f8, f8, f8, f8)", cache=True)
def primary_terms(v, omega, heading, dt, angular_accel_max, v_max, alpha2, gamma):  # noqa: PLR0913
    """Each candidate's heading term (the heading it will have turned by once a turn at omega is stopped at the
    drive's angular limit, against ``heading``) and its primary base alpha_2 heading + gamma |v| / v_max."""
    heading_term, base = np.empty(v.shape[0]), np.empty(v.shape[0])
    for k in range(v.shape[0]):
        turned = omega[k] * dt + omega[k] * abs(omega[k]) / (2 * angular_accel_max)
        heading_term[k] = 1.0 - abs(wrap_one(heading - turned)) / np.pi
        speed_term = abs(v[k]) / v_max if v_max > 0 else 0.0
        base[k] = alpha2 * heading_term[k] + gamma * speed_term
    return heading_term, base


@njit("f8[:, ::1](f8[::1], f8[::1], f8[::1], f8)", cache=True)
def reading_points(ranges, bearings, sensor_radius, offset):
    """The point each finite range reading marks, (m, 2) relative to the pose's reference point in the robot
    frame: ``offset`` ahead of it is the centre, the sensor ``sensor_radius`` (one for all, or one per sensor) from
    the centre along its bearing."""
    if sensor_radius.shape[0] not in (1, ranges.shape[0]):
        raise ValueError("one sensor radius, or one per reading")
    out = np.empty((ranges.shape[0], 2))
    m = 0
    for i in range(ranges.shape[0]):
        if np.isfinite(ranges[i]):
            reach = sensor_radius[i if sensor_radius.shape[0] > 1 else 0] + ranges[i]
            out[m, 0], out[m, 1] = offset + reach * math.cos(bearings[i]), reach * math.sin(bearings[i])
            m += 1
    return out[:m].copy()


@njit("f8[:, ::1](f8[:, ::1], f8, f8, f8, f8, f8, f8)", cache=True)
def thin_to_robot_frame(world, cell, ox, oy, c, s, offset):  # noqa: PLR0913
    """The obstacle memory's points (world frame) thinned to one per ``cell``-sized square (the first one
    remembered in each, in the order of the squares' keys, as ``np.unique(..., return_index=True)`` gives
    them), then relative to the centre in the robot frame at odometry pose (ox, oy) with cos c and sin s."""
    m = world.shape[0]
    ix, iy = np.empty(m, np.int64), np.empty(m, np.int64)
    for j in range(m):
        ix[j], iy[j] = np.round(world[j, 0] / cell), np.round(world[j, 1] / cell)
    if m:
        ix -= min(ix.min(), 0)
        iy -= min(iy.min(), 0)
    width = max(iy.max(), 0) + 1 if m else 1
    key = ix * width + iy
    order = np.argsort(key, kind="mergesort")  # stable: the first of equal keys comes first
    out = np.empty((m, 2))
    kept = 0
    for n in range(m):
        j = order[n]
        if n and key[j] == key[order[n - 1]]:
            continue
        dx, dy = world[j, 0] - ox, world[j, 1] - oy
        out[kept, 0], out[kept, 1] = c * dx + s * dy - offset, -s * dx + c * dy
        kept += 1
    return out[:kept].copy()


@njit("b1(f8[:, :], f8[:, :], f8, f8, f8, f8, f8)", cache=True)
def path_blocked(probabilities, ahead, origin_x, origin_y, resolution, reach, threshold):  # noqa: PLR0913
    """Whether a cell of the occupancy grid (``probabilities``, lower-left corner at the origin) at or above the
    impassable ``threshold`` has its centre within ``reach`` of a point of the path ``ahead`` ((n, 2) world
    points). Only the cells in the bounding box of the points' cells widened by ceil(reach / resolution) cells
    are looked at: a cell outside it has its centre more than ``reach`` from every point."""
    if ahead.shape[0] == 0:
        raise ValueError("no path ahead")
    margin = int(math.ceil(reach / resolution))
    row_lo = col_lo = np.iinfo(np.int64).max
    row_hi = col_hi = np.iinfo(np.int64).min
    for k in range(ahead.shape[0]):  # the points' cells, as OccupancyGrid.world_to_cell
        row = int(math.floor((ahead[k, 1] - origin_y) / resolution))
        col = int(math.floor((ahead[k, 0] - origin_x) / resolution))
        row_lo, row_hi, col_lo, col_hi = min(row_lo, row), max(row_hi, row), min(col_lo, col), max(col_hi, col)
    rows, cols = probabilities.shape
    for i in range(max(row_lo - margin, 0), min(row_hi + margin + 1, rows)):
        for j in range(max(col_lo - margin, 0), min(col_hi + margin + 1, cols)):
            if not probabilities[i, j] >= threshold:
                continue
            x, y = origin_x + (j + 0.5) * resolution, origin_y + (i + 0.5) * resolution  # OccupancyGrid.cell_to_world
            for k in range(ahead.shape[0]):
                if math.hypot(x - ahead[k, 0], y - ahead[k, 1]) <= reach:
                    return True
    return False

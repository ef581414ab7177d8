"""A plain reference implementation of one FRC dynamic-window decision: the yardstick of ``teamsim bench nav``,
which replays whole FRC calls through today's ``DynamicWindow.decide`` and through this, as ``reference_astar`` is
the A* yardstick.

It is deliberately unclever: Python loops over every (v, omega) candidate of the window and, inside, over every
obstacle point, with ``math`` on floats and no numpy anywhere in the decision. It evaluates the same window, the
same candidates in the same order, the same admissibility tests and the same objectives as
``DynamicWindow.decide`` for Method.FRC (Chand §3.5, eq. 3.14-3.37, Tables 3.3-3.4; the [RECON] readings are
those documented in ``teamsim.controllers.navigation.dynamic_window``), for both drive forms, so on the same inputs it
returns the same (v, omega) on every branch of the selection logic (Fig 3.7):

  1. v_max = min(v_glmax (3.14), v_obmax (3.17)) (3.18), with d_obfr = min(FRS) (3.15)-(3.16);
     v_min by (3.19)-(3.23) with its hysteresis band [RECON];
  2. the linear window: a_a, a_d and [v_min, v_max] applied to v_c, N_vd samples (plus 0 inside the window);
  3. the angular window: (3.24)-(3.25) over the tricycle's reachable curvatures, or the differential drive's
     box omega_c -+ alpha dt; alpha_min; N_omega_d samples (plus 0); then the braking continuation of the
     current motion is appended as the last candidate;
  4. per candidate: the safety margin (3.26)-(3.27) SM = SM_min + k_SM |v_c| (no motion of the centre towards a
     flagged point); the tricycle's curvature constraint CC_T (3.28)-(3.32) [RECON] (CC_D holds by construction);
     DC_cd of the circle enlarged by SM along the centre's arc round the instantaneous centre of rotation
     (3.11)-(3.13), capped at DC_cdmax, times DCF for a tricycle steering towards a close side obstacle CL_ob;
     ST_v (3.33) by integrating the held cycle and the brake [RECON]; ST_omega (3.34) for differential drive;
     the heading term h = 1 - |wrap(theta_tmod - (omega dt + omega |omega| / (2 alpha)))| / pi [RECON];
  5. the primary objective (3.35): alpha_2 h + gamma |v| / v_max if ST_v and DC_cd > DC_cdmin, alpha_3 times
     that if ST_v and DC_cd <= DC_cdmin, -1 otherwise (and -1 for inadmissible candidates); the first candidate
     with the greatest value wins if it is > -1;
  6. otherwise, for a tricycle at rest whose wheel is not yet at the lock it should turn to, that turn of its
     wheel; otherwise the opposing linear velocity and the best secondary objective over omega, (3.36) for the
     tricycle, (3.37) for differential drive [RECON]: alpha_2 h DC_cd^2 / DC_cdmax^2 on their conditions;
  7. otherwise that velocity with omega from the average curvature, or the hardest braking if that would move
     the centre towards a flagged point.

It imports nothing from ``dynamic_window`` (issue 28): the scalar limits (3.14), (3.17), (3.23) and the
tricycle's curvature limits are written here again from the equations, and of the window it is given only its
numbers are read (parameters, drive limits, radius, offset, steering geometry, control period). Only FRC (not
RFRC, ODW or ODWDS) is covered.
"""
from __future__ import annotations

import math

TWO_PI = 2 * math.pi
STEER_REQUEST = 0.01  # rad/s: the turn-only command that turns a standing tricycle's wheel (§3.5's "steer")


def goal_speed_limit(p, v_gmax: float, d_tgt: float) -> float:
    """(3.14) v_glmax: 0 within d_stop of the goal, falling linearly within d_decel, else v_gmax."""
    if d_tgt <= p.d_stop:
        return 0.0
    return v_gmax * d_tgt / p.d_decel if d_tgt <= p.d_decel else v_gmax


def obstacle_speed_limit(p, v_gmax: float, d_obfr: float) -> float:
    """(3.17) v_obmax [RECON: continuous]: v_obmin up to d_obfrmin, rising linearly to v_gmax at d_obfrmax."""
    if d_obfr <= p.d_obfrmin:
        return p.v_obmin
    if d_obfr > p.d_obfrmax:
        return v_gmax
    return p.v_obmin + (v_gmax - p.v_obmin) * (d_obfr - p.d_obfrmin) / (p.d_obfrmax - p.d_obfrmin)


def reverse_limit(p, v_gmax: float, d_obfr: float, d_obrr: float, d_obirr: float, previous: float) -> float:
    """(3.19)-(3.23) v_min [RECON]: no reversing with something close behind; back away (-v_gmax) when the front is
    nearer than d_obfrT2; forward only beyond d_obfrT1; between the two, as before (hysteresis)."""
    if d_obirr < p.d_obirrT or d_obrr < p.d_obrrT:
        return 0.0
    if d_obfr < p.d_obfrT2:
        return -v_gmax
    return 0.0 if d_obfr > p.d_obfrT1 else previous


def curvature_limits(steering, dt: float, steer: float) -> tuple[float, float]:
    """A tricycle's [c_min, c_max] = tan(delta) / L over the wheel angles delta reachable in one cycle."""
    lo = max(steer - steering.steer_rate_max * dt, -steering.steer_max)
    hi = min(steer + steering.steer_rate_max * dt, steering.steer_max)
    return math.tan(lo) / steering.wheelbase, math.tan(hi) / steering.wheelbase


def _clip(x: float, lo: float, hi: float) -> float:
    return min(max(x, lo), hi)


def _sign(x: float) -> float:
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


def _wrap(angle: float) -> float:
    """Into [-pi, pi), as ``polar_histogram.wrap``."""
    return (angle + math.pi) % TWO_PI - math.pi


def _samples(lo: float, hi: float, count: int) -> list[float]:
    """``count`` evenly spaced values over [lo, hi] (numpy.linspace's arithmetic), plus 0 when it lies inside."""
    if hi > lo:
        step = (hi - lo) / (count - 1)
        values = [i * step + lo for i in range(count - 1)] + [hi]
    else:
        values = [lo]
    if lo < 0.0 < hi:
        values = sorted(set(values + [0.0]))
    return values


def _towards(v: float, omega: float, points: list[tuple[float, float]], offset: float, radius: float) -> bool:
    """Whether the centre, moving along (v, omega y_off) (3.13), heads for one of ``points`` within the robot's
    half-width."""
    vx, vy = v, omega * offset
    speed = math.hypot(vx, vy)
    for px, py in points:
        if vx * px + vy * py > 1e-12 and abs(vx * py - vy * px) < radius * speed:
            return True
    return False


def _collision_distance(v: float, omega: float, points: list[tuple[float, float, float]], r: float,
                        offset: float, kept: float, dc_max: float, radius: float) -> float:
    """DC_cd of one candidate: the centre's travel along its arc (or line) until the circle of radius ``r`` touches
    one of ``points`` (x, y, distance from the centre; those inside the robot's own circle of ``radius`` are left
    out, and those between it and ``r`` are measured against it), capped at DC_cdmax; ``kept`` (the clearance)
    for a candidate that does not move the centre."""
    enlarged = r
    turning = abs(omega) > 1e-9
    if not (abs(v) > 1e-9 or (turning and abs(offset) > 1e-9)):
        return kept
    travel = math.inf
    if turning:  # the centre circles I = (-offset, v / omega) at radius rho (3.11)
        icr_y = v / omega
        rho = math.hypot(offset, icr_y)
        centre_angle = math.atan2(-icr_y, offset)
        turn_sign = _sign(omega)
        for px, py, dist in points:
            r = enlarged if dist >= enlarged else radius
            qx, qy = px + offset, py - icr_y
            d = math.hypot(qx, qy)
            if abs(d - rho) < r:
                ahead_angle = (turn_sign * (math.atan2(qy, qx) - centre_angle)) % TWO_PI
                cos_touch = (rho * rho + d * d - r * r) / max(2 * rho * d, 1e-12)
                touch = math.acos(_clip(cos_touch, -1.0, 1.0))
                travel = min(travel, rho * max(ahead_angle - touch, 0.0))
    else:  # straight along +-x
        forward = _sign(v)
        for px, py, dist in points:
            r = enlarged if dist >= enlarged else radius
            ahead = forward * px
            if ahead > 0 and abs(py) < r:
                travel = min(travel, ahead - math.sqrt(max(r * r - py * py, 0.0)))
    return min(travel, dc_max)


def _stops_clear(v: float, omega: float, points: list[tuple[float, float, float]], window,
                 braking_steps: int) -> bool:
    """ST_v by integration, for one candidate: held one cycle, then braking at a_a along its curvature with omega
    slewed at the drive's angular limit, two cycles a step, for ``braking_steps`` steps (as many as the fastest
    candidate of the window needs to stop: the turn rate keeps settling after a slower one has); whether the
    circle stays clear of every point (x, y, the circle's radius for that point)."""
    p, lim, dt0, offset = window.params, window.limits, window.dt, window.offset
    brake = min(p.a_a, lim.accel_max)
    speed, w = abs(v), omega
    moving = speed > 1e-9
    curvature = omega / v if moving else 0.0
    direction = _sign(v)
    x = y = th = 0.0
    for step_index in range(braking_steps + 1):
        held = step_index == 0
        dt = dt0 if held else 2 * dt0
        if held:
            next_speed, next_w = speed, w
        else:
            next_speed = max(speed - brake * dt, 0.0)
            turn = lim.angular_accel_max * dt
            next_w = _clip(curvature * direction * next_speed, w - turn, w + turn)
        step = direction * (speed + next_speed) / 2 * dt
        mean_w = (w + next_w) / 2
        mid = th + mean_w * dt / 2
        x, y, th = x + step * math.cos(mid), y + step * math.sin(mid), th + mean_w * dt
        cx, cy = x + offset * (math.cos(th) - 1.0), y + offset * math.sin(th)
        for px, py, rr in points:
            if (px - cx) ** 2 + (py - cy) ** 2 < rr * rr:
                return False
        speed, w = next_speed, next_w
    return True


def _braking_steps(fastest: float, brake: float, dt: float) -> int:
    """How many braking steps (of two cycles) after the held one it takes ``fastest`` to reach 0."""
    steps, speed = 0, fastest
    while True:
        speed = max(speed - brake * dt, 0.0)
        steps += 1
        if speed == 0.0:
            return steps


def reference_decide(window, state, points, heading: float, d_tgt: float,
                     v_min_previous: float = 0.0, v_cap: float = math.inf) -> tuple[float, float, str, float]:
    """FRC's decision, plainly: (v, omega, branch, v_min) for the next cycle, from the same arguments as
    ``window.decide`` (``points``: obstacle points relative to the robot's centre in the robot frame, any
    sequence of (x, y); ``heading``: theta_tmod relative to the robot; ``d_tgt``: distance to the final goal;
    ``v_cap``: teamsim's further speed limit, 0 while a trapped FRC turns to face its plan). ``window`` is read
    for its numbers only; ``state`` is anything with v, omega and steer."""
    if window.method.name != "FRC":
        raise ValueError("reference_decide covers FRC only")
    p, lim, dt, radius, offset = window.params, window.limits, window.dt, window.radius, window.offset
    pts = [(float(x), float(y)) for x, y in (points.tolist() if hasattr(points, "tolist") else points)]
    pts = [(x, y, math.hypot(x, y)) for x, y in pts]

    # (3.15)-(3.16), (3.19)-(3.22): nearest points in the front, rear and immediate-rear sectors.
    d_obfr = d_obrr = d_obirr = math.inf
    for x, y, dist in pts:
        bearing = abs(math.atan2(y, x))
        if bearing <= p.front_half_angle:
            d_obfr = min(d_obfr, dist)
        if bearing >= math.pi - p.rear_half_angle:
            d_obrr = min(d_obrr, dist)
        if bearing >= math.pi - p.immediate_rear_half_angle:
            d_obirr = min(d_obirr, dist)

    v_max = min(goal_speed_limit(p, lim.v_max, d_tgt), v_cap, obstacle_speed_limit(p, lim.v_max, d_obfr))  # (3.18)
    v_min = reverse_limit(p, lim.v_max, d_obfr, d_obrr, d_obirr, v_min_previous)  # (3.23)

    # The linear window.
    speed_up, slow_down = min(p.a_a, lim.accel_max) * dt, min(-p.a_d, lim.accel_max) * dt
    v_lo = state.v - (slow_down if state.v > 0 else speed_up)
    v_hi = state.v + (slow_down if state.v < 0 else speed_up)
    v_wmin, v_wmax = _clip(v_min, v_lo, v_hi), _clip(v_max, v_lo, v_hi)

    # The angular window (3.24)-(3.25) and alpha_min.
    turn = lim.angular_accel_max * dt
    if window.tricycle:
        c_min, c_max = curvature_limits(window.steering, dt, state.steer)
        products = [c * vw for c in (c_min, c_max) for vw in (v_wmin, v_wmax)]
        w_min, w_max = min(products), max(products)
    else:
        w_min, w_max = state.omega - turn, state.omega + turn
    alpha_min = min(abs(w_max - state.omega), abs(w_min - state.omega)) / dt
    w_lo = max(w_min, max(state.omega - turn, -lim.omega_max))
    w_hi = min(w_max, min(state.omega + turn, lim.omega_max))
    if w_lo > w_hi:
        w_lo = w_hi = _clip(0.0, state.omega - turn, state.omega + turn)

    # The candidates: the window's grid, v outer, then the braking continuation of the current motion.
    candidates = [(v, w) for v in _samples(v_wmin, v_wmax, p.n_vd) for w in _samples(w_lo, w_hi, p.n_wd)]
    brake_step = min(p.a_a, lim.accel_max) * dt
    v_brake = _clip(_sign(state.v) * max(abs(state.v) - brake_step, 0.0), v_wmin, v_wmax)
    c_now = state.omega / state.v if abs(state.v) > 1e-9 else 0.0
    w_brake = _clip(_clip(c_now * v_brake, state.omega - turn, state.omega + turn), w_lo, w_hi)
    candidates.append((v_brake, w_brake))

    # Per decision: the safety margin's flagged points (3.26)-(3.27), the enlarged circle, the clearance kept
    # by a candidate that does not move the centre, the points DC_cd and ST_v look at.
    margin = p.sm_min + p.k_sm * abs(state.v)
    r = radius + margin
    flagged = [(x, y) for x, y, dist in pts if dist - radius <= margin]
    kept = _clip(min(dist for _, _, dist in pts) - r, 0.0, p.dc_max) if pts else p.dc_max
    outside = [pt for pt in pts if pt[2] >= radius]  # flagged ones are measured against the robot's own circle
    fastest = max(abs(v) for v, _ in candidates)
    brake = min(p.a_a, lim.accel_max)
    reach = r + (fastest * dt + fastest ** 2 / (2 * brake) + 0.1) + TWO_PI * abs(offset)  # as FRC sums it
    stop_points = [(x, y, r if dist >= r else radius) for x, y, dist in outside if dist < reach]
    braking_steps = _braking_steps(fastest, brake, 2 * dt)
    left = right = False
    if window.tricycle:  # CL_ob: a point close to the rim on either side
        lo, hi = p.side_sector
        for x, y, dist in pts:
            if dist - radius <= p.close_side_distance:
                bearing = math.atan2(y, x)
                left = left or lo <= bearing <= hi
                right = right or lo <= -bearing <= hi

    primary, secondary = [], []
    for v, w in candidates:
        still = abs(v) < 1e-9
        # Admissible: no motion towards a flagged point; the tricycle's CC_T = CC1 CC4 (3.28)-(3.32) [RECON].
        admissible = not _towards(v, w, flagged, offset, radius)
        steers_to_close = False
        if window.tricycle:
            if still:
                cc = abs(w) < 1e-9 and not abs(state.v) < 1e-9
            else:
                c = w / v
                cc = c_min - 1e-9 <= c <= c_max + 1e-9
                steers_to_close = (left and c > 1e-9) or (right and c < -1e-9)
            admissible = admissible and cc
        dc = _collision_distance(v, w, outside, r, offset, kept, p.dc_max, radius)
        if steers_to_close:
            dc = dc * p.dcf
        # (3.33); a stop or a point turn about the centre sweeps nothing new and can always stop
        in_place = still and (abs(w) < 1e-9 or abs(offset) < 1e-9)
        st_v = in_place or (dc > 0 and (not stop_points or _stops_clear(v, w, stop_points, window, braking_steps)))
        st_w = True if window.tricycle else (dc > 0 and dc > w ** 2 / (2 * alpha_min))  # (3.34)
        turned = w * dt + w * abs(w) / (2 * lim.angular_accel_max)
        h = 1.0 - abs(_wrap(heading - turned)) / math.pi
        base = p.alpha2 * h + p.gamma * (abs(v) / v_max if v_max > 0 else 0.0)
        if not admissible or not st_v:  # (3.35)
            primary.append(-1.0)
        else:
            primary.append(base if dc > p.dc_min else p.alpha3 * base)
        # (3.36) tricycle, (3.37) differential drive [RECON]
        if not st_v and (window.tricycle or not abs(state.v) < 1e-9 or st_w):
            secondary.append(p.alpha2 * h * dc ** 2 / p.dc_max ** 2)
        else:
            secondary.append(-1.0)
        if not admissible:
            secondary[-1] = -1.0

    best = 0
    for k in range(1, len(candidates)):
        if primary[k] > primary[best]:
            best = k
    if primary[best] > -1.0:
        return candidates[best][0], candidates[best][1], "primary", v_min

    # A standing tricycle turns its wheel, away from a close side obstacle on one side only, else towards the
    # heading, until the wheel is at that lock.
    if window.tricycle and state.v == 0.0:
        side = 1.0 if right and not left else -1.0 if left and not right else (1.0 if heading >= 0 else -1.0)
        if abs(side * window.steering.steer_max - state.steer) >= 1e-9:
            return 0.0, side * STEER_REQUEST, "steer", v_min
    # Oppose the current motion (standing still: away from the nearer of front and rear).
    backwards = state.v > 0 or (state.v == 0 and d_obfr <= d_obrr)
    v_oppose = v_wmin if backwards else v_wmax
    best = None
    for k, (v, _) in enumerate(candidates):
        if abs(v - v_oppose) <= 1e-8 + 1e-5 * abs(v_oppose) and (best is None or secondary[k] > secondary[best]):
            best = k
    if best is not None and secondary[best] > -1.0:
        return candidates[best][0], candidates[best][1], "secondary", v_min

    # The average curvature, unless it heads for a flagged point: then brake.
    # A standing tricycle does not turn.
    if window.tricycle:
        w = _clip(v_oppose * (c_min + c_max) / 2, w_lo, w_hi) if v_oppose else 0.0
    else:
        w = (w_lo + w_hi) / 2
    if not _towards(v_oppose, w, flagged, offset, radius):
        return v_oppose, w, "curvature", v_min
    v = _clip(0.0, v_wmin, v_wmax)
    if window.tricycle:
        w = _clip(v * math.tan(state.steer) / window.steering.wheelbase, w_lo, w_hi) if v else 0.0
    else:
        w = _clip(0.0, w_lo, w_hi)
    return v, w, "brake", v_min

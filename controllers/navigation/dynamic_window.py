"""Chand's modified dynamic window (§3.5, eq. 3.11-3.40, Tables 3.3-3.4) and the navigation controllers of §3.6.2.

The second stage of reactive control: the modified target heading theta_tmod from the direction sensor
(``teamsim.controllers.navigation.polar_histogram``) becomes the velocity pair (v, omega) for the next control cycle.
Forms for the tricycle (no point turns: it reverses to turn round) and for differential drive (tracked robots use it).

Frames. Robot frame: x forward, y left, headings counter-clockwise from the world x axis (the thesis's Fig 3.5
draws forward along y). The pose and the command (v, omega) refer to the drive's reference point (a tricycle's
rear-axle midpoint); the physical centre, which carries the enclosing circle of radius r_m and the direction
sensor, is ``centre_offset`` ahead of it (the thesis's y_off).
  (3.11) r = +-sqrt(r_1^2 + y_off^2): the radius of the arc the centre follows when the reference point turns
         on radius r_1 = v / omega;
  (3.12) v = (r / r_1) v_1 = r omega: the centre's speed;
  (3.13) [RECON: missing from the OCR] theta_v = atan2(omega y_off, v_1): the angle between the centre's
         velocity and the robot's forward axis, i.e. the centre moves along (v_1, omega y_off). r_1min is not a
         separate parameter: the curvature limits below already bound r_1.

Per cycle (Fig 3.6, Fig 3.7):
  1. v_max = min(v_glmax, v_obmax) (3.14)-(3.18): slow down near the goal and for obstacles in front.
     (3.17) [RECON] the printed middle case, v_gmax (d_obfr - d_obfrmin)/(d_obfrmax - d_obfrmin) + v_obmin,
     overshoots v_gmax near d_obfrmax; the continuous form (v_gmax - v_obmin)(...) + v_obmin is used, and the
     garbled last case is v_gmax.
  2. v_min (3.19)-(3.23) [RECON: cases garbled]: 0 while an obstacle is close behind (d_obirr < d_obirrT or
     d_obrr < d_obrrT; this subsumes reversing), else -v_gmax once d_obfr < d_obfrT2 (back away), else 0 once
     d_obfr > d_obfrT1 (resume forward only), else unchanged: T2 < T1 is a hysteresis band. Goals here are
     positions, so the tricycle's "near the goal but needs orientation correction" case never arises.
  3. The linear window: a_a, a_d and [v_min, v_max] applied to v_c, N_vd samples.
  4. The angular window: curvature limits c_min, c_max from the drive state, (3.24)-(3.25) for omega_min,
     omega_max, alpha_min = min(|alpha_a|, |alpha_d|), and the robot's angular acceleration and +-omega_gmax;
     N_omega_d samples. Tricycle: c = tan(delta)/L over the steering angles delta reachable this cycle at the
     steering rate. Differential drive: the reachable wheel speeds form the same box in (v, omega) that the drive's
     acceleration limits give, so omega_min/max = omega_c -+ alpha dt and CC_D (curvature within the box's
     limits) holds for every candidate of the window by construction.
     A stop (v = 0, and omega = 0) is added to the samples whenever the window contains it, and so is the
     braking continuation of the current motion (see ST_v below).
  5. Safety margin (3.26)-(3.27): PR_ob flags obstacles within SM = SM_min + k_SM |v_c| of the rim; candidates
     whose centre moves towards a flagged obstacle (it lies ahead, within the robot's half-width of the line of
     motion) are rejected. SM "is added to the robot's perimeter to allow it to stop or reverse before
     colliding", so DC_cd and the stopping test below use the circle enlarged by SM [RECON]: the robot stops at
     the margin, not at the obstacle. A point already inside the enlarged circle is measured against the robot's
     own circle (the margin's test only looks along the line of motion, not along the arc).
  6. Per candidate: curvature constraint, distance to collision DC_cd of the enclosing circle along the centre's
     arc (Arras et al.'s exact method for polygons is replaced by the enclosing circle, as §3.4 does), the
     tricycle's DCF reduction towards a close side obstacle CL_ob, the stopping tests ST_v (3.33) and ST_omega
     (3.34), and the objectives (3.35)-(3.40).
     Tricycle curvature constraint (3.28)-(3.32) [RECON]: read as printed, CC1 = (c in range) NOT(v_cd = 0)
     (omega_cd != 0) would forbid ever driving straight; the overbar must span "(v_cd = 0)(omega_cd != 0)", so
     CC1 = c in range and not a point turn. CC2 and CC3 (switching direction with c in range) are then special
     cases of CC1, and CC_T = CC1 CC4 with CC4 = NOT(v_c = 0 and v_cd = 0) (no deadlock standing still).
     Heading term [RECON]: printed as |(theta_tmod - theta_c) - omega_cd|/pi, which the maximised objectives
     would reward for turning away from the target; the "1 -" of (3.10) is restored, and theta_tmod is already
     robot-relative (§3.4 subtracts theta_c). Subtracting omega_cd (rad/s) from an angle needs a time; the
     heading the candidate turns through before its turn can be stopped is used,
     omega_cd dt + omega_cd |omega_cd| / (2 alpha), alpha the drive's angular acceleration: the term then asks
     for the turn rate that arrives on the target heading without overshooting it (a fixed look-ahead of 1 s
     made robots with Scratchy's 0.15 rad/s^2 weave about their path).
     ST_v (3.33) [RECON]: DC_cd > v_cd^2 / (2 a_a) holds only if the robot can brake along the candidate's arc
     from now on. It cannot: the candidate is held for a cycle first, and braking along an arc needs omega to
     fall with v, which the drive's angular acceleration may not allow (the path then tightens). So ST_v is
     evaluated by integrating that stop (``stops_clear``): the candidate for one cycle, then a_a along its
     curvature with omega slewed at the drive's limit, the enlarged circle kept clear of every point. The
     braking continuation of the current motion is always among the candidates, so a robot whose last command
     passed this test can still stop unless it has seen something new. (3.34) is kept as printed (mixed
     units) where the objectives name ST_omega: (3.37) and (3.38).
     Secondary objectives [RECON]: read as printed, (3.36) scores a candidate that cannot stop by goal heading
     alone, and only while DC_cd <= DC_cdmin, so it prefers the candidates that drive into the obstacle over
     those that steer away; §3.5 says it "attempts to steer the robot away from an obstacle even if it is too
     close to stop". The DC_cd^2/DC_cdmax^2 factor of its CL_ob case is therefore applied to every candidate that
     cannot stop, so a candidate steering away ranks above one heading in (a CL_ob candidate's DC_cd is already
     multiplied by DCF). (3.37), truncated in the OCR after "NOT ST_v and NOT(v_c = 0)", gets the same factor on
     its printed conditions. RFRC keeps (3.40) as printed.
  7. Selection: the best primary objective if valid (> -1); else a linear velocity opposing the current motion
     with the best secondary objective over omega; else that velocity with omega from the average curvature
     (a differential drive's: the middle of its angular window). Never towards a flagged obstacle: if that last
     resort would be, the robot brakes as hard as it can instead (a choice; the thesis does not say). A tricycle
     at rest with no admissible candidate first turns its front wheel (``DynamicWindow._steer_at_rest``
     [RECON]: a wheel left turned towards a close side obstacle held the robot beside it for good).

Variants (§3.6.2): FRC, the full method; RFRC, DCF = 1 and no CL_ob, (3.39) and (3.40); ODW, the original window
with no direction sensor: v_obmax = v_gmax, v_min = -v_gmax, the tricycle's curvature check like CC_D, no DCF,
and (3.38) with beta_1 = 0.3, braking when nothing is admissible; ODWDS, ODW with the direction sensor and
beta_1 = 0.005. (3.18) is not used by ODW, so v_max = v_glmax there: it still stops at its goal.

Controllers: ``FRC``, ``RFRC``, ``ODW``, ``ODWDS`` drive straight for the goal; ``HRDK`` plans once with the
modified A* on a known map and follows the path with FRC; ``HRDU`` maps with an occupancy grid while driving and
re-plans. Each is ``__call__(Observation) -> Command``. Between positioning fixes (0.6 s apart) a controller
advances its last fix by its odometry (``Observation.velocity``; without one, by the velocities it commanded).
It takes the dynamic window's state (v_c, omega_c) from its own last command, which the locomotion follows under
the same acceleration limits, except when the odometry says the robot has stalled: driven at 0.05 m/s or more,
it moved at under a quarter of that over the last period, and turned at under a quarter of its commanded turn rate
(or of 0.2 rad/s: a robot that turns as asked is not held, docs/decisions.md). Something the IR ring does not
see, such as a box corner between two beams, is holding it. The controller then starts from the
measured (rest) state and remembers a contact point on its circle where its centre was heading (``_contact``).
Before this, a robot halted against such a corner went on asking for the same motion for the rest of the trial (a
touch-lock). The 0.05 m/s, the 0.2 rad/s and the quarter are choices, not the thesis's: setting off from rest, a
physics robot lags its first commands by more than a quarter. The IR ring sees only a few directions (10-14 beams for
41 candidate directions), so a controller keeps the obstacle points of the last ``obstacle_memory`` seconds, in
its odometry frame so that a fix's jump does not smear them. Eight seconds (a choice): a box corner that juts
out between two beams is seen only from further off, and in the kinematic study Robot B met such corners about
5 s after last seeing them; with 2 s it had forgotten them and drove into them (and, halted against a corner no
beam saw, stayed there).
"""
from __future__ import annotations

import enum
import math
from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.navigation import dwa_kernels as kernels
from teamsim.controllers.navigation.astar import PlannerParams, WeightAdaptation, adapt_weights, plan_on_grid
from teamsim.controllers.navigation.occupancy_grid import Evidence, OccupancyGrid
from teamsim.controllers.navigation.path_following import PathFollower, PathFollowing
from teamsim.controllers.navigation.multi_point_turn import MultiPointTurn
from teamsim.controllers.navigation.polar_histogram import (DirectionSensorParams, modified_target_heading,
                                                            target_heading, wrap)
from teamsim.controllers.navigation.trap_escape import EscapeParams, TrapEscape
from teamsim.controllers.skills.locomotion import STEER_REQUEST, next_steer
from teamsim.models.robot import DriveLimits

# Robot kinds that drive like a tricycle or like a differential drive (skid-steer tracks do, §3.6).
DRIVE_FORMS = {"tricycle": "tricycle", "differential": "differential", "diffdrive": "differential",
               "tracked": "differential"}
INVALID = -1.0  # the objectives' "otherwise" value
# A stall (module notes; both chosen): driven at least this fast, m/s, the odometry reads under this share of it.
STALL_DRIVEN_SPEED = 0.05
STALL_SPEED_SHARE = 0.25
# ... and it turns at under this share of the commanded turn rate, or of this one (rad/s), whichever is more: a
# robot that turns as asked is not held (a tracked robot turning in a bog creeps forward; chosen).
STALL_TURN_FLOOR = 0.2
NO_CONTACT = np.zeros((0, 2))  # obstacle points of no stall
MEMORY_CELL = 0.02  # m: the obstacle memory keeps one point per square of this side


class Method(enum.Enum):
    FRC = "frc"  # final reactive controller: direction sensor + the full modified window
    RFRC = "rfrc"  # reduced-parameter FRC
    ODW = "odw"  # original dynamic window only
    ODWDS = "odwds"  # original dynamic window + direction sensor

    @property
    def modified(self) -> bool:
        return self in (Method.FRC, Method.RFRC)

    @property
    def uses_direction_sensor(self) -> bool:
        return self is not Method.ODW


@dataclass(frozen=True)
class DynamicWindowParams:
    # Table 3.3 (p.50), re-associated by order from the linearised OCR (spec §1.6).
    a_a: float = 0.1  # m/s^2, linear acceleration
    a_d: float = -0.1  # m/s^2, linear deceleration
    alpha2: float = 0.4  # weight of goal-directedness (heading)
    alpha3: float = 0.01  # scale of the primary objective once DC_cd <= DC_cdmin
    gamma: float = 0.2  # weight of speed
    dc_max: float = 3.0  # DC_cdmax, m: collision distances are capped here
    dc_min: float = 0.6  # DC_cdmin, m
    dcf: float = 0.0  # DCF: factor on DC_cd of tricycle candidates steering towards a close side obstacle
    d_decel: float = 2.0  # m from the goal where slowing down starts (3.14)
    d_obfrmax: float = 2.0  # m (3.17), front obstacle distance above which v_obmax = v_gmax
    d_obfrmin: float = 0.5  # m (3.17), below which v_obmax = v_obmin
    d_obfrT1: float = 0.95  # m (3.23), front distance above which forward-only motion resumes
    d_obfrT2: float = 0.75  # m (3.23), front distance below which the robot may back away
    d_obirrT: float = 0.5  # m (3.23), immediate-rear distance below which reversing is subsumed
    d_obrrT: float = 0.7  # m (3.23), rear distance below which reversing is subsumed
    d_stop: float = 0.3162  # m (3.14), goal distance at which the robot stops
    k_sm: float = 0.1  # s (3.27), safety-margin growth with speed
    n_vd: int = 5  # N_vd, linear velocity samples
    n_wd: int = 11  # N_omega_d, angular velocity samples
    v_obmin: float = 0.2  # m/s (3.17), speed limit with an obstacle close in front
    # §3.6.2:
    beta1_odw: float = 0.3  # (3.38) clearance weight, ODW
    beta1_odwds: float = 0.005  # (3.38) clearance weight, ODWDS
    # Not given by the thesis (spec §8); chosen:
    sm_min: float = 0.1  # SM_min, m (3.27)
    front_half_angle: float = math.radians(50)  # FRS: obstacles within this bearing of straight ahead
    rear_half_angle: float = math.radians(60)  # RRS: within this of straight behind
    immediate_rear_half_angle: float = math.radians(20)  # IRRS: within this of straight behind
    close_side_distance: float = 0.3  # m from the rim: a side obstacle this close is CL_ob
    side_sector: tuple[float, float] = (math.radians(45), math.radians(135))  # |bearing| range of "the side"
    # Distances d_obfr, d_obrr, d_obirr and the thresholds on them are from the robot's centre (§3.6.1:
    # d_obfrmin and d_obfrmax are "the minimum and maximum sensing ranges relative to the centre").


@dataclass(frozen=True)
class SteeringGeometry:
    """A tricycle's steering (the tricycle model's assumed values; pass its TricycleSpec to match a robot)."""
    wheelbase: float = 0.5  # m, front wheel to the rear axle
    steer_max: float = math.radians(60)
    steer_rate_max: float = 1.0  # rad/s


@dataclass(frozen=True)
class DriveState:
    """What the window starts from: the current velocities (v_c, omega_c) and, for a tricycle, the steering
    angle. The controllers take them from their own previous command, which the locomotion follows under the same
    acceleration limits, or from the odometry after a stall (module notes)."""
    v: float = 0.0
    omega: float = 0.0
    steer: float = 0.0


@dataclass(frozen=True)
class Decision:
    v: float
    omega: float
    branch: str  # "primary", "secondary", "curvature" (average-curvature fallback), "steer" (a standing
    # tricycle turns its wheel) or "brake"
    objective: float  # the chosen candidate's objective; -1 for the fallbacks
    v_min: float  # (3.23)'s v_min, kept for its hysteresis


# ---------------------------------------------------------------------- single equations, as pure functions


def curvature_in_range(v: np.ndarray, omega: np.ndarray, c_min: float, c_max: float) -> np.ndarray:
    """The factor (c_cd <= c_max)(c_cd >= c_min) of (3.28)-(3.30), with c_cd = omega_cd / v_cd, and CC1's
    NOT((v_cd = 0)(omega_cd != 0)) [RECON, module notes]: a candidate with v_cd = 0 has no curvature and passes
    only as a stop (omega_cd = 0), never as a point turn. Alone, it is the check the original window (ODW, ODWDS)
    makes for a tricycle, like CC_D."""
    still = np.abs(v) < 1e-9
    curvature = omega / np.where(still, 1.0, v)
    return np.where(still, np.abs(omega) < 1e-9, (curvature >= c_min - 1e-9) & (curvature <= c_max + 1e-9))


def tricycle_curvature_constraint(v_c: float, v: np.ndarray, omega: np.ndarray, c_min: float,
                                  c_max: float) -> np.ndarray:
    """(3.32) CC_T = (CC1 | CC2 | CC3) CC4 per candidate (v_cd, omega_cd), for current linear velocity v_c [RECON]:
    CC1 (3.28) = curvature in range and not a point turn (``curvature_in_range``); CC2 (3.29) = curvature in range,
    v_c > 0, v_cd < 0 and CC3 (3.30) = curvature in range, v_c < 0, v_cd > 0 are then special cases of CC1; CC4
    (3.31) = NOT(v_c = 0 and v_cd = 0), no deadlock standing still."""
    still = np.abs(v) < 1e-9
    return curvature_in_range(v, omega, c_min, c_max) & ~(still & (abs(v_c) < 1e-9))


def can_stop_turning(dc: np.ndarray, omega: np.ndarray, alpha_min: float) -> np.ndarray:
    """(3.34) ST_omega: DC_cd > omega_cd^2 / (2 alpha_min), as printed (mixed units), tested only where DC_cd > 0."""
    return (dc > 0) & (dc > omega ** 2 / (2 * alpha_min))


def secondary_objective_tricycle(heading_term: np.ndarray, dc: np.ndarray, st_v: np.ndarray,
                                 params: DynamicWindowParams) -> np.ndarray:
    """(3.36) o_dwst, the tricycle FRC's objective for candidates that cannot stop, [RECON, module notes]: its
    CL_ob case alpha_2 h DC_cd^2 / DC_cdmax^2 for every candidate with NOT ST_v (a CL_ob candidate's DC_cd already
    carries DCF), -1 otherwise. ``heading_term`` h = 1 - |(theta_tmod - theta_c) - omega_cd t| / pi."""
    return np.where(~st_v, params.alpha2 * heading_term * dc ** 2 / params.dc_max ** 2, INVALID)


def secondary_objective_differential(heading_term: np.ndarray, dc: np.ndarray, st_v: np.ndarray,
                                     st_w: np.ndarray, v_c: float, params: DynamicWindowParams) -> np.ndarray:
    """(3.37), the differential drive's secondary objective [RECON, module notes]: on its printed conditions,
    NOT ST_v and (NOT(v_c = 0) or ST_omega), the value of ``secondary_objective_tricycle``; -1 otherwise."""
    standing = abs(v_c) < 1e-9
    return np.where(~st_v & (~standing | st_w), params.alpha2 * heading_term * dc ** 2 / params.dc_max ** 2,
                    INVALID)


def secondary_objective_reduced(heading_term: np.ndarray, st_v: np.ndarray,
                                params: DynamicWindowParams) -> np.ndarray:
    """(3.40), RFRC's tricycle secondary objective, as printed: alpha_2 h if NOT ST_v, -1 otherwise."""
    return np.where(~st_v, params.alpha2 * heading_term, INVALID)


class DynamicWindow:
    """One drive's modified dynamic window; ``decide`` is a pure function of its arguments."""

    def __init__(self, limits: DriveLimits, kind: str, footprint_radius: float, *, method: Method = Method.FRC,
                 params: DynamicWindowParams = DynamicWindowParams(), centre_offset: float = 0.0,
                 steering=SteeringGeometry(), control_dt: float = 0.1):
        if kind not in DRIVE_FORMS:
            raise ValueError(f"robot kind {kind!r} has no dynamic-window form; known: {', '.join(DRIVE_FORMS)}")
        self.limits = limits
        self.tricycle = DRIVE_FORMS[kind] == "tricycle"
        self.radius = footprint_radius
        self.method = method
        self.params = params
        self.offset = centre_offset
        self.steering = steering  # anything with wheelbase, steer_max, steer_rate_max (a TricycleSpec will do)
        self.dt = control_dt

    # ------------------------------------------------------------------ limits and windows (3.14)-(3.25)

    def goal_speed_limit(self, d_tgt: float) -> float:
        """(3.14) v_glmax."""
        p, v_gmax = self.params, self.limits.v_max
        if d_tgt <= p.d_stop:
            return 0.0
        return v_gmax * d_tgt / p.d_decel if d_tgt <= p.d_decel else v_gmax

    def obstacle_speed_limit(self, d_obfr: float) -> float:
        """(3.17) v_obmax, in its continuous [RECON] form."""
        p, v_gmax = self.params, self.limits.v_max
        if d_obfr <= p.d_obfrmin:
            return p.v_obmin
        if d_obfr <= p.d_obfrmax:
            return (v_gmax - p.v_obmin) * (d_obfr - p.d_obfrmin) / (p.d_obfrmax - p.d_obfrmin) + p.v_obmin
        return v_gmax

    def reverse_limit(self, d_obfr: float, d_obrr: float, d_obirr: float, previous: float) -> float:
        """(3.23) v_min, with the hysteresis band [d_obfrT2, d_obfrT1] [RECON]."""
        p = self.params
        if d_obirr < p.d_obirrT or d_obrr < p.d_obrrT:
            return 0.0
        if d_obfr < p.d_obfrT2:
            return -self.limits.v_max
        if d_obfr > p.d_obfrT1:
            return 0.0
        return previous

    def linear_window(self, v_c: float, v_min: float, v_max: float) -> tuple[float, float]:
        """[v_wmin, v_wmax]: a_a and a_d (bounded by the drive's limit) applied to v_c, then [v_min, v_max]. If the
        limits cannot be met this cycle the window is the hardest braking towards them."""
        p, a_lim = self.params, self.limits.accel_max
        speed_up, slow_down = min(p.a_a, a_lim) * self.dt, min(-p.a_d, a_lim) * self.dt
        lo = v_c - (slow_down if v_c > 0 else speed_up)
        hi = v_c + (slow_down if v_c < 0 else speed_up)
        return _clip(v_min, lo, hi), _clip(v_max, lo, hi)

    def curvature_limits(self, steer: float) -> tuple[float, float]:
        """Tricycle: [c_min, c_max] over the steering angles reachable this cycle."""
        s = self.steering
        step = s.steer_rate_max * self.dt
        lo, hi = max(steer - step, -s.steer_max), min(steer + step, s.steer_max)
        return math.tan(lo) / s.wheelbase, math.tan(hi) / s.wheelbase

    def angular_window(self, state: DriveState, v_window: tuple[float, float]) -> tuple[float, float, float]:
        """[omega_wmin, omega_wmax] and alpha_min, from (3.24)-(3.25) and the angular limits."""
        step = self.limits.angular_accel_max * self.dt
        if self.tricycle:
            c_min, c_max = self.curvature_limits(state.steer)
            products = [c * v for c in (c_min, c_max) for v in v_window]
            w_min, w_max = min(products), max(products)  # (3.24), (3.25)
        else:
            w_min, w_max = state.omega - step, state.omega + step
        alpha_min = min(abs(w_max - state.omega), abs(w_min - state.omega)) / self.dt
        lo = max(state.omega - step, -self.limits.omega_max)
        hi = min(state.omega + step, self.limits.omega_max)
        lo, hi = max(w_min, lo), min(w_max, hi)
        if lo > hi:  # omega_c lies outside what the drive allows next cycle: get as close as it can
            lo = hi = _clip(0.0, state.omega - step, state.omega + step)
        return lo, hi, alpha_min

    # ------------------------------------------------------------------ geometry

    def collision_distances(self, v: np.ndarray, omega: np.ndarray, points: np.ndarray,
                            margin: float = 0.0) -> np.ndarray:
        """DC_cd: how far the centre travels along each candidate's arc before the enclosing circle, enlarged by
        ``margin``, touches an obstacle point, capped at DC_cdmax. A point already inside the enlarged circle
        (flagged by the safety margin) is measured against the robot's own circle instead [RECON]: the margin's
        test rejects only motion straight towards it, so without this an arc that curves into a flagged point
        would count as collision-free, and robots drove round into the box corners beside them. Points inside
        the robot's own circle are left to the safety margin's test.

        [RECON] A candidate that does not move the centre (a stop, a point turn) has no path to measure along; it
        is given the clearance it keeps, the enlarged circle's distance to the nearest point (0 if one is inside
        it). Given DC_cdmax instead, near obstacles it escapes the alpha_3 scaling of (3.35) that every moving
        candidate gets there, outscores them all, and a robot at rest stays at rest for good: the deadlock at
        zero velocity that CC4 (3.31) is there to prevent."""
        x, y = _columns(points)
        return kernels.collision_distances(_floats(v), _floats(omega), x, y, self.radius, margin, self.offset,
                                           self.params.dc_max)

    def in_place(self, v: np.ndarray, omega: np.ndarray) -> np.ndarray:
        """Candidates that leave the robot's centre where it is: a stop, and a point turn about the centre
        (a differential drive's; a tricycle's centre is ahead of its rear axle and cannot turn in place)."""
        return (np.abs(v) <= 1e-9) & ((np.abs(omega) <= 1e-9) | (abs(self.offset) <= 1e-9))

    def stops_clear(self, v: np.ndarray, omega: np.ndarray, points: np.ndarray, margin: float) -> np.ndarray:
        """ST_v by integration: whether, holding each candidate for one cycle and then braking at a_a along its
        curvature (omega following c v as fast as the drive's angular acceleration allows), the circle enlarged
        by ``margin`` stays clear of every obstacle point outside it, and the robot's own circle of every point
        between the two (as in ``collision_distances``)."""
        if v.size == 0:
            return np.ones(0, bool)
        x, y = _columns(points)
        return kernels.stops_clear(_floats(v), _floats(omega), x, y, self.radius, margin, *self._stopping(v, margin))

    def _stopping(self, v: np.ndarray, margin: float) -> tuple[float, float, float, float, float]:
        """``stops_clear``'s model of a stop: the reach of the points it can meet, the offset, the cycle, the
        braking deceleration and the turn-rate change per braking step."""
        brake = min(self.params.a_a, self.limits.accel_max)
        # Only points the enlarged circle can reach: the centre moves at most the reference point's stopping
        # path plus twice the offset (the centre swung round to the reference point's other side).
        fastest = float(np.abs(v).max())
        reach = self.radius + margin + fastest * self.dt + fastest ** 2 / (2 * brake) + 0.1 + 2 * abs(self.offset)
        return reach, self.offset, self.dt, brake, self.limits.angular_accel_max * 2 * self.dt

    def best_primary(self, v: np.ndarray, omega: np.ndarray, base: np.ndarray, admissible: np.ndarray,
                     steers_to_close: np.ndarray, points: np.ndarray, margin: float,
                     alpha_min: float) -> tuple[int, float]:
        """The choice by the primary objective: the index of the best admissible candidate whose stop is clear
        (ST_v), and its value; (-1, 0) if there is none. FRC (3.35) scores ``base``, times alpha_3 once DC_cd
        (times DCF for a tricycle steering towards a close side obstacle) is at most DC_cdmin; RFRC (3.39)
        ``base``; ODW and ODWDS (3.38) ``base`` + beta_1 DC_cd / DC_cdmax, a differential drive's candidates only
        where ST_omega (3.34) holds too. ``dwa_kernels.best_primary`` measures DC_cd and ST_v only for the
        candidates that could still win: the same choice as scoring them all (docs/decisions.md, "The primary
        objective without measuring every candidate")."""
        p, method = self.params, self.method
        frc = method is Method.FRC
        dc_scale = np.where(steers_to_close, p.dcf, 1.0) if frc and self.tricycle else np.ones(v.size)
        near_scale = p.alpha3 if frc else 1.0
        clearance_weight = {Method.ODW: p.beta1_odw, Method.ODWDS: p.beta1_odwds}.get(method, 0.0)
        turn_stop = not (method.modified or self.tricycle)  # §3.5: tricycles check ST_v only
        x, y = _columns(points)
        best, score = kernels.best_primary(_floats(v), _floats(omega), _floats(base), admissible, dc_scale, x, y,
                                           self.radius, margin, *self._stopping(v, margin), p.dc_max, p.dc_min,
                                           near_scale, clearance_weight, turn_stop, alpha_min)
        return int(best), float(score)

    def towards(self, v: np.ndarray, omega: np.ndarray, points: np.ndarray) -> np.ndarray:
        """For each candidate, whether the centre moves towards any of ``points``: one of them lies ahead along the
        centre's velocity (v, omega y_off), the direction theta_v of (3.13), within the robot's half-width."""
        if points.shape[0] == 0:
            return np.zeros(v.shape[0], bool)
        vx, vy = v[:, None], (omega * self.offset)[:, None]
        speed = np.hypot(vx, vy)
        along = vx * points[:, 0] + vy * points[:, 1]
        across = np.abs(vx * points[:, 1] - vy * points[:, 0])
        return ((along > 1e-12) & (across < self.radius * speed)).any(axis=1)

    # ------------------------------------------------------------------ the decision

    def decide(self, state: DriveState, points: np.ndarray, heading: float, d_tgt: float,
               v_min_previous: float = 0.0, v_cap: float = math.inf) -> Decision:
        """(v, omega) for the next cycle. ``points``: obstacle points (m, 2) relative to the robot's centre in the
        robot frame; ``heading``: theta_tmod relative to the robot; ``d_tgt``: distance to the final goal;
        ``v_cap``: a further limit on forward speed (0: stop and turn, as a trapped FRC does, ``trap_escape``)."""
        p, lim = self.params, self.limits
        points = np.asarray(points, float).reshape(-1, 2)
        distance = np.hypot(points[:, 0], points[:, 1])
        bearing = np.abs(np.arctan2(points[:, 1], points[:, 0]))
        # d_obfr (3.15)-(3.16), d_obrr (3.19)-(3.20), d_obirr (3.21)-(3.22)
        d_obfr, d_obrr, d_obirr = kernels.sector_nearest(distance, bearing, p.front_half_angle,
                                                         math.pi - p.rear_half_angle,
                                                         math.pi - p.immediate_rear_half_angle)

        v_glmax = min(self.goal_speed_limit(d_tgt), v_cap)
        if self.method.modified:
            v_max = min(v_glmax, self.obstacle_speed_limit(d_obfr))  # (3.18)
            v_min = self.reverse_limit(d_obfr, d_obrr, d_obirr, v_min_previous)
        else:
            v_max, v_min = v_glmax, -lim.v_max
        v_window = self.linear_window(state.v, v_min, v_max)
        w_lo, w_hi, alpha_min = self.angular_window(state, v_window)
        v, omega = _pairs(_samples(*v_window, p.n_vd), _samples(w_lo, w_hi, p.n_wd),
                          self._braking_continuation(state, v_window, (w_lo, w_hi)))

        # Safety margin (3.26)-(3.27): no candidate may move the centre towards an obstacle inside it.
        margin = p.sm_min + p.k_sm * abs(state.v)
        flagged = points[distance - self.radius <= margin]
        safe = ~self.towards(v, omega, flagged)

        curvature_ok, steers_to_close = self._curvature_checks(state, v, omega, points, distance)
        admissible = safe & curvature_ok
        heading_term, base = kernels.primary_terms(v, omega, heading, self.dt, lim.angular_accel_max, v_max, p.alpha2,
                                                   p.gamma)
        best, score = self.best_primary(v, omega, base, admissible, steers_to_close, points, margin, alpha_min)
        if best >= 0:  # (3.35), (3.38), (3.39)
            return Decision(float(v[best]), float(omega[best]), "primary", score, v_min)
        if not self.method.modified:
            return self._brake(state, v_window, (w_lo, w_hi), v_min)

        dc = self.collision_distances(v, omega, points, margin)
        if self.tricycle and self.method is Method.FRC:
            dc = np.where(steers_to_close, dc * p.dcf, dc)
        # (3.33) by integration [RECON]. A candidate that leaves the centre where it is (a stop; a differential
        # drive's point turn) sweeps nothing new: it can always stop, even with an obstacle inside the margin.
        # Its DC_cd (the clearance it keeps) still sets the alpha_3 scaling of (3.35).
        in_place = self.in_place(v, omega)
        st_v = in_place | ((dc > 0) & self.stops_clear(v, omega, points, margin))
        if self.tricycle:
            st_w = np.ones(v.size, bool)  # §3.5: tricycles check ST_v only
        else:
            st_w = can_stop_turning(dc, omega, alpha_min)  # (3.34)

        if self.tricycle and state.v == 0.0:
            steer = self._steer_at_rest(state, points, distance, heading, v_min)
            if steer is not None:
                return steer
        # Oppose the current motion (standing still: move away from the nearer of front and rear).
        backwards = state.v > 0 or (state.v == 0 and d_obfr <= d_obrr)
        v_oppose = v_window[0] if backwards else v_window[1]
        at_oppose = np.isclose(v, v_oppose)
        if self.tricycle and self.method is Method.FRC:  # (3.36)
            secondary = secondary_objective_tricycle(heading_term, dc, st_v, p)
        elif self.tricycle:  # (3.40)
            secondary = secondary_objective_reduced(heading_term, st_v, p)
        else:  # (3.37)
            secondary = secondary_objective_differential(heading_term, dc, st_v, st_w, state.v, p)
        secondary = np.where(admissible & at_oppose, secondary, INVALID)
        best = int(np.argmax(secondary))
        if secondary[best] > INVALID:
            return Decision(float(v[best]), float(omega[best]), "secondary", float(secondary[best]), v_min)

        if self.tricycle:
            c_min, c_max = self.curvature_limits(state.steer)
            w = tricycle_turn(v_oppose, (c_min + c_max) / 2, (w_lo, w_hi))
        else:
            w = (w_lo + w_hi) / 2
        if self.towards(np.array([v_oppose]), np.array([w]), flagged)[0]:
            return self._brake(state, v_window, (w_lo, w_hi), v_min)
        return Decision(float(v_oppose), w, "curvature", INVALID, v_min)

    def _braking_continuation(self, state: DriveState, v_window, w_window) -> tuple[float, float]:
        """The next step of braking along the current curvature, as ``stops_clear`` assumes it, within the
        windows."""
        brake = min(self.params.a_a, self.limits.accel_max) * self.dt
        turn = self.limits.angular_accel_max * self.dt
        v = _clip(float(np.sign(state.v)) * max(abs(state.v) - brake, 0.0), *v_window)
        curvature = state.omega / state.v if abs(state.v) > 1e-9 else 0.0
        omega = _clip(curvature * v, state.omega - turn, state.omega + turn)
        return v, _clip(omega, *w_window)

    def _curvature_checks(self, state: DriveState, v: np.ndarray, omega: np.ndarray, points: np.ndarray,
                          distance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The curvature constraint per candidate, and whether it steers towards a close side obstacle CL_ob
        (tricycle FRC only)."""
        if not self.tricycle:
            return np.ones(v.size, bool), np.zeros(v.size, bool)  # CC_D holds by construction (module notes)
        c_min, c_max = self.curvature_limits(state.steer)
        still = np.abs(v) < 1e-9
        curvature = omega / np.where(still, 1.0, v)
        if self.method.modified:
            cc = tricycle_curvature_constraint(state.v, v, omega, c_min, c_max)  # CC_T = CC1 CC4 [RECON]
        else:
            cc = curvature_in_range(v, omega, c_min, c_max)  # ODW, ODWDS: like CC_D
        if self.method is not Method.FRC:
            return cc, np.zeros(v.size, bool)
        left, right = self.close_sides(points, distance)
        steers_to_close = ~still & ((left & (curvature > 1e-9)) | (right & (curvature < -1e-9)))
        return cc, steers_to_close

    def close_sides(self, points: np.ndarray, distance: np.ndarray) -> tuple[bool, bool]:
        """Whether a close side obstacle CL_ob lies on the left, and on the right."""
        p = self.params
        bearing = np.arctan2(points[:, 1], points[:, 0])
        close = distance - self.radius <= p.close_side_distance
        lo, hi = p.side_sector
        return (bool((close & (bearing >= lo) & (bearing <= hi)).any()),
                bool((close & (-bearing >= lo) & (-bearing <= hi)).any()))

    def _steer_at_rest(self, state: DriveState, points: np.ndarray, distance: np.ndarray, heading: float,
                       v_min: float) -> Decision | None:
        """A tricycle at rest with no admissible candidate turns its front wheel (a turn-only command,
        ``locomotion.next_steer``): away from a close side obstacle on one side only, else towards the target
        heading; None once the wheel is at that lock. [RECON: the thesis does not say what a tricycle does from
        rest when nothing is admissible.] The wedge this breaks: stopped beside an obstacle with the wheel turned
        towards it, every forward candidate steers towards CL_ob (DCF = 0 rejects them; the secondary objective
        then picks a creep that cannot stop), the obstacle is outside the front sector so (3.23) forbids
        reversing, and "oppose the current motion" from rest is v = 0 or such a creep: with a wheel that does not
        turn at v = 0 the robot stayed there, or rocked towards the obstacle a millimetre at a time, for good."""
        left, right = self.close_sides(points, distance)
        side = 1.0 if right and not left else -1.0 if left and not right else (1.0 if heading >= 0 else -1.0)
        if abs(side * self.steering.steer_max - state.steer) < 1e-9:
            return None
        return Decision(0.0, side * STEER_REQUEST, "steer", INVALID, v_min)

    def _brake(self, state: DriveState, v_window, w_window, v_min: float) -> Decision:
        """The reachable velocity nearest a standstill; a tricycle keeps its steering angle."""
        v = _clip(0.0, *v_window)
        if self.tricycle:
            omega = tricycle_turn(v, math.tan(state.steer) / self.steering.wheelbase, w_window)
        else:
            omega = _clip(0.0, *w_window)
        return Decision(v, omega, "brake", INVALID, v_min)


def tricycle_turn(v: float, curvature: float, w_window: tuple[float, float]) -> float:
    """A tricycle's turn rate at speed ``v`` along ``curvature``, within the angular window; none standing, whatever
    the window (it has no point turns, and a turn-only command would turn its wheel instead)."""
    return _clip(v * curvature, *w_window) if v else 0.0


def _clip(x: float, lo: float, hi: float) -> float:
    """np.clip of one number (the same value; numpy's call costs more than the arithmetic)."""
    return float(min(max(x, lo), hi))


def _floats(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float)


def _columns(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x and y of (m, 2) points as contiguous arrays, as the compiled kernels take them."""
    points = np.asarray(points, float).reshape(-1, 2)
    return np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1])


def _samples(lo: float, hi: float, count: int) -> np.ndarray:
    """``count`` evenly spaced values over [lo, hi], plus 0 when it lies inside (in order)."""
    if hi > lo and count > 1:  # np.linspace's arithmetic, without its generality's cost
        values = np.arange(count, dtype=float) * ((hi - lo) / (count - 1)) + lo
        values[-1] = hi
    else:
        values = np.array([lo])
    if lo < 0.0 < hi:
        at = int(np.searchsorted(values, 0.0))
        if at == values.size or values[at] != 0.0:
            values = np.concatenate((values[:at], [0.0], values[at:]))
    return values


def _pairs(v_samples: np.ndarray, w_samples: np.ndarray, last: tuple[float, float]) -> tuple[np.ndarray, ...]:
    """Every (v, omega) of the samples, v-major, then the pair ``last``."""
    n = v_samples.size * w_samples.size
    v, omega = np.empty(n + 1), np.empty(n + 1)
    v[:n].reshape(v_samples.size, w_samples.size)[:] = v_samples[:, None]
    omega[:n].reshape(v_samples.size, w_samples.size)[:] = w_samples
    v[n], omega[n] = last
    return v, omega


# ====================================================================== controllers


def _compose(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """Pose b, expressed in frame a, in a's parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], float(wrap(a[2] + b[2]))


def _inverse(a: tuple[float, float, float]) -> tuple[float, float, float]:
    c, s = math.cos(a[2]), math.sin(a[2])
    return -c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2]


def _advance(pose: tuple[float, float, float], v: float, omega: float, dt: float) -> tuple[float, float, float]:
    """Exact unicycle motion of the reference point over dt."""
    x, y, th = pose
    if abs(omega) < 1e-9:
        return x + v * dt * math.cos(th), y + v * dt * math.sin(th), th
    radius = v / omega
    th_new = th + omega * dt
    return (x + radius * (math.sin(th_new) - math.sin(th)), y - radius * (math.cos(th_new) - math.cos(th)),
            float(wrap(th_new)))



class _PoseTracker:
    """Odometry (from the measured velocities, else the controller's own commands), and the pose estimate: the
    last fix advanced by odometry."""

    def __init__(self, history_seconds: float):
        self.odometry = (0.0, 0.0, 0.0)
        self.history: deque = deque()  # (time, odometry pose)
        self.history_seconds = history_seconds
        self.correction = None  # world pose of the odometry frame
        self.fix_time = None
        self.time = None

    def update(self, time: float, fix, v: float, omega: float):
        """Advance odometry to ``time`` at (v, omega), the velocities of the period since the last update; take in
        a new fix. Returns the pose estimate (x, y, heading), or None before the first fix."""
        if self.time is not None:
            self.odometry = _advance(self.odometry, v, omega, time - self.time)
        self.time = time
        self.history.append((time, self.odometry))
        while self.history[0][0] < time - self.history_seconds:
            self.history.popleft()
        if fix is not None and fix.time != self.fix_time:
            self.fix_time = fix.time
            at_fix = next((pose for t, pose in reversed(self.history) if t <= fix.time + 1e-9), self.history[0][1])
            self.correction = _compose((fix.x, fix.y, fix.heading), _inverse(at_fix))
        return None if self.correction is None else _compose(self.correction, self.odometry)


def _to_frame(pose: tuple[float, float, float], points: np.ndarray) -> np.ndarray:
    """Points (m, 2) given in the frame of ``pose`` (x, y, heading), in the pose's parent frame."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    x, y = points[:, 0], points[:, 1]
    out = np.empty((len(points), 2))
    out[:, 0], out[:, 1] = pose[0] + c * x - s * y, pose[1] + s * x + c * y
    return out


class DynamicWindowController:
    """A reactive navigator (FRC, RFRC, ODW or ODWDS) for one robot, driving to ``goal`` (x, y).

    ``centre_offset``: how far the robot's physical centre is ahead of its pose's reference point (the tricycle
    model's is half its wheelbase). ``sensor_radius``: the IR sensors' distance from the centre, one for all or
    one per sensor in the order of the observation's readings (a polygon's sensors sit on its sides, nearer the
    centre than its enclosing circle; default: the footprint radius). ``steering``: a tricycle's steering geometry
    (its TricycleSpec will do)."""
    method = Method.FRC
    escapes_traps = False  # FRC's departure from the thesis (trap_escape); the printed methods have none

    def __init__(self, limits: DriveLimits, kind: str, footprint_radius: float, goal: tuple[float, float], *,
                 params: DynamicWindowParams = DynamicWindowParams(),
                 direction: DirectionSensorParams = DirectionSensorParams(), centre_offset: float = 0.0,
                 sensor_radius: float | np.ndarray | None = None, steering=SteeringGeometry(),
                 control_dt: float = 0.1,
                 obstacle_memory: float = 8.0):
        self.window = DynamicWindow(limits, kind, footprint_radius, method=self.method, params=params,
                                    centre_offset=centre_offset, steering=steering, control_dt=control_dt)
        self.goal = (float(goal[0]), float(goal[1]))
        self.direction = direction
        self.radius = footprint_radius
        self.offset = centre_offset
        self.sensor_radius = np.asarray(footprint_radius if sensor_radius is None else sensor_radius, float)
        self.memory_seconds = obstacle_memory
        self.tracker = _PoseTracker(history_seconds=max(obstacle_memory, 2.0))
        self.memory: deque = deque()  # (time, how many points) of each reading remembered, oldest first
        self.remembered = np.empty((0, 2))  # their obstacle points in the odometry frame, in the same order
        self.state = DriveState()
        self.v_min = 0.0
        self.last_decision: Decision | None = None
        self.previous_direction: float | None = None  # last theta_tmod, world frame
        self.arrived = False
        self.trail: list[tuple[float, float, float]] = []  # (time, x, y) of every pose estimate, for the outcome
        self.pose_estimate: tuple[float, float, float] | None = None  # the last fix advanced by odometry
        self.escape = TrapEscape(self.goal, footprint_radius, multi_point=self.window.tricycle) \
            if self.escapes_traps else None
        # a trapped tricycle turns to face its plan in legs, having no point turns
        self.turn = MultiPointTurn(self.window) if self.escapes_traps and self.window.tricycle else None
        self.sweep = 0.0  # +-1 while a wedged tricycle sweeps its wheel towards that lock (``_wedged``)

    @property
    def name(self) -> str:
        return self.method.value

    def __call__(self, obs: Observation) -> Command:
        contact = self._contact(self.state, obs.velocity)
        if len(contact):
            self.state = DriveState(obs.velocity[0], obs.velocity[1], self.state.steer)
        v, omega = (self.state.v, self.state.omega) if obs.velocity is None else obs.velocity
        pose = self.pose_estimate = self.tracker.update(obs.time, obs.pose, v, omega)
        seen = self._seen(obs, contact)
        points = self._remember(obs.time, seen)
        if pose is None:
            return self._command(0.0, 0.0, "no fix")
        self.trail.append((obs.time, pose[0], pose[1]))
        if self.escape is not None:
            self.escape.hits.add(_to_frame(pose, seen))
        centre = (pose[0] + self.offset * math.cos(pose[2]), pose[1] + self.offset * math.sin(pose[2]))
        d_tgt = math.dist(centre, self.goal)
        self.arrived = self.arrived or (d_tgt <= self.window.params.d_stop and abs(self.state.v) < 1e-9)
        if self.arrived:
            return self._command(0.0, 0.0, "arrived")
        target = self.waypoint(pose, centre, obs)
        heading = bearing = float(wrap(target_heading(*centre, *target) - pose[2]))
        if self.method.uses_direction_sensor:
            previous = None if self.previous_direction is None else float(wrap(self.previous_direction - pose[2]))
            heading = modified_target_heading(points, heading, self.radius, self.direction, previous)
            self.previous_direction = heading + pose[2]
        turn_first = self._turn_first(bearing, obs.time)
        if turn_first and self.turn is not None:  # a tricycle turns in legs
            command = self.turn.command(self.state, points, bearing)
            self.sweep = 0.0
            if command is not None:
                return self._command(*command, f"{self.name} escape turn")
            self.escape.stop_turning()  # no room for a leg either way: the window drives
            turn_first = False
        if self.turn is not None:
            self.turn.restart()
        if turn_first:  # a differential drive turns in place towards the plan itself, not theta_tmod
            decision = self.window.decide(self.state, points, bearing, d_tgt, self.v_min, v_cap=0.0)
        else:
            decision = self.window.decide(self.state, points, heading, d_tgt, self.v_min)
        if self.turn is not None and self._wedged(decision):
            return self._command(0.0, self.sweep * STEER_REQUEST, f"{self.name} sweep")
        self.last_decision = decision
        self.v_min = decision.v_min
        escaping = self.escape is not None and self.escape.escaping
        return self._command(decision.v, decision.omega, f"{self.name} escape" if escaping else self.name)

    def _turn_first(self, bearing: float, time: float) -> bool:
        """Whether to turn on the spot towards ``bearing`` (the way ahead, relative to the robot) before driving
        on: a trapped FRC facing its escape plan (``TrapEscape.turn_first``)."""
        return self.escape is not None and self.escape.turn_first(bearing, time)

    def _wedged(self, decision: Decision) -> bool:
        """Whether a standing tricycle is wedged: the window has nothing to do but stand, its own steering at rest
        done (the wheel at the lock it chose, ``_steer_at_rest``). Then the wheel sweeps from lock to lock (the
        window's own steer requests overridden meanwhile), so that the window meets every steering angle: with
        boxes close on both sides the lock it chose leads into one of them, and a straighter wheel leads out.
        Ends when the window moves the robot. Sets the sweep's direction as it goes. Not in the thesis (issue 22;
        docs/decisions.md, "Multi-point turn")."""
        standing = self.state.v == 0.0 and decision.v == 0.0 and decision.branch in ("steer", "curvature", "brake")
        if not standing or (self.sweep == 0.0 and decision.branch == "steer"):
            self.sweep = 0.0
            return False
        lock = self.window.steering.steer_max
        if self.sweep == 0.0 or abs(self.state.steer - self.sweep * lock) < 1e-9:
            self.sweep = -1.0 if self.state.steer > 0 else 1.0
        return True

    def waypoint(self, pose: tuple[float, float, float], centre: tuple[float, float], obs: Observation):
        """The point the direction sensor aims at: the goal itself for the reactive controllers, or a trapped
        FRC's way out (``trap_escape``)."""
        return self.goal if self.escape is None else self.escape.waypoint(obs.time, centre, pose[2])

    def _contact(self, commanded: DriveState, velocity) -> np.ndarray:
        """Where a stall says the body touches, relative to the pose's reference point in the robot frame: the
        point of the enclosing circle the centre was moving towards, when the odometry shows the robot stopped, and
        not turning as asked, although it was driven (a touch the IR ring did not see, such as a box corner between
        two beams).
        Empty when there is no stall."""
        if (velocity is None or abs(commanded.v) < STALL_DRIVEN_SPEED
                or abs(velocity[0]) > STALL_SPEED_SHARE * abs(commanded.v)
                or abs(velocity[1]) > STALL_SPEED_SHARE * max(abs(commanded.omega), STALL_TURN_FLOOR)):
            return NO_CONTACT
        bearing = math.atan2(commanded.omega * self.offset, commanded.v)
        return np.array([[self.offset + self.radius * math.cos(bearing), self.radius * math.sin(bearing)]])

    def _seen(self, obs: Observation, contact: np.ndarray) -> np.ndarray:
        """This reading's obstacle points, and any stall ``contact``, relative to the pose's reference point in
        the robot frame."""
        body = kernels.reading_points(_floats(obs.ir_range), _floats(obs.ir_bearings),
                                      _floats(self.sensor_radius.reshape(-1)), self.offset)
        return np.concatenate([body, contact]) if len(contact) else body

    def _remember(self, time: float, body: np.ndarray) -> np.ndarray:
        """Points ``body`` (robot frame) added to the memory; all remembered points relative to the centre, in
        the robot frame."""
        ox, oy, oth = self.tracker.odometry
        self.memory.append((time, len(body)))
        forgotten = 0
        while self.memory[0][0] < time - self.memory_seconds:
            forgotten += self.memory.popleft()[1]
        world = np.concatenate([self.remembered[forgotten:], _to_frame((ox, oy, oth), body)])
        self.remembered = world
        c, s = math.cos(oth), math.sin(oth)
        # A slow robot sees the same spots again and again: keep one point per 2 cm cell.
        return kernels.thin_to_robot_frame(world, MEMORY_CELL, ox, oy, c, s, self.offset)

    def _command(self, v: float, omega: float, behaviour: str) -> Command:
        """Issue (v, omega) and track the drive state it leads to; a tricycle's steering angle follows as the
        tricycle locomotion turns it (``locomotion.next_steer``); a tricycle standing still does not turn, whatever
        its command asks of the wheel."""
        steer, turn_rate = self.state.steer, omega
        if self.window.tricycle:
            steer = next_steer(steer, v, omega, (v, omega), self.window.steering, self.window.dt)
            turn_rate = omega if v != 0.0 else 0.0
        self.state = DriveState(v, turn_rate, steer)
        return Command(v=v, omega=omega, behaviour=behaviour)


class FRC(DynamicWindowController):
    """Final reactive controller: direction sensor + the full modified dynamic window (§3.6.2), and a way out of
    the pockets the printed method circles in for good (``trap_escape``; issue 22), which a tricycle turns out of
    in legs (``multi_point_turn``)."""
    method = Method.FRC
    escapes_traps = True


class PrintedFRC(DynamicWindowController):
    """FRC exactly as §3.6.2 prints it, without the trap escape: the thesis's own behaviour, for comparison."""
    method = Method.FRC

    @property
    def name(self) -> str:
        return "frc-printed"


class RFRC(DynamicWindowController):
    """Reduced-parameter FRC: DCF = 1, no CL_ob, (3.39) and (3.40) (§3.6.2)."""
    method = Method.RFRC


class ODW(DynamicWindowController):
    """The original dynamic window alone, objective (3.38) with beta_1 = 0.3 (§3.6.2)."""
    method = Method.ODW


class ODWDS(DynamicWindowController):
    """The original dynamic window behind the direction sensor, beta_1 = 0.005 (§3.6.2)."""
    method = Method.ODWDS


class HRDK(FRC):
    """Hybrid reactive-deliberative navigation in a known environment (§3.6.2): plan once with the modified A*
    (known map, so w_p1 = w_p2 = 0) on ``known_map``, impassable cells inflated by the footprint radius plus a
    clearance, then follow the path with FRC, aiming N_t nodes ahead of the path node closest to the robot. Past
    the end of a partial path the robot heads for the goal reactively (§3.2.2)."""
    escapes_traps = False  # its plan already leads round the pockets

    def __init__(self, limits: DriveLimits, kind: str, footprint_radius: float, goal: tuple[float, float], *,
                 known_map: OccupancyGrid, planner: PlannerParams = PlannerParams(),
                 following: PathFollowing = PathFollowing(), **kwargs):
        super().__init__(limits, kind, footprint_radius, goal, **kwargs)
        self.grid = known_map
        self.planner = planner
        self.following = following
        self.follower: PathFollower | None = None
        self.keep_out: np.ndarray | None = None  # bool, the grid's shape: cells no plan crosses, whatever the map
        # says (set by the user, e.g. a wheeled explorer round the bogs it met)

    @property
    def name(self) -> str:
        return "hrdk"

    def plan(self, centre: tuple[float, float]) -> None:
        grid = self.grid
        if self.keep_out is not None:
            grid = OccupancyGrid(grid.origin, grid.resolution,
                                 np.where(self.keep_out, grid.params.p_max, grid.probabilities), grid.params)
        path, result = plan_on_grid(grid, centre, self.goal, self.planner, self.radius + self.following.clearance)
        self.follower = PathFollower(path, result.reached, self.grid.resolution, self.following)

    def waypoint(self, pose, centre, obs):
        if self.follower is None:
            self.plan(centre)
        return self.follower.waypoint(centre, self.goal)

    def retarget(self, goal: tuple[float, float], path: np.ndarray | None = None) -> None:
        """Drive on to a new ``goal``: along ``path`` ((n, 2) world points, e.g. a planner's) if given, else along
        a plan of its own made at the next decision. The obstacle memory is kept."""
        self.goal = (float(goal[0]), float(goal[1]))
        self.arrived = False
        self.follower = None if path is None else PathFollower(np.asarray(path, float), True, self.grid.resolution,
                                                                self.following)


@dataclass(frozen=True)
class Replanning:
    # The thesis re-plans on poor progress "with time delays" (§3.6.3) but gives no trigger; chosen.
    progress_period: float = 10.0  # s between progress checks (3.6)
    blocked_lookahead: int = 20  # re-plan when one of this many path nodes ahead becomes impassable
    min_interval: float = 2.0  # s: at most one re-plan this often
    # Not in the thesis: after a progress check finds poor progress and the robot still where it was, a differential
    # or tracked robot first turns on the spot to face its (re-planned) path, as a trapped FRC does
    # (``TrapEscape.turn_first``, the same limits). Off by default, so the navigation study's HRDU is the thesis's;
    # the explorers use it (docs/decisions.md, "HRDU turns to its path").
    turn_to_path: bool = False
    facing: float = EscapeParams.facing
    turning: float = EscapeParams.turning
    settle: float = 0.5  # s: the turn ends facing the path with a turn rate the drive can stop within this time


class HRDU(HRDK):
    """Hybrid navigation in an unknown environment (§3.6.2): map with ``grid`` (unexplored to begin with) from
    every IR reading, plan with the exploration weights of (3.5)-(3.6), and re-plan when the path ahead turns out
    to be blocked or when progress towards the goal over a period falls below d_progmin, adapting the weights."""

    def __init__(self, limits: DriveLimits, kind: str, footprint_radius: float, goal: tuple[float, float], *,
                 grid: OccupancyGrid, adaptation: WeightAdaptation = WeightAdaptation(),
                 replanning: Replanning = Replanning(), planner: PlannerParams = PlannerParams(), **kwargs):
        planner = replace(planner, weight_critical=adaptation.initial_critical,
                          weight_unexplored=adaptation.initial_unexplored)
        super().__init__(limits, kind, footprint_radius, goal, known_map=grid, planner=planner, **kwargs)
        self.adaptation = adaptation
        self.replanning = replanning
        self.last_plan_time = -math.inf
        self.progress_check = None  # (time, distance to goal, centre) at the last progress check
        self.replans = 0  # plans after the first
        self.turn_started: float | None = None  # turning on the spot to face the path since (``turn_to_path``)
        # The last reading's evidence mapped into ``grid``, with its pose and time: another grid of the same frame
        # (an explorer's outgoing map) can apply it rather than compute it again.
        self.last_evidence: Evidence | None = None

    @property
    def name(self) -> str:
        return "hrdu"

    def retarget(self, goal: tuple[float, float], path: np.ndarray | None = None) -> None:
        super().retarget(goal, path)
        self.progress_check = None

    def waypoint(self, pose, centre, obs):
        evidence = self.grid.update(pose, obs.ir_range, obs.ir_bearings, sensor_radius=self.sensor_radius,
                                    centre_offset=self.offset, footprint_radius=self.radius)
        self.last_evidence = replace(evidence, time=obs.time)
        distance = math.dist(centre, self.goal)
        if self.follower is None:
            self.plan(centre)
            self.last_plan_time = obs.time
            self.progress_check = (obs.time, distance, centre)
            return super().waypoint(pose, centre, obs)
        if self.progress_check is None:  # following a path handed over by ``retarget``
            self.progress_check = (obs.time, distance, centre)
        replan = self.path_blocked()
        if obs.time - self.progress_check[0] >= self.replanning.progress_period:
            progress = self.progress_check[1] - distance
            self.planner = adapt_weights(self.planner, progress, self.adaptation)  # (3.6)
            poor = progress < self.adaptation.min_progress
            replan = replan or poor
            # stuck where it was, not winding along its path: turn to face the path first
            stuck = poor and math.dist(centre, self.progress_check[2]) < self.adaptation.min_progress
            if stuck and self.replanning.turn_to_path and not self.window.tricycle and self.turn_started is None:
                self.turn_started = obs.time
            self.progress_check = (obs.time, distance, centre)
        if replan and obs.time - self.last_plan_time >= self.replanning.min_interval:
            self.plan(centre)
            self.last_plan_time = obs.time
            self.replans += 1
        return super().waypoint(pose, centre, obs)

    def _turn_first(self, bearing: float, time: float) -> bool:
        """After poor progress in place (``Replanning.turn_to_path``): until facing the path, for at most ``turning``
        s. A slow robot with a small angular acceleration otherwise keeps a tight circle that only just clears the
        boxes and walls beside it: reducing its turn rate would swing its arc into them (traced: a tracked explorer
        circled for 1000 s between a box and the world's wall, its path 1 m ahead)."""
        if self.turn_started is None:
            return False
        r = self.replanning
        settled = abs(self.state.omega) <= self.window.limits.angular_accel_max * r.settle  # else it overshoots
        if (abs(bearing) <= r.facing and settled) or time - self.turn_started >= r.turning:
            self.turn_started = None
        return self.turn_started is not None

    def path_blocked(self) -> bool:
        """Whether a cell now mapped impassable lies within the planning inflation of the path just ahead
        (``dwa_kernels.path_blocked``)."""
        ahead = self.follower.path[self.follower.node:self.follower.node + self.replanning.blocked_lookahead]
        return kernels.path_blocked(self.grid.probabilities, np.asarray(ahead, float), *self.grid.origin,
                                    self.grid.resolution, self.radius + self.following.clearance,
                                    self.planner.occupied_threshold)

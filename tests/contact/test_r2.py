"""Contact regression: Parker's R-2 (§2.2.1) drives, grips, lifts, carries and pushes as the thesis says.

Everything runs through the full World (locomotion with its acceleration limits, physics contacts, IR model,
seed 0). The gripper behaviours judge success from the robot's own sensors; these tests check them against
ground truth (body positions), with the tolerances of the issue: a lifted puck rises > 0.1 m and slips
< 3 mm in the pads' frame while carried through four 90 degree turns and 1 m; a 2 kg puck cannot be lifted;
the beams are broken exactly while a puck lies across them; one R-2 cannot translate the long box by pushing
its middle (< 2 cm in 10 s) but turns it by pushing an end (> 5 degrees), and two R-2s pushing the ends in
turn advance it (> 0.1 m); 2 m straight with < 3 % drift, circle radius within 5 %, stopping within v^2/2a.
"""
from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from teamsim.controllers.skills import gripper as G
from teamsim.models.objects import BoxDims, PuckDims
from teamsim.models.r2 import R2Dims, build
from teamsim.world import yaw_of
from tests.contact.harness import CustomParams, RobotSlot, body_pose, make_world, run_for

R2 = R2Dims()
PUCK = PuckDims()
SEED = 0
BOX = BoxDims()


def solo(policy, x=0.0, y=0.0, yaw=0.0, room=(6.0, 6.0), **params):
    world = make_world(CustomParams(room=room, robots=[RobotSlot("red", "r2", x, y, yaw)], **params),
                       {"red": policy}, seed=SEED)
    return world, world.robots["red"]


def unstable_warnings(world) -> list[str]:
    return [mujoco.mjtWarning(k).name for k, n in enumerate(world.data.warning.number) if n]


FRAMES = {mujoco.mjtObj.mjOBJ_BODY: ("xpos", "xmat"), mujoco.mjtObj.mjOBJ_GEOM: ("geom_xpos", "geom_xmat"),
          mujoco.mjtObj.mjOBJ_SITE: ("site_xpos", "site_xmat")}


def frame_of(world, kind, name):
    """World position and rotation matrix of a body, geom or site."""
    mujoco.mj_kinematics(world.model, world.data)
    i = mujoco.mj_name2id(world.model, kind, name)
    pos, mat = FRAMES[kind]
    return getattr(world.data, pos)[i].copy(), getattr(world.data, mat)[i].reshape(3, 3).copy()


def in_frame(world, kind, frame, body):
    """Position of ``body`` in the frame of ``frame`` (a body, geom or site)."""
    origin, rotation = frame_of(world, kind, frame)
    return rotation.T @ (body_pose(world, body) - origin)


def sensors() -> G.GripperSensors:
    return G.GripperSensors.of(build("layout"))


# -- the model -----------------------------------------------------------------------------------------------
def test_every_part_compiles_to_the_thesis_size():
    world, red = solo(lambda o: (0.0, 0.0))
    m, d = world.model, world.data
    root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "red/")
    assert m.body_subtreemass[root] == pytest.approx(5.0, abs=0.05), "about 5 kg (assumed)"
    mujoco.mj_kinematics(m, d)
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for g in red.geoms:
        if m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0:
            continue  # visual only
        pos, size = d.geom_xpos[g], m.geom_size[g]
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:
            half = np.abs(d.geom_xmat[g].reshape(3, 3)) @ size
        elif m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
            half = np.full(3, size[0])
        else:  # cylinder: radius across its axis, half length along it
            axis = d.geom_xmat[g].reshape(3, 3)[:, 2]
            half = np.abs(axis) * size[1] + size[0] * np.sqrt(np.clip(1 - axis ** 2, 0, 1))
        lo, hi = np.minimum(lo, pos - half), np.maximum(hi, pos + half)
    extent = hi - lo
    assert extent == pytest.approx([R2.depth, R2.width, R2.height], abs=2e-3), "12.5 x 10 x 14 in (§2.2.1)"
    jaw = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "red/finger_left")
    lift = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "red/lift")
    assert 2 * m.jnt_range[jaw][1] == pytest.approx(3 * 0.0254), "3 in opening"
    assert m.jnt_range[lift][1] == pytest.approx(7 * 0.0254), "7 in lift"
    assert len(red.model.ir_sensors) == 8 and len(red.model.beams) == 2


def test_ir_bearings_match_the_sensor_sites():
    world, red = solo(lambda o: (0.0, 0.0))
    for name, bearing in zip(red.model.ir_sensors, red.model.ir_bearings):
        _, rotation = frame_of(world, mujoco.mjtObj.mjOBJ_SITE, f"red/{name}")
        look = rotation[:, 2]
        assert math.atan2(look[1], look[0]) == pytest.approx(bearing, abs=1e-6), name


def test_idle_is_stable():
    world, red = solo(lambda o: (0.0, 0.0))
    run_for(world, 0.5)  # settle onto the floor
    start = world.data.qpos[red.qpos_adr:red.qpos_adr + 3].copy()
    run_for(world, 10.0)
    assert unstable_warnings(world) == []
    assert np.abs(world.data.qpos[red.qpos_adr:red.qpos_adr + 3] - start).max() < 1e-3
    assert not any(o.break_beams.any() for o in world.controllers["red"].observations), "closed, empty jaw"


# -- driving -------------------------------------------------------------------------------------------------
def test_drives_two_metres_straight():
    world, red = solo(lambda o: (R2.v_max, 0.0), x=-2.0)
    start = world.pose(red)
    run_for(world, 10.0, until=lambda w: w.pose(red)[0] - start[0] >= 2.0)
    end = world.pose(red)
    travelled = end[0] - start[0]
    assert travelled >= 2.0
    assert abs(end[1] - start[1]) / travelled < 0.03, "lateral drift"
    assert abs(end[2] - start[2]) < 0.03, "heading drift (rad)"


def test_follows_a_circle():
    v, omega = 0.2, 0.5
    world, red = solo(lambda o: (v, omega))
    run_for(world, 2.0)  # past the acceleration ramp
    points = []
    for _ in range(42):  # one full circle (2 pi / 0.5 = 12.6 s)
        run_for(world, 0.3)
        points.append(world.pose(red)[:2])
    points = np.array(points)
    a = np.c_[2 * points, np.ones(len(points))]
    cx, cy, k = np.linalg.lstsq(a, (points ** 2).sum(axis=1), rcond=None)[0]
    assert math.sqrt(k + cx ** 2 + cy ** 2) == pytest.approx(v / omega, rel=0.05)


def test_stops_within_its_deceleration_distance():
    commands = {"v": R2.v_max}
    world, red = solo(lambda o: (commands["v"], 0.0), x=-2.0)
    run_for(world, 3.0)
    speed = world.speed(red)
    assert speed == pytest.approx(R2.v_max, rel=0.02)
    start = world.pose(red)[:2]
    commands["v"] = 0.0
    run_for(world, 3.0)
    stopped = float(np.hypot(*(world.pose(red)[:2] - start)))
    braking = speed ** 2 / (2 * R2.accel_max)
    assert world.speed(red) < 0.01
    # The slew limiter takes its first step at once, so the discrete stop is up to half a control period of
    # cruising shorter than v^2/2a; it must not be longer (1 cm of tyre creep allowed).
    assert braking - speed * world.control_dt <= stopped <= braking + 0.01


# -- IR --------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("yaw, group", [(0.0, "ir_tip"), (math.pi, "ir_back"), (math.pi / 2, "ir_right"),
                                        (-math.pi / 2, "ir_left")])
def test_ir_reads_a_wall_within_the_noise_model(yaw, group):
    """The robot turned so that one group of sensors faces the east wall at several distances: each raw reading
    stays within 4 sigma of the calibration's response to the true distance along the ray (sigma = noise
    fraction x response, plus quantisation)."""
    room = 4.0
    for gap in (0.05, 0.15, 0.25):
        world, red = solo(lambda o: (0.0, 0.0), yaw=yaw, room=(room, room))
        ir = red.model.ir
        wall = room / 2
        faces = [k for k, name in enumerate(red.model.ir_sensors) if name.startswith(group)]
        sites = [frame_of(world, mujoco.mjtObj.mjOBJ_SITE, f"red/{red.model.ir_sensors[k]}") for k in faces]
        nearest = max(pos[0] for pos, _ in sites)
        world.data.qpos[red.qpos_adr] += wall - gap - nearest  # place the group's nearest sensor gap off the wall
        run_for(world, 2.0)
        for k, (pos, rotation) in zip(faces, sites):
            distance = (gap + nearest - pos[0]) / rotation[0, 2]  # along the sensor's ray (its site's z axis)
            raws = np.array([o.ir_raw[k] for o in world.controllers["red"].observations[3:]])
            clean = float(ir.response(distance))
            sigma = float(np.interp(distance, ir.distances, ir.noise_fractions)) * clean + ir.resolution
            assert clean > 0 and np.all(np.abs(raws - clean) <= 4 * sigma), (group, gap, distance, raws, clean)


# -- gripper ---------------------------------------------------------------------------------------------
PUCK_X = 0.35  # m ahead of the robot's axle: the fingertip IR (at 0.154 m) sees it at 0.17 m


def carry_route():
    """Four 0.27 m legs, each followed by a 90 degree turn to the left: 1.08 m and 360 degrees."""
    legs = []
    for _ in range(4):
        legs += [(0.2, 0.0, 1.35), (0.0, 1.0, math.pi / 2)]
    return G.TimedRoute(legs)


@pytest.fixture(scope="module")
def transport():
    """Approach, grasp, lift, carry, lower and release one puck; the trace the tests below examine."""
    layout = sensors()
    behaviours = [G.Approach(layout), G.Grasp(layout), G.Lift(layout), G.Carry(layout, carry_route()),
                  G.Lower(layout), G.Release(layout)]
    sequence = G.Sequence(behaviours)
    world, red = solo(sequence, pucks=[(PUCK_X, 0.0)])
    trace = {"behaviour": [], "puck": [], "in_pad": [], "pose": []}
    while world.time < 40.0 and sequence.status == G.RUNNING:
        run_for(world, world.control_dt)
        trace["behaviour"].append(sequence.current.name)
        trace["puck"].append(body_pose(world, "puck0/puck"))
        trace["in_pad"].append(in_frame(world, mujoco.mjtObj.mjOBJ_GEOM, "red/pad_left", "puck0/puck"))
        trace["pose"].append(world.pose(red))
    trace = {k: np.array(v) for k, v in trace.items()}
    return world, red, sequence, trace


def test_picks_a_puck_off_the_floor_and_lifts_it(transport):
    world, red, sequence, trace = transport
    assert [b.status for b in sequence.behaviours[:3]] == [G.SUCCEEDED] * 3
    lifted = trace["puck"][trace["behaviour"] == "carry"]
    rise = lifted[:, 2].min() - trace["puck"][0, 2]
    assert rise > 0.1, f"puck rose {rise:.3f} m"
    assert unstable_warnings(world) == []


def test_carries_it_through_four_turns_without_slipping(transport):
    world, red, sequence, trace = transport
    assert sequence.behaviours[3].status == G.SUCCEEDED
    carrying = trace["behaviour"] == "carry"
    poses = trace["pose"][carrying]
    path = np.hypot(*np.diff(poses[:, :2], axis=0).T).sum()
    turned = np.abs((np.diff(poses[:, 2]) + math.pi) % (2 * math.pi) - math.pi).sum()
    assert path >= 1.0 and math.degrees(turned) >= 4 * 85
    in_pad = trace["in_pad"][carrying]
    slip = np.linalg.norm(in_pad - in_pad[0], axis=1).max()
    assert slip < 3e-3, f"puck slipped {slip * 1000:.2f} mm in the pad's frame"


def test_sets_it_down_and_lets_go(transport):
    world, red, sequence, trace = transport
    assert sequence.status == G.SUCCEEDED
    puck = body_pose(world, "puck0/puck")
    assert abs(puck[2]) < 2e-3, "on the floor"
    _, rotation = frame_of(world, mujoco.mjtObj.mjOBJ_BODY, "puck0/puck")
    assert rotation[2, 2] > math.cos(math.radians(5)), "upright"
    ahead = in_frame(world, mujoco.mjtObj.mjOBJ_BODY, "red/carriage", "puck0/puck")
    assert ahead[0] - PUCK.radius > R2.front_beam_x, "clear of the jaw"
    last = world.controllers["red"].observations[-1]
    assert not last.break_beams.any() and last.touch["fingers"] == 0.0


@pytest.mark.parametrize("dy, yaw", [(0.03, 0.0), (-0.03, -0.1), (0.04, 0.1)])
def test_approach_centres_an_offset_puck_between_the_pads(dy, yaw):
    """A puck off to one side, seen by one fingertip: the robot turns to it and stops with it between the
    pads, clear of their tips (it needs < 12.7 mm of lateral error to enter an open jaw)."""
    approach = G.Approach(sensors())
    world, red = solo(approach, yaw=yaw, pucks=[(PUCK_X, dy)])
    run_for(world, 20.0, until=lambda w: approach.status != G.RUNNING)
    assert approach.status == G.SUCCEEDED
    puck = in_frame(world, mujoco.mjtObj.mjOBJ_BODY, "red/carriage", "puck0/puck")
    assert abs(puck[0] - R2.pad_x) < R2.pad_length / 2
    assert abs(puck[1]) < R2.half_jaw - PUCK.radius


def test_lifts_its_rated_payload_of_0_91_kg():
    """Parker §2.2.1: the R-2's gripper lifts 2 lb (0.91 kg); the lift is sized 1.3x that plus the carriage."""
    layout = sensors()
    sequence = G.Sequence([G.Approach(layout), G.Grasp(layout), G.Lift(layout)])
    world, red = solo(sequence, pucks=[(PUCK_X, 0.0)], puck_dims=PuckDims(mass=0.91))
    resting = body_pose(world, "puck0/puck")[2]
    run_for(world, 20.0, until=lambda w: sequence.status != G.RUNNING)
    assert sequence.status == G.SUCCEEDED
    run_for(world, 2.0)  # held up, not sliding out of the pads
    rise = body_pose(world, "puck0/puck")[2] - resting
    assert rise > 0.1, f"the 0.91 kg puck rose {rise:.3f} m"
    assert unstable_warnings(world) == []


def test_cannot_lift_two_kilograms():
    layout = sensors()
    sequence = G.Sequence([G.Approach(layout), G.Grasp(layout), G.Lift(layout)])
    world, red = solo(sequence, pucks=[(PUCK_X, 0.0)], puck_dims=PuckDims(mass=2.0))
    run_for(world, 20.0, until=lambda w: sequence.status != G.RUNNING)
    assert sequence.status == G.FAILED
    lift = sequence.behaviours[2]
    assert (lift.status, lift.reason) == (G.FAILED, "too heavy")
    run_for(world, 2.0)  # keeps trying
    assert body_pose(world, "puck0/puck")[2] < 5e-3, "the 2 kg puck stays on the floor"


def test_break_beams_are_broken_exactly_while_a_puck_lies_across_them():
    """Jaw open and down, the robot creeps over a puck (which ends up in the cavity, pushed by the bumper) and
    backs away again. At every tick each beam reads broken iff the puck's disc crosses the beam's line (1 mm
    left either side of the edge for contact penetration)."""
    commands, record, holder = {"v": 0.0}, [], []

    def policy(obs):
        puck = in_frame(holder[0], mujoco.mjtObj.mjOBJ_BODY, "red/carriage", "puck0/puck")  # ground truth now
        record.append((obs.break_beams.copy(), puck))
        return commands["v"], 0.0, {"grip": 1.0, "lift": 0.0}

    world, red = solo(policy, pucks=[(0.22, 0.0)])
    holder.append(world)
    run_for(world, 1.0)  # open the jaw
    record.clear()
    for v in (0.02, -0.02):  # over the puck, then back off it
        commands["v"] = v
        run_for(world, 6.0)
    beams_x = [R2.front_beam_x if name == "beam_front" else R2.rear_beam_x for name in red.model.beams]
    seen = {(k, state): 0 for k in range(2) for state in (True, False)}
    for broken, puck in record:
        assert abs(puck[1]) < R2.half_jaw
        for k, x in enumerate(beams_x):
            overlap = PUCK.radius - abs(puck[0] - x)
            if abs(overlap) > 1e-3:
                assert broken[k] == (overlap > 0), (k, puck, broken)
                seen[(k, bool(broken[k]))] += 1
    assert min(seen.values()) >= 3, seen
    assert record[-1][1][0] > R2.front_beam_x + PUCK.radius, "backed off past the puck"


def test_a_puck_under_the_raised_gripper_is_trapped_and_pushed():
    """Parker §3.8: the cavity under the gripper traps extra pucks. With the lift up, the robot drives over a
    puck: it passes under the jaw, stops against the front bumper between the skirts and is pushed along,
    through a turn too."""
    world, red = solo(G.TimedRoute([(0.15, 0.0, 4.0), (0.1, 0.3, 3.0)]), pucks=[(0.3, 0.0)])
    world.controllers["red"].policy = lambda o, route=world.controllers["red"].policy: (
        *(route(o) or (0.0, 0.0)), {"grip": 0.0, "lift": 1.0})
    start = body_pose(world, "puck0/puck")
    run_for(world, 7.5)
    puck = in_frame(world, mujoco.mjtObj.mjOBJ_BODY, "red/chassis", "puck0/puck")
    assert R2.front_x < puck[0] - PUCK.radius < R2.front_x + 0.01, "against the front bumper"
    assert abs(puck[1]) < R2.prong_y - PUCK.radius + 1e-3, "between the skirts"
    assert np.hypot(*(body_pose(world, "puck0/puck") - start)[:2]) > 0.5
    assert max(o.touch["bump_front"] for o in world.controllers["red"].observations) > 0.0, "the bumper feels it"


@pytest.mark.parametrize("side", [0.075, 0.082, -0.075, -0.082])
def test_a_sweep_that_pushes_a_puck_beside_the_jaw_backs_off_and_picks_it_up(side):
    """A puck beside the jaw is met by the front bumper; neither the fingertips nor the beams see it. The sweep
    stops on the bump, backs off, turns to look and picks it up, instead of pushing it along its line (1-2 m into
    a wall in the cleanup, kill-red seed 214 and break-gripper seed 218)."""
    from teamsim.controllers.behaviours.cleanup import MOVE, CleanupRobot, locations_from_extents

    brain = CleanupRobot(build("red"), np.random.default_rng(SEED))
    brain.knowledge.learn_locations(locations_from_extents(np.array([-2.8, 2.8, -2.8, 2.8]), np.array([-2.8, 0.0]),
                                                           clearance=0.4))
    move = brain.sets[MOVE]
    move.state, move.line = "sweep", (0.0, 2.5, None)  # east along y = 0 for 2.5 m

    def sweep(obs):
        return (0.0, 0.0) if brain.estimate.update(obs) is None else move(obs)

    start = np.array([-1.5, side])
    world, red = solo(sweep, x=-2.0, pucks=[tuple(start)])
    run_for(world, 40.0, until=lambda w: move.state == "carry")
    assert move.state == "carry", f"ended in {move.state}"
    puck = body_pose(world, "puck0/puck")
    assert puck[2] > 0.1, "lifted"
    assert np.hypot(*(puck[:2] - start)) < 0.4, "not pushed along the line"


def test_a_puck_knocked_onto_its_side_stops_rolling():
    """Rolling resistance (PuckDims.roll_damping): on its side and rolling at 0.1 m/s, a puck stops within 8 cm
    and stays; without it, it rolled on at constant speed (MuJoCo's contacts here have no rolling friction)."""
    world, red = solo(lambda o: (0.0, 0.0), x=-2.0, pucks=[(0.5, 0.0)])
    joint = world.model.body_jntadr[mujoco.mj_name2id(world.model, mujoco.mjtObj.mjOBJ_BODY, "puck0/")]  # the frame
    adr, dof = world.model.jnt_qposadr[joint], world.model.jnt_dofadr[joint]
    world.data.qpos[adr:adr + 3] = (0.5, 0.0, PUCK.radius)
    world.data.qpos[adr + 3:adr + 7] = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # axis along y
    world.data.qvel[dof:dof + 6] = (0.1, 0.0, 0.0, 0.0, 0.1 / PUCK.radius, 0.0)  # rolling along +x
    run_for(world, 3.0)
    after_3s = body_pose(world, "puck0/puck")
    run_for(world, 5.0)
    end = body_pose(world, "puck0/puck")
    assert after_3s[0] - 0.5 < 0.08 and abs(end[0] - after_3s[0]) < 1e-3, (after_3s, end)
    assert abs(end[2] - PUCK.radius) < 2e-3, "still on its side"



def test_the_cleanup_missions_pucks_have_the_same_rolling_resistance():
    """The mission's world comes from its scenario, not from the contact harness: its pucks must be placed with
    the damping too (they were not, and a puck on its side rolled on at 0.6 mm/s for 1200 s)."""
    from teamsim.config import TrialConfig
    from teamsim.runner import World, mission_of, resolve

    mission = mission_of("hazardous-waste")
    world = World(resolve(TrialConfig(mission="hazardous-waste", params=mission.Params(), seed=0), mission), mission)
    pucks = [b for b in range(world.model.nbody) if world.model.body(b).name.startswith("puck") and
             world.model.body_jntnum[b]]  # the attachment frames, which carry the free joints
    assert len(pucks) == 10
    for body in pucks:
        dof = world.model.jnt_dofadr[world.model.body_jntadr[body]]
        assert world.model.dof_damping[dof:dof + 6] == pytest.approx([PUCK.roll_damping] * 6)

# -- box pushing (Parker §6.1) ------------------------------------------------------------------------------
def box_pose(world) -> np.ndarray:
    position, rotation = frame_of(world, mujoco.mjtObj.mjOBJ_BODY, "box0/box")
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, rotation.ravel())
    return np.array([position[0], position[1], yaw_of(quat)])


def pushing(policies: dict):
    """R-2s facing the box (its long side along y at the origin) 2 cm from it, at the given y."""
    x = -BOX.depth / 2 - R2.tip_x - 0.02
    robots = [RobotSlot(name, "r2", x, y, 0.0) for name, (y, _) in policies.items()]
    world = make_world(CustomParams(room=(6.0, 6.0), robots=robots, boxes=[(0.0, 0.0, 0.0)], box_dims=BOX),
                       {name: policy for name, (_, policy) in policies.items()}, seed=SEED)
    return world


END_Y = BOX.length / 2 - 0.15  # a robot pushing an end: its centre line 0.15 m from the end


def test_one_r2_cannot_move_the_box_by_its_middle():
    world = pushing({"red": (0.0, lambda o: (0.2, 0.0))})
    start = box_pose(world)
    run_for(world, 10.0)
    assert np.hypot(*(box_pose(world) - start)[:2]) < 0.02
    assert unstable_warnings(world) == []


def test_one_r2_turns_the_box_by_an_end():
    world = pushing({"red": (END_Y, lambda o: (0.2, 0.0))})
    start = box_pose(world)
    run_for(world, 10.0)
    assert abs(math.degrees(box_pose(world)[2] - start[2])) > 5.0


def test_two_r2s_pushing_the_ends_in_turn_advance_the_box():
    """Parker's box pushing: each robot pushes its end for 4 s while the other holds still, twice each."""
    period = 4.0

    def turn_of(k):
        return lambda o: (0.2 if int(o.time // period) % 2 == k else 0.0, 0.0)

    world = pushing({"red": (END_Y, turn_of(0)), "green": (-END_Y, turn_of(1))})
    start = box_pose(world)
    run_for(world, 4 * period)
    assert box_pose(world)[0] - start[0] > 0.1

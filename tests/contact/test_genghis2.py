"""Contact regression: Genghis-II (Parker §2.2.2) walks, turns, stands, pushes and senses through the full World.

The robot runs a tripod gait (``teamsim.controllers.skills.gait``) under a scripted (v, omega). What Parker says and
these tests hold it to: it walks (slower than an R-2's 0.457 m/s, §2.2.1), it pushes the long box more weakly
than an R-2 (§6.1.1: "cannot push the box as quickly as an R-2, due to less powerful effectors"), and its
whiskers, shoulder IR, inclinometer and belly tactile sensors read what they touch or see. Speeds, push forces
and tolerances are this model's (its assumed servos and gait), measured with fixed seeds.
"""
from __future__ import annotations

import functools
import math

import mujoco
import numpy as np
import pytest

from teamsim.faults import Fault
from teamsim.models import ROBOT_BUILDERS
from teamsim.models.arenas import Bog, Box
from teamsim.models.genghis2 import LEGS, Genghis2Dims
from tests.contact.harness import CustomParams, RobotSlot, body_pose, make_world, run_for

DIMS = Genghis2Dims()
ROOM = (4.0, 4.0)  # walls' inner faces at x, y = +-2 m
MAX_TILT = math.radians(15)


def solo(policy, x=-1.5, y=0.0, yaw=0.0, seed=0, **params):
    world = make_world(CustomParams(room=ROOM, robots=[RobotSlot("red", "genghis2", x, y, yaw)], **params),
                       {"red": policy}, seed=seed)
    return world, world.robots["red"]


def warnings(world) -> list[str]:
    return [mujoco.mjtWarning(k).name for k, n in enumerate(world.data.warning.number) if n]


def observations(world):
    return world.controllers["red"].observations


def test_standing_size_and_mass_are_parkers():
    """The compiled model measures Parker's 0.41 x 0.28 x 0.23 m standing, with 0.15 m legs, 1.5 kg."""
    world, red = solo(lambda o: (0.0, 0.0))
    m, d = world.model, world.data
    bodies = [b for b in range(m.nbody) if m.body(b).name.startswith("red/")]
    assert sum(m.body_mass[bodies]) == pytest.approx(DIMS.mass, abs=1e-9)
    assert len(red.actuators) == 12

    def geom(name):
        return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"red/{name}")

    floor = d.qpos[red.qpos_adr + 2]  # the robot frame's origin is on the floor under it
    radio, shell, whisker = geom("radio"), geom("shell"), geom("whisker_left")
    ends = d.geom_xpos[whisker] + np.outer((-1, 1), d.geom_xmat[whisker].reshape(3, 3)[:, 2] * m.geom_size[whisker, 1])
    front = ends[:, 0].max() + m.geom_size[whisker, 0]
    rear = d.geom_xpos[shell, 0] - m.geom_size[shell, 0]
    feet = np.array([d.geom_xpos[geom(f"foot_{leg}")] for leg in LEGS])
    hips = np.array([d.xpos[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"red/hip_{leg}")] for leg in LEGS])
    assert d.geom_xpos[radio, 2] + m.geom_size[radio, 1] - floor == pytest.approx(0.23, abs=1e-6)
    assert front - rear == pytest.approx(0.41, abs=1e-6)
    assert feet[:, 1].max() - feet[:, 1].min() == pytest.approx(0.28, abs=1e-6)
    assert np.linalg.norm(feet - hips, axis=1) == pytest.approx(np.full(6, 0.15), abs=1e-6)
    assert feet[:, 2] - floor == pytest.approx(np.full(6, DIMS.foot_radius), abs=1e-6), "every foot down"


def test_idle_is_stable():
    world, red = solo(lambda o: (0.0, 0.0))
    run_for(world, 0.5)  # settle onto the feet (spawned 2 mm up)
    settled = world.data.qpos[red.qpos_adr:red.qpos_adr + 3].copy()
    run_for(world, 9.5)
    drift = world.data.qpos[red.qpos_adr:red.qpos_adr + 3] - settled
    assert warnings(world) == []
    assert np.abs(drift).max() < 1e-3, f"body drifted {drift} m while standing"
    last = observations(world)[-1]
    assert max(abs(a) for a in last.inclination) < math.radians(0.5)
    assert all(force == 0.0 for force in last.touch.values()), "standing, nothing touches whiskers or belly"


def test_walks_one_metre_without_tipping():
    world, red = solo(lambda o: (DIMS.v_max, 0.0))
    start = world.pose(red)
    budget = 1.0 / DIMS.v_max * 1.25  # 15.6 s: 1 m at full speed plus a quarter for gait losses
    run_for(world, budget, until=lambda w: w.pose(red)[0] - start[0] >= 1.0)
    end = world.pose(red)
    assert end[0] - start[0] >= 1.0, f"walked only {end[0] - start[0]:.3f} m in {budget:.1f} s"
    assert 1.0 / world.time > 0.8 * DIMS.v_max, "mean speed, including the start"
    assert abs(end[1] - start[1]) < 0.05 and abs(end[2] - start[2]) < math.radians(5), "walks straight"
    tilt = max(max(abs(r), abs(p)) for r, p in (o.inclination for o in observations(world)))
    assert tilt < MAX_TILT
    assert warnings(world) == []


@pytest.mark.parametrize("direction", (1, -1), ids=("left", "right"))
def test_turns_on_the_spot(direction):
    omega, seconds = DIMS.omega_max * direction, 4.0
    world, red = solo(lambda o: (0.0, omega))
    start, turned, last = world.pose(red), 0.0, world.pose(red)[2]
    for _ in range(round(seconds / world.control_dt)):
        run_for(world, world.control_dt)
        yaw = world.pose(red)[2]
        turned += (yaw - last + math.pi) % (2 * math.pi) - math.pi
        last = yaw
    assert direction * turned > math.radians(45)
    # The commanded angle less the acceleration ramp; the gait compensates its feet's sideways slip.
    commanded = abs(omega) * seconds - omega ** 2 / (2 * DIMS.angular_accel_max)
    assert abs(turned) == pytest.approx(commanded, rel=0.08)  # measured 0.95 of it either way (2026-11-26)
    assert math.dist(world.pose(red)[:2], start[:2]) < 0.05, "turns on the spot"
    assert warnings(world) == []


@functools.cache
def steady_push(kind: str) -> tuple[float, float]:
    """(mean horizontal force on the long heavy box over the last 3 s of 8 s of full-speed pushing at its
    middle, N; how far the box moved, m). The robot starts 5 cm (plus its footprint) from the box's face."""
    half_depth = CustomParams().box_dims.depth / 2
    radius = ROBOT_BUILDERS[kind]("probe").footprint_radius
    world = make_world(CustomParams(room=ROOM, robots=[RobotSlot("red", kind, -half_depth - radius - 0.05, 0, 0)],
                                    boxes=[(0.0, 0.0, 0.0)]), {"red": lambda o: (10.0, 0.0)})
    m, d = world.model, world.data
    box = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "box0/box")
    robot_geoms = set(world.robots["red"].geoms.tolist())
    start = body_pose(world, "box0/box")
    forces, wrench = [], np.zeros(6)
    while world.time < 8.0 - 1e-9:
        run_for(world, world.control_dt)
        force = 0.0
        for i in range(d.ncon):
            g1, g2 = d.contact.geom[i]
            if {m.geom_bodyid[g1], m.geom_bodyid[g2]} & {box} and {g1, g2} & robot_geoms:
                mujoco.mj_contactForce(m, d, i, wrench)
                force += abs((d.contact.frame[i].reshape(3, 3).T @ wrench[:3])[0])  # along x, the push
        forces.append(force)
    assert warnings(world) == []
    moved = float(np.hypot(*(body_pose(world, "box0/box") - start)[:2]))
    return float(np.mean(forces[-30:])), moved


@pytest.mark.parametrize("other", ("r2", "diffdrive"))
def test_pushes_the_heavy_box_more_weakly_than(other):
    genghis, moved = steady_push("genghis2")
    assert genghis > 2.0, "it does push"
    assert moved < 0.005, "one Genghis-II cannot shift the 7.5 kg box (Parker §6.1; models/objects.BoxDims)"
    stronger, _ = steady_push(other)
    assert genghis < 0.5 * stronger, f"Genghis-II {genghis:.1f} N vs {other} {stronger:.1f} N"


def test_wades_through_a_bog_at_its_traversability():
    """Bog drag is calibrated from max_traction (teamsim.world.bog_drag): a robot at full effort should hold
    traversability x v_max there. That holds only if max_traction is what the legs really push with."""
    world, red = solo(lambda o: (DIMS.v_max, 0.0), bogs=[Bog(0.0, 0.0, 2.0, 2.0)])
    run_for(world, 3.0)
    start = world.pose(red)[0]
    run_for(world, 8.0)
    speed = (world.pose(red)[0] - start) / 8.0
    # Measured 1.08 of it (2026-11-26): the legs' mean push over a stride is a little above max_traction.
    assert speed == pytest.approx(DIMS.traversability * DIMS.v_max, rel=0.12)
    assert warnings(world) == []


def test_whiskers_feel_a_wall_and_the_belly_does_not():
    gap = 0.15  # whisker tips to the east wall
    world, red = solo(lambda o: (DIMS.v_max, 0.0), x=ROOM[0] / 2 - gap - DIMS.chassis_length / 2 - DIMS.whisker_reach)
    run_for(world, 8.0)
    obs = observations(world)
    whiskers = np.array([o.touch["whisker_left"] + o.touch["whisker_right"] for o in obs])
    times = np.array([o.time for o in obs])
    assert (whiskers[times < 1.0] == 0).all(), "nothing touched yet"
    assert whiskers[times > 5.0].mean() > 1.0 and (whiskers[times > 5.0] > 0).mean() > 0.9
    assert all(o.touch[f"belly_{p}"] == 0 for o in obs for p in ("front", "middle", "back"))
    tilt = max(max(abs(r), abs(p)) for r, p in (o.inclination for o in obs))
    assert tilt < MAX_TILT and warnings(world) == []


def test_belly_reads_only_what_it_rests_on():
    """Stand over a 5 cm block (below the belly), then break the six lift servos: the body sinks until its
    middle pad rests on the block; the front and back pads stay clear of the floor (the legs' stops)."""
    block = Box(0.0, 0.0, half_x=0.05, half_y=0.02, half_z=0.025)
    faults = [Fault("break-motor", "red", 1.0, {"motor": f"lift_{leg}"}) for leg in LEGS]
    world = make_world(CustomParams(room=ROOM, robots=[RobotSlot("red", "genghis2", 0.0, 0.0, 0.0)],
                                    obstacles=(block,)), {"red": lambda o: (0.0, 0.0)}, faults=faults)
    run_for(world, 4.0)
    obs = observations(world)
    standing = [o.touch for o in obs if o.time < 1.0]
    assert all(t[f"belly_{p}"] == 0 for t in standing for p in ("front", "middle", "back"))
    lying = obs[-1].touch
    weight = DIMS.mass * 9.81
    assert 0.5 * weight < lying["belly_middle"] < 1.2 * weight
    assert lying["belly_front"] == 0 and lying["belly_back"] == 0
    assert warnings(world) == []


def test_shoulder_ir_reads_a_wall_within_the_noise_model():
    # Front shoulder sensors (at the chassis' front corners, 30 degrees off ahead) 0.15 m from the east wall
    # along their rays; the rear pair sees nothing within its 0.3 m.
    ray = 0.15
    x = ROOM[0] / 2 - DIMS.chassis_length / 2 - ray * math.cos(math.radians(30))
    world, red = solo(lambda o: (0.0, 0.0), x=x, seed=3)
    run_for(world, 3.0)
    true = world.data.sensordata[red.ir_adr]
    assert true[:2] == pytest.approx([ray, ray], abs=0.003), "the rangefinders see the wall where it is"
    ir = red.model.ir
    expected = ir.response(np.array([ray]))[0]
    sigma = np.interp(ray, ir.distances, ir.noise_fractions) * expected
    raw = np.array([o.ir_raw for o in observations(world)[5:]])  # standing still after the first 0.5 s
    assert (np.abs(raw[:, :2] - expected) <= 4 * sigma + ir.resolution).all()
    assert abs(raw[:, :2].mean() - expected) < 3 * sigma / math.sqrt(raw[:, :2].size) + ir.resolution
    ranges = np.array([o.ir_range for o in observations(world)[5:]])
    assert np.abs(ranges[:, :2] - ray).max() < 0.03
    assert (raw[:, 2:] == 0).all() and np.isinf(ranges[:, 2:]).all(), "the rear pair sees nothing"

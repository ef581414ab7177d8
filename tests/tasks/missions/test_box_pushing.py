"""End to end: Parker's box pushing in physics (§6.1), through the real World, with fixed seeds.

What the thesis reports and these tests check: two R-2s push the ends of the long box in turn, each its own end,
and the box crosses the room square; when one R-2 is taken away the other, after a brief pause (§6.1.2: "about
5 to 8 seconds"), pushes both ends; when it is put back they share the ends again; with Genghis-II in its place
the R-2 pushes less often (Genghis-II's push is slow) and Genghis-II goes home once the R-2 is gone (Fig. 6-2).
And bad input (an unknown robot in a fault, a box that cannot advance that far, a Genghis-II asked to acquire an
end) is one line and exit status 2.

The mission's push log is what each robot believes it did; these tests also record, from the physics, where the
robot stood relative to the box when each push completed, and check the pushes were made where they are logged.

The mission runs 20-30x real time; each trial is run once (functools.cache) and read by several tests.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from itertools import pairwise

import pytest
import yaml

from teamsim.config import ConfigError, TrialConfig
from teamsim.controllers.alliance.motivation import AllianceParams
from teamsim.controllers.behaviours.box_pushing import GO_HOME, LEFT, RIGHT, BoxPushParams
from teamsim.faults import Health, apply_fault, parse_fault
from teamsim.models.objects import BoxDims
from teamsim.scenario import resolve
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.box_pushing import STAND_BACK, reach_to_walls
from teamsim.world import World

MISSION = MISSIONS["box-pushing"]
SEED = 1
PARAMS = BoxPushParams()
BOX = BoxDims()


@dataclass(frozen=True)
class Push:
    robot: str
    end: str
    activated: float
    completed: float
    along: float  # where the robot's centre was when the push completed, in the box's frame: m along the box
    behind: float  # (+: towards the left end) and m behind its centre
    heading: float  # its heading less the box's, degrees (0: square to the box, facing it)


def place(world: World, robot: str) -> tuple[float, float, float]:
    """(along, behind, heading) of ``robot`` relative to the box, from the physics (see Push)."""
    x, y, yaw = MISSION.box_pose(world)
    px, py, heading = world.pose(world.robots[robot])
    dx, dy = px - x, py - y
    return (-dx * math.sin(yaw) + dy * math.cos(yaw), -(dx * math.cos(yaw) + dy * math.sin(yaw)),
            math.degrees(math.remainder(heading - yaw, 2 * math.pi)))


@dataclass
class Trial:
    world: World
    metrics: dict
    pushes: list  # every completed Push, in order of completion
    events: list  # the world's events (behaviour changes, faults, radio)

    def of(self, robot: str, since: float = 0.0, until: float = math.inf) -> list[Push]:
        """robot's pushes activated in [since, until)."""
        return [p for p in self.pushes if p.robot == robot and since <= p.activated < until]

    def behaviour_changes(self, robot: str) -> list[tuple[float, str]]:
        return [(e["t"], e["to"]) for e in self.events if e["event"] == "behaviour" and e["robot"] == robot]


@functools.cache
def trial(seed: int, duration: float, *faults: str, advance: float | None = None) -> Trial:
    """Run for ``duration`` s; given ``advance`` (the mission's target, m), until the box has advanced that far."""
    events = []
    params = MISSION.Params() if advance is None else MISSION.Params(advance=advance)
    config = resolve(TrialConfig(mission="box-pushing", params=params, seed=seed,
                                 faults=[parse_fault(f) for f in faults]), MISSION)
    world = World(config, MISSION, events=events.append)
    seen, pushes = set(), []
    while world.time < duration - 1e-9 and not (advance is not None and MISSION.done(world)):
        world.tick()
        for brain in world.scene.info["brains"]:  # a record appears at the tick its push completes
            for record in brain.pushes:
                if id(record) not in seen:
                    seen.add(id(record))
                    pushes.append(Push(record.robot, record.end, record.activated, record.completed,
                                       *place(world, record.robot)))
        world.advance(world.steps_per_tick)
    _, metrics = MISSION.outcome(world)
    pushes.sort(key=lambda p: p.completed)
    # the outcome's log is the same pushes
    assert sorted(map(tuple, metrics["push_log"])) == sorted(
        (p.robot, p.end, round(p.activated, 2), round(p.completed, 2)) for p in pushes)
    return Trial(world, metrics, pushes, events)


def no_faults(seed: int = SEED) -> Trial:
    return trial(seed, 60.0)


TAKEOVER = ("remove:green@30", "revive:green@90")


def takeover() -> Trial:
    return trial(SEED, 200.0, *TAKEOVER)


GENGHIS = ("remove:green@40", "add-robot:genghis@40,kind=genghis2", "remove:red@160")


def genghis() -> Trial:
    return trial(SEED, 220.0, *GENGHIS)


def alternate(pushes: list[Push]) -> bool:
    """Between any two consecutive completed pushes of one end, the other end was pushed (completed in between,
    inclusive: the two robots' first pushes finish in the same tick)."""
    for end in (LEFT, RIGHT):
        times = [p.completed for p in pushes if p.end == end]
        others = [p.completed for p in pushes if p.end != end]
        if any(not any(a <= t <= b for t in others) for a, b in pairwise(times)):
            return False
    return True


def misplaced(pushes: list[Push]) -> list[Push]:
    """The pushes not made where they are logged: behind the logged end, ``end_inset`` (0.15 m) in from it, square
    to the box. Tolerances: 0.12 m along the box (the robot's centre stays on the box, whose end is 0.15 m
    further out; measured within 0.09 m in the good runs, the box turning under the pushes), from touching the
    back face to 0.1 m further back than the robot's start (it has backed off for release_time when the push is
    recorded; measured 0.30 m for an R-2, 0.37 m for Genghis-II), and 10 degrees (measured within 2)."""
    target = BOX.length / 2 - PARAMS.end_inset
    kind = {"red": "r2", "green": "r2", "genghis": "genghis2"}
    return [p for p in pushes
            if abs(p.along - (target if p.end == LEFT else -target)) > 0.12
            or not BOX.depth / 2 < p.behind < BOX.depth / 2 + STAND_BACK[kind[p.robot]] + 0.1
            or abs(p.heading) > 10.0]


# -- two R-2s ---------------------------------------------------------------------------------------------------
# Seed 0 (the CLI's default) once sat in a finished push for 27 s: a set made applicable again by news within a tick
# of its own push completing stayed active, its push done (fixed in 106c0bf).
@pytest.mark.parametrize("seed", [SEED, 0])
def test_two_r2s_push_their_own_ends_in_turn_and_the_box_advances_square(seed):
    t = no_faults(seed)
    red, green = t.of("red"), t.of("green")
    assert {p.end for p in red} == {LEFT} and {p.end for p in green} == {RIGHT}  # never the other's end
    # 60 s at about one push each per 9 s (measured 8 and 7): a robot that stopped after a few would fail.
    assert len(red) >= 5 and len(green) >= 5
    assert alternate(t.pushes), t.pushes
    # Once in step (after the start, when both ends are applicable to both), a push starts only after the
    # other end's push is complete: one at a time, ends in turn.
    settled = [p for p in t.pushes if p.activated >= 10.0]
    assert all(b.activated >= a.completed for a, b in pairwise(settled)), settled
    assert len(settled) >= 8 and all(a.end != b.end for a, b in pairwise(settled)), settled
    assert misplaced(t.pushes) == []
    # The box advances (measured 0.54 m in 60 s) and stays square (measured -1.2 degrees).
    assert t.metrics["advance_m"] > 0.1
    assert abs(t.metrics["heading_drift_deg"]) < 5.0
    assert t.metrics["pushes"] == len(red) + len(green)


# -- an R-2 taken away and put back (§6.1.2) ---------------------------------------------------------------------
@pytest.mark.parametrize("seed", [SEED, 2])
def test_the_survivor_takes_the_other_end_over_after_a_brief_pause(seed):
    """green is removed at 30 s. red's push-right activates when its motivation reaches theta: at the slow rate
    1/phi (phi = r2_patience, 30 s) while green's claim on that end stands, and at the fast rate (fast_delay) once
    the claim lapses, tau = 9 s after green's last message. That message went out in the radio period (3 s) before
    the removal, so the pause from the removal, Parker's "brief pause of about 5 to 8 seconds", lies between
    tau - 3 s and tau + fast_delay and a tick (docs/decisions.md, box pushing's "Rates"). Measured: 8.2 s at
    seed 1 (red's own last left push completed at 31.6 s, after the removal: 6.6 s from it) and 8.5 s at seed 2."""
    t = takeover() if seed == SEED else trial(seed, 64.0, "remove:green@30")
    first_right = min(p.activated for p in t.of("red") if p.end == RIGHT)
    tau = AllianceParams().tau
    assert tau - 3.0 <= first_right - 30.0 <= tau + PARAMS.fast_delay + 0.2, first_right
    if seed == SEED:
        last_left = max(p.completed for p in t.of("red", until=30.0) if p.end == LEFT)
        assert first_right - last_left == pytest.approx(6.6, abs=1.0)  # as measured
    assert not t.of("green", since=30.0, until=90.0)


def test_the_survivor_pushes_both_ends_while_alone():
    """(By its log: see the next test for where it pushed.)"""
    t = takeover()
    alone = t.of("red", since=30.0, until=90.0)  # green is away from 30 s to 90 s
    assert {p.end for p in alone} == {LEFT, RIGHT}, alone  # measured: right, left
    assert all(a.end != b.end for a, b in pairwise(alone))  # each push at the other end from the last
    # Acquiring the other end (back off, along the box, round its end) is slow, but each push is complete.
    assert all(p.completed - p.activated >= PARAMS.push_time for p in alone)


def test_the_pushes_after_a_takeover_are_made_where_they_are_logged():
    t = takeover()
    assert misplaced(t.pushes) == []


def test_a_revived_r2_comes_back_at_the_free_end_and_pushes_it():
    """green is put back at 90 s behind the end with no robot near it, with a fresh controller, and pushes that end
    (its first push: measured 90.4-93.1 s at the right end, red being at the left)."""
    t = takeover()
    back = t.of("green", since=90.0)
    assert back, "green never pushed after its revival"
    assert back[0].completed < 90.0 + 20.0
    end = t.world.scene.info["ends"]["green"]  # the end entry_pose set it down at
    assert back[0].end == end and misplaced(back[:1]) == []
    assert t.world.robots["green"].active and t.world.robots["red"].active


def test_after_a_revival_the_two_share_the_ends_again():
    """40 s after green's return, each robot pushes only one end, in turn."""
    t = takeover()
    late = [p for p in t.pushes if p.activated >= 130.0]
    red, green = [p for p in late if p.robot == "red"], [p for p in late if p.robot == "green"]
    assert len(red) >= 3 and len(green) >= 3
    assert len({p.end for p in red}) == 1 and len({p.end for p in green}) == 1
    assert {p.end for p in red} != {p.end for p in green}
    assert alternate(late)
    assert misplaced(late) == []


# -- an R-2 killed where it stands (issue 29) ---------------------------------------------------------------------
# kill, unlike remove, leaves the dead R-2 at its end, behind the box: the survivor's acquisition of that end meets
# it. The whole 3 m alone takes a lone R-2 about 1500 s (2.0 mm/s): too slow for a test, so the box need only
# advance 1 m here; green is killed at 40 s (the box about 0.4 m on).
KILL = ("kill:green@40",)
KILL_ADVANCE = 1.0


def killed() -> Trial:
    return trial(SEED, 600.0, *KILL, advance=KILL_ADVANCE)


def test_the_survivor_of_a_kill_pushes_past_the_dead_r2_and_the_box_gets_there():
    """After green is killed (its radio silent from 40 s) red takes the right end over once green's claim lapses
    (tau after its last message, 9 s) and pushes it from beside the dead R-2, where its fingertips meet it: its
    first right push is complete well within lambda (60 s), which is how long it was wedged against green before.
    It then pushes both ends in turn, and the box advances the set 1 m. Measured: the first right push activated
    at 47.2 s and complete at 61.5 s, 0.26 m right of the middle (the right pushes 0.10-0.58 m right of it, within
    4 degrees of square), 17 pushes alone, 1 m at 357.7 s."""
    t = killed()
    assert t.metrics["advance_m"] >= KILL_ADVANCE and t.world.time < 600.0
    assert not t.of("green", since=40.0)
    right = [p for p in t.of("red", since=40.0) if p.end == RIGHT]
    assert right, "red never pushed the right end"
    assert right[0].completed < 40.0 + 9.0 + PARAMS.give_up_after, right[0]
    # it took the right end: pushed it from beside green, at the right half of the box, square to it
    assert all(p.along < 0.0 and abs(p.heading) < 10.0 for p in right), right
    alone = t.of("red", since=40.0)
    assert len(alone) >= 6 and all(a.end != b.end for a, b in pairwise(alone)), alone
    # no set wedged until lambda gave it up
    gave_up = [e for e in t.events if e["event"] == "motivation" and e.get("kind") == "acquiescence"]
    assert not gave_up, gave_up


# -- Genghis-II in green's place ---------------------------------------------------------------------------------
def test_genghis_pushes_its_end_and_the_r2_pushes_less_often():
    """Green is removed and Genghis-II added at 40 s (set down at the free, right, end). Each of its pushes walks
    into the box for genghis_push_time (10 s) and backs off; red's push-left is applicable only after news of a
    newer right push, so red waits for Genghis-II's slow pushes: its interval between left pushes grows from
    about 9 s (measured 9.0 s with green, after the start) to about 12 s (measured 12.0 s)."""
    t = genghis()
    g = t.of("genghis")
    assert len(g) >= 5 and {p.end for p in g} == {RIGHT}  # measured 10
    assert all(p.completed - p.activated >= PARAMS.genghis_push_time + PARAMS.release_time - 1e-6 for p in g)
    assert t.world.scene.info["ends"]["genghis"] == RIGHT
    assert misplaced(t.of("red") + g) == []
    before = [p.activated for p in t.of("red", since=10.0, until=40.0) if p.end == LEFT]
    after = [p.activated for p in t.of("red", since=45.0, until=160.0) if p.end == LEFT]
    assert len(before) >= 3 and len(after) >= 5
    mean_before = (before[-1] - before[0]) / (len(before) - 1)
    mean_after = (after[-1] - after[0]) / (len(after) - 1)
    assert mean_after > mean_before + 2.0, (before, after)
    assert mean_after >= PARAMS.genghis_push_time
    assert not t.of("red", since=160.0)  # removed


def test_genghis_goes_home_once_the_r2_is_gone():
    """red is removed at 160 s: Genghis-II no longer hears anyone pushing the left end, finishes its push, and
    go-home (applicable while nobody is heard pushing the opposite end) walks it back from the box."""
    t = genghis()
    changes = t.behaviour_changes("genghis")
    went_home = [time for time, to in changes if to == GO_HOME]
    assert went_home and went_home[0] > 160.0  # never before red was removed (measured 169.5 s)
    assert went_home[0] < 160.0 + 30.0
    robot = t.world.robots["genghis"]
    assert robot.behaviour == GO_HOME and t.metrics["final_behaviour"]["genghis"] == GO_HOME
    assert robot.behaviour_time[GO_HOME] > 20.0  # measured 50.6 s: from about 170 s to the end
    # It walked home_distance back from where it stood to push (measured 1.72 m behind the box's centre at the
    # end, against 0.37 m while pushing).
    _, behind, _ = place(t.world, "genghis")
    assert behind > BOX.depth / 2 + STAND_BACK["genghis2"] + 0.5 * PARAMS.home_distance


@pytest.mark.parametrize("x, y, heading, margin, room, reach", [
    (0.0, 0.0, 0.0, 0.5, (4.0, 2.0), 1.5),                            # east, to 0.5 m short of the east wall
    (0.0, 0.0, math.pi, 0.5, (4.0, 2.0), 1.5),                        # west
    (0.0, 0.0, math.pi / 4, 0.0, (2.0, 2.0), math.sqrt(2)),           # diagonally into the corner
    (1.5, 0.0, 0.0, 0.5, (4.0, 2.0), 0.0),                            # already margin from the wall: no further
    (1.8, 0.0, 0.0, 0.5, (4.0, 2.0), 0.0),                            # nearer than margin: 0, not negative
    (0.0, 0.0, math.pi / 2, 1.2, (4.0, 2.0), 0.0),                    # the room narrower than twice the margin
])
def test_reach_to_walls(x, y, heading, margin, room, reach):
    assert reach_to_walls(x, y, heading, margin, room) == pytest.approx(reach)


def test_an_r2_joining_a_full_team_waits_behind_its_teammate_and_takes_the_end_once_it_is_gone():
    """An R-2 added at 20 s while red and green push is set down behind green (right end). It waits: no push and
    no claim while green works (it used to drive into its teammate's back at once and log that as a push), and
    once green is taken away at 50 s it takes the right end over after about tau, as a survivor does (measured:
    activated at 59.2 s, pushed by 65.3 s)."""
    t = trial(SEED, 70.0, "add-robot:newr2@20,kind=r2", "remove:green@50")
    assert t.world.scene.info["ends"]["newr2"] == RIGHT
    assert not t.of("newr2", until=50.0)
    assert not [e for e in t.events if e["event"] == "radio" and e["robot"] == "newr2" and 20.0 < e["t"] < 50.0
                and "push" in str(e["payload"].get("task", ""))], "it claimed an end while waiting"
    assert len(t.of("green", since=20.0, until=50.0)) >= 3  # green went on pushing its end
    first = t.of("newr2", since=50.0)
    assert first and first[0].end == RIGHT and first[0].completed < 50.0 + 25.0


def test_a_robot_joining_a_full_team_at_the_start_waits_in_the_room():
    """With the box 1 m from the west wall, "0.8 m behind its teammate" is inside the wall: Genghis-II was set down
    there and lay on its belly against it, whiskers on the floor. It waits as far back as the room allows."""
    t = trial(SEED, 5.0, "add-robot:genghis@0,kind=genghis2")
    world, model, genghis = t.world, t.world.model, t.world.robots["genghis"]
    walls = {model.geom(f"wall_{side}").id for side in ("north", "south", "east", "west")}
    touching = [{int(world.data.contact.geom1[i]), int(world.data.contact.geom2[i])} for i in range(world.data.ncon)]
    assert not [pair for pair in touching if pair & walls and pair & set(genghis.geoms.tolist())], "it touches a wall"
    # standing on its feet behind green, facing the box as green does
    x, _, heading = world.pose(genghis)
    gx, _, green_heading = world.pose(world.robots["green"])
    _, qx, qy, _ = world.data.qpos[genghis.qpos_adr + 3:genghis.qpos_adr + 7]
    assert 1 - 2 * (qx * qx + qy * qy) > 0.98 and abs(heading - green_heading) < 0.2  # upright, facing the box
    assert x < gx - (STAND_BACK["genghis2"] + STAND_BACK["r2"] - 0.02)
    assert t.world.scene.info["waiting"] == {"genghis"}


# -- the faults ---------------------------------------------------------------------------------------------------
def test_remove_and_revive_parse_and_change_health():
    remove, revive = parse_fault("remove:red@60"), parse_fault("revive:red@120")
    assert (remove.kind, remove.robot, remove.time, remove.options) == ("remove", "red", 60.0, {})
    assert (revive.kind, revive.robot, revive.time, revive.options) == ("revive", "red", 120.0, {})
    health = Health()
    apply_fault(remove, health, ("left", "right"))
    assert not health.alive and not health.radio_on and health.removed
    apply_fault(revive, health, ("left", "right"))
    assert health.alive and health.radio_on  # (the world puts it back and clears `removed`)
    with pytest.raises(ConfigError, match="unknown option 'kind' for remove"):
        parse_fault("remove:red@60,kind=r2")


# -- bad input, through the CLI -------------------------------------------------------------------------------------
def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    from teamsim.cli import main

    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_one_line_error(code: int, err: str, fragment: str) -> None:
    assert code == 2, err
    assert err.startswith("teamsim: error: ") and err.count("\n") == 1, err
    assert fragment in err, err


@pytest.mark.parametrize("argv, fragment", [
    (["--fault", "remove:purple@5"], "no robot 'purple'; team: red, green"),
    (["--fault", "revive:purple@5"], "no robot 'purple'; team: red, green"),
    (["--set", "advance=50"], "task.advance=50: the box would leave the 7.9248 x 3.6576 m room"),
    (["--set", "right=spider"], "right='spider': allowed values are r2, genghis2"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, fragment):
    code, _, err = run_cli(capsys, "run", "box-pushing", *argv, "--out", str(tmp_path))
    assert_one_line_error(code, err, fragment)
    assert not list(tmp_path.iterdir()), "nothing is written for a rejected run"


def genghis_scenario(capsys, tmp_path, acquires):
    """The mission's own scenario with Genghis-II at the right end (`teamsim scenario show --set right=genghis2`),
    its controller's `acquires` set as given, written to a file."""
    shown = tmp_path / "shown.yaml"
    code, _, err = run_cli(capsys, "scenario", "show", "box-pushing", "--set", "right=genghis2",
                           "--output", str(shown))
    assert code == 0, err
    scenario = yaml.safe_load(shown.read_text())
    assert scenario["robots"]["genghis"]["kind"] == "genghis2"
    scenario["robots"]["genghis"]["controller"]["acquires"] = acquires
    path = tmp_path / f"acquires-{acquires}.yaml"
    path.write_text(yaml.safe_dump(scenario))
    return path


def test_a_genghis_asked_to_acquire_an_end_is_rejected(capsys, tmp_path):
    path = genghis_scenario(capsys, tmp_path, True)
    out = tmp_path / "out"
    code, _, err = run_cli(capsys, "run", "box-pushing", "--scenario", str(path), "--out", str(out),
                           "--duration", "1")
    assert_one_line_error(code, err, "robots.genghis.controller.acquires=true: Genghis-II cannot acquire")
    assert not out.exists() or not list(out.iterdir())


def test_a_genghis_that_does_not_acquire_runs(capsys, tmp_path):
    """The same file with acquires: false is accepted (1 s: not enough to complete, so status 1, not 2)."""
    path = genghis_scenario(capsys, tmp_path, False)
    code, out, err = run_cli(capsys, "run", "box-pushing", "--scenario", str(path), "--out", str(tmp_path / "out"),
                             "--duration", "1")
    assert code == 1 and out.startswith("failed: "), err


def test_a_box_longer_than_the_room_is_wide_is_rejected(capsys, tmp_path):
    """The box's length lies across the room (along its own y): 4 m does not fit the 12 ft (3.66 m) room."""
    shown = tmp_path / "shown.yaml"
    assert run_cli(capsys, "scenario", "show", "box-pushing", "--output", str(shown))[0] == 0
    scenario = yaml.safe_load(shown.read_text())
    scenario["objects"]["box"]["length"] = 4.0
    path = tmp_path / "long-box.yaml"
    path.write_text(yaml.safe_dump(scenario))
    code, _, err = run_cli(capsys, "run", "box-pushing", "--scenario", str(path), "--out", str(tmp_path / "out"))
    assert_one_line_error(code, err, "objects.boxes[0]: does not fit inside the 7.9248 x 3.6576 m arena: 4 m "
                                     "across along y")
    assert not (tmp_path / "out").exists()


def test_the_rejection_says_how_far_the_box_can_go():
    config = resolve(TrialConfig(mission="box-pushing", params=MISSION.Params(), seed=SEED), MISSION)
    scenario = config.scenario
    MISSION.check_scenario(scenario)  # the default 5 m is accepted ...
    assert MISSION.room_ahead(scenario) >= scenario.task.advance  # ... so the hint must allow at least that

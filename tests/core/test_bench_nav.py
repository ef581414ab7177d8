"""``teamsim bench nav``'s whole-call replay: today's FRC and one deciding by the plain reference_decide give the
same command on every recorded call, and a controller that differs is counted as differing."""
from __future__ import annotations

import numpy as np

from teamsim.bench import nav
from teamsim.controllers.navigation.dynamic_window import Decision


def test_the_whole_call_replay_agrees_with_the_reference_on_every_call():
    rows = nav.time_decisions(density=0.10, worlds=1, duration=6.0)
    for name, row in rows.items():
        replay = row["replay"]
        assert replay["calls"] == row["calls"] > 50, name
        assert replay["same"] == replay["calls"], name
        assert replay["branches"].get("primary", 0) > 0, name


def test_the_replay_counts_a_different_command(monkeypatch):
    original = nav.with_reference_decide

    def half_speed_reference(controller):
        original(controller)
        decide = controller.window.decide

        def halved(*args, **kwargs):
            d = decide(*args, **kwargs)
            return Decision(d.v / 2, d.omega, d.branch, d.objective, d.v_min)

        controller.window.decide = halved
        return controller

    monkeypatch.setattr(nav, "with_reference_decide", half_speed_reference)
    robot = nav.ROBOTS["differential (B)"]
    world = nav.random_world(0.10, np.random.default_rng(0))
    observations = []
    controller = nav.FRC(robot.limits, robot.kind, robot.radius, world.goal)
    nav.kinematic_run(world, nav.RecordingController(controller, observations), robot, 3.0)
    replay = nav.replay_calls(robot, [(world.goal, observations)])
    assert replay["calls"] == len(observations) > 10
    assert replay["same"] < replay["calls"]

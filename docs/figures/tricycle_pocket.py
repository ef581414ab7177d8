"""docs/figures/tricycle-pocket.png: Robot A in examples/navigate-tricycle-pocket.yaml, with and without FRC's
multi-point turn (docs/navigation.md, "A tricycle in a pocket").

Needs matplotlib. Run from the repository root:
    python docs/figures/tricycle_pocket.py
"""
from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from teamsim.models import build_robot  # noqa: E402
from teamsim.runner import mission_of  # noqa: E402
from teamsim.scenario import load, read  # noqa: E402
from teamsim.tasks.missions.navigate import kinematic_robot, nav_world_of, navigation_controller  # noqa: E402
from teamsim.tasks.worlds.navigation import kinematic_run  # noqa: E402

FILE = Path("examples/navigate-tricycle-pocket.yaml")


def trace(multi_point: bool):
    """The world, and (time, x, y, heading, v, turning) of every tick."""
    world = nav_world_of(load(read(FILE), mission_of("navigate"), FILE.parent))
    model = build_robot("tricycle", "red")
    controller = navigation_controller("FRC", model, world)
    if not multi_point:  # FRC before the turn: a trapped tricycle kept the window's choice
        controller.turn = None
        controller.escape.turn_limit = 0.0
    ticks = []

    def traced(obs):
        command = controller(obs)
        ticks.append((obs.time, obs.pose.x, obs.pose.y, obs.pose.heading, command.v,
                      command.behaviour.endswith(("turn", "sweep"))))
        return command

    kinematic_run(world, traced, kinematic_robot(model), 450.0, on_contact="stop")
    return world, np.array(ticks, dtype=float)


def draw_world(axes, world) -> None:
    for box in world.boxes:
        axes.add_patch(plt.Rectangle((box.x - box.half_x, box.y - box.half_y), 2 * box.half_x, 2 * box.half_y,
                                     color="0.6"))
    axes.plot(*world.start[:2], "ko")
    axes.plot(*world.goal, "g*", ms=14)


def footprint(axes, tick, colour) -> None:
    """Robot A's enclosing circle (radius 0.5 m, centred 0.25 m ahead of the rear axle) at one tick."""
    x, y, heading = tick[1:4]
    centre = (x + 0.25 * np.cos(heading), y + 0.25 * np.sin(heading))
    axes.add_patch(plt.Circle(centre, 0.5, fill=False, color=colour, lw=1))
    axes.plot([centre[0], centre[0] + 0.5 * np.cos(heading)], [centre[1], centre[1] + 0.5 * np.sin(heading)],
              color=colour, lw=1)


def main() -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5.6))
    world, stuck = trace(multi_point=False)
    _, turned = trace(multi_point=True)
    draw_world(left, world)
    left.plot(stuck[:, 1], stuck[:, 2], color="tab:red", lw=1.2, label="no multi-point turn: stands to 450 s")
    left.plot(turned[:, 1], turned[:, 2], color="tab:blue", lw=1, label=f"FRC: arrives at {turned[-1, 0]:.0f} s")
    left.set(xlim=(-7.5, 7.5), ylim=(-7.5, 7.5), aspect="equal", title="Robot A, uniform world 20 %, seed 120006")
    left.legend(loc="upper right", fontsize=8)

    draw_world(right, world)
    right.plot(stuck[:, 1], stuck[:, 2], color="tab:red", lw=1)
    footprint(right, stuck[-1], "tab:red")
    turning = turned[:, 5] > 0
    right.plot(turned[:, 1], turned[:, 2], color="0.3", lw=0.6)
    for sign, colour, label in ((1, "tab:blue", "turning, forwards"), (-1, "tab:orange", "turning, backwards")):
        legs = turning & (np.sign(turned[:, 4]) == sign)
        right.plot(turned[legs, 1], turned[legs, 2], ".", color=colour, ms=3, label=label)
    first = int(np.argmax(turning))
    footprint(right, turned[first], "tab:blue")
    end = stuck[-1, 1:3]
    right.set(xlim=(end[0] - 2, end[0] + 2), ylim=(end[1] - 2, end[1] + 2), aspect="equal",
              title="the pocket: where it stood (red), where it began to turn (blue)")
    right.legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig("docs/figures/tricycle-pocket.png", dpi=90)


if __name__ == "__main__":
    main()

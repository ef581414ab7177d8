"""docs/figures/frc-circling.png: FRC as printed circling in examples/navigate-circling.yaml (docs/navigation.md).

Needs matplotlib (`pip install matplotlib`; not a dependency of teamsim). Run from the repository root:
    python docs/figures/circling.py
"""
from __future__ import annotations

import math
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

FILE = Path("examples/navigate-circling.yaml")


def trace(method: str):
    world = nav_world_of(load(read(FILE), mission_of("navigate"), FILE.parent))
    model = build_robot("diffdrive", "red", radius=0.35)
    controller = navigation_controller(method, model, world)
    ticks = []

    def traced(obs):
        command = controller(obs)
        ticks.append((obs.time, obs.pose.x, obs.pose.y, obs.pose.heading, controller.previous_direction,
                      math.atan2(world.goal[1] - obs.pose.y, world.goal[0] - obs.pose.x), command.omega))
        return command

    kinematic_run(world, traced, kinematic_robot(model), 450.0, on_contact="stop")
    return world, np.array(ticks, dtype=float)


def main() -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5.2), gridspec_kw={"width_ratios": [1, 1.4]})
    for method, colour in (("FRC-printed", "tab:red"), ("FRC", "tab:blue")):
        world, ticks = trace(method)
        left.plot(ticks[:, 1], ticks[:, 2], color=colour, lw=1, label=f"{method}: {ticks[-1, 0]:.0f} s")
    for box in world.boxes:
        left.add_patch(plt.Rectangle((box.x - box.half_x, box.y - box.half_y), 2 * box.half_x, 2 * box.half_y,
                                     color="0.6"))
    left.plot(*world.start[:2], "ko")
    left.plot(*world.goal, "g*", ms=14)
    left.set(xlim=(-7.5, 7.5), ylim=(-7.5, 7.5), aspect="equal", title="Robot B, uniform world 20 %, seed 20007")
    left.legend(loc="upper right")

    world, ticks = trace("FRC-printed")
    lap = (ticks[:, 0] >= 400) & (ticks[:, 0] <= 440)
    t = ticks[lap, 0]
    heading = ticks[lap, 3]
    for column, label, style in ((5, "goal", "g-"), (4, "theta_tmod, the direction sensor's choice (3.10)", "b.")):
        relative = (ticks[lap, column] - heading + math.pi) % (2 * math.pi) - math.pi
        right.plot(t, np.degrees(relative), style, ms=2, label=label)
    right.axhline(0, color="k", lw=0.5)
    twin = right.twinx()
    twin.plot(t, ticks[lap, 6], color="tab:orange", lw=1, label="omega commanded")
    twin.set_ylabel("omega, rad/s")
    right.set(xlabel="time, s", ylabel="bearing from the robot's heading, degrees (left +)",
              title="FRC as printed, 400-440 s: one lap every 16 s")
    right.legend(loc="lower left", fontsize=8)
    twin.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig("docs/figures/frc-circling.png", dpi=90)


if __name__ == "__main__":
    main()

"""Drive `navigate` through teamsim's learning interface (teamsim.env) twice on the same worlds: once with random
actions, once with teamsim's own FRC controller fed the interface's observations. Trains nothing; prints a
table of what each achieved (docs/env.md shows its output).

    $ pip install -e ".[rl]" && python examples/env_random_vs_frc.py [--seeds 0-4] [--density 0.1]
"""
from __future__ import annotations

import argparse

import numpy as np

from teamsim.env import SingleRobotEnv


def episode(env: SingleRobotEnv, seed: int, policy: str) -> dict:
    """One episode; ``policy`` is "random" (uniform actions from a seeded action space) or "FRC"."""
    env.reset(seed=seed)
    env.action_space.seed(seed)
    team, agent = env.team, env.agent
    frc = team.mission_controller(agent) if policy == "FRC" else None
    total, terminated, truncated, info = 0.0, False, False, {}
    while not (terminated or truncated):
        if frc is not None:
            action = team.command_of(agent, frc(team.last_observation(agent)))
        else:
            action = env.action_space.sample()
        _, reward, terminated, truncated, info = env.step(action)
        total += reward
    metrics = info["metrics"]
    return {"policy": policy, "seed": seed, "return": total, "completed": info["completed"],
            "time_s": info["time"], "path_m": metrics["path_length"],
            "final_distance_m": metrics["final_distance_to_goal"]}


def seeds_of(text: str) -> list[int]:
    first, _, last = text.partition("-")
    return list(range(int(first), int(last or first) + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seeds_of, default=seeds_of("0-4"), help="worlds, e.g. 0-4")
    parser.add_argument("--density", type=float, default=0.1, help="obstacle density of the worlds")
    args = parser.parse_args()
    env = SingleRobotEnv("navigate", settings=[f"density={args.density}"])
    rows = [episode(env, seed, policy) for seed in args.seeds for policy in ("random", "FRC")]
    print("| policy | seed | return | completed | time, s | path, m | final distance to goal, m |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['policy']} | {r['seed']} | {r['return']:.3f} | {r['completed']} | {r['time_s']:.1f} | "
              f"{r['path_m']:.1f} | {r['final_distance_m']:.2f} |")
    for policy in ("random", "FRC"):
        mine = [r for r in rows if r["policy"] == policy]
        print(f"\n{policy}: {sum(r['completed'] for r in mine)}/{len(mine)} completed, mean return "
              f"{np.mean([r['return'] for r in mine]):.3f}, mean final distance "
              f"{np.mean([r['final_distance_m'] for r in mine]):.2f} m")


if __name__ == "__main__":
    main()

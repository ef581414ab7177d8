"""teamsim.env (issue 30): missions as a PettingZoo ParallelEnv and a Gymnasium Env, passing those libraries' own
checkers; an agent's observations are its controller's, and teamsim's FRC driven through the interface is
bit for bit the mission's own run."""
from __future__ import annotations

import hashlib

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test

from teamsim.env import SingleRobotEnv, TeamEnv
from teamsim.runner import run_trial, trial_config


@pytest.mark.parametrize("mission", ["hazardous-waste", "navigate", "box-pushing"])
def test_missions_pass_pettingzoos_parallel_api_test(mission):
    parallel_api_test(TeamEnv(mission, duration=2.0), num_cycles=40)  # 2 s: truncated at step 20


def test_a_one_robot_mission_passes_gymnasiums_env_checker():
    check_env(SingleRobotEnv("navigate", duration=2.0), skip_render_check=True)


def test_frc_through_the_interface_is_the_missions_own_run(tmp_path):
    native = run_trial(trial_config("navigate", seed=3, duration=8.0, out=str(tmp_path)), progress=False)
    env = TeamEnv("navigate", duration=8.0)
    env.reset(seed=3)
    frc = env.mission_controller("red")
    while env.agents:
        env.step({"red": env.command_of("red", frc(env.last_observation("red")))})
    assert hashlib.sha256(env.state().tobytes()).hexdigest() == native.summary["final_state_sha256"]


def test_observations_are_the_controllers_readings():
    env = TeamEnv("hazardous-waste", duration=5.0)
    observations, _ = env.reset(seed=1)
    for _ in range(8):  # past the first positioning fix (0.6 s)
        observations, *_ = env.step({a: np.zeros(4) for a in env.agents})
    names = env.observation_names("red")
    vector, reading = observations["red"], env.last_observation("red")
    assert len(names) == len(vector) == env.observation_space("red").shape[0]
    ir = [k for k, n in enumerate(names) if n.startswith("ir_range/")]
    np.testing.assert_allclose(vector[ir], np.minimum(reading.ir_range, env.world.robots["red"].model.ir.max_range),
                               rtol=1e-6)
    pose = [names.index(f"pose/{n}") for n in ("has_fix", "x", "y", "heading")]
    np.testing.assert_allclose(vector[pose], [1.0, reading.pose.x, reading.pose.y, reading.pose.heading], rtol=1e-6)
    assert {"effectors/grip", "effectors/lift"} <= set(names)


def test_same_seed_same_episode_and_another_seed_another():
    env = TeamEnv("navigate", duration=1.0)
    first = env.reset(seed=5)[0]["red"]
    again = env.reset(seed=5)[0]["red"]
    other = env.reset(seed=6)[0]["red"]
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)


def test_an_r2s_gripper_follows_its_action():
    env = TeamEnv("hazardous-waste", duration=5.0)
    env.reset(seed=2)
    grip = env.observation_names("red").index("effectors/grip")
    for _ in range(15):
        observations, *_ = env.step({"red": np.array([0.0, 0.0, 1.0, 0.0]), "blue": np.zeros(4),
                                     "green": np.zeros(4)})
    opened = observations["red"][grip]
    for _ in range(15):
        observations, *_ = env.step({"red": np.array([0.0, 0.0, 0.0, 0.0]), "blue": np.zeros(4),
                                     "green": np.zeros(4)})
    assert opened > 0.8 and observations["red"][grip] < 0.2


def test_a_killed_robot_terminates_alone_and_the_others_go_on():
    env = TeamEnv("hazardous-waste", duration=3.0, faults=["kill:red@1"])
    env.reset(seed=0)
    terminated = {}
    while "red" in env.agents:
        _, _, terminated, truncated, _ = env.step({a: np.zeros(4) for a in env.agents})
    assert terminated == {"red": True, "blue": False, "green": False}
    assert env.agents == ["blue", "green"] and env.world.time == pytest.approx(1.0)  # dead from its fault's tick


def test_robots_that_are_not_agents_keep_their_mission_controllers():
    env = TeamEnv("hazardous-waste", duration=30.0, agents=["blue", "green"])
    env.reset(seed=0)
    assert env.agents == ["blue", "green"]
    for _ in range(30):  # red's ALLIANCE activates find-locations at 2.1 s
        env.step({"blue": np.zeros(4), "green": np.zeros(4)})
    behaviours = {name: robot.behaviour for name, robot in env.world.robots.items()}
    assert behaviours == {"red": "find-locations-methodical", "blue": "agent", "green": "agent"}  # red's ALLIANCE


def test_navigate_rewards_sum_to_the_progress_made():
    env = TeamEnv("navigate", duration=20.0)
    env.reset(seed=3)
    frc, total = env.mission_controller("red"), 0.0
    while env.agents:
        _, rewards, *_ = env.step({"red": env.command_of("red", frc(env.last_observation("red")))})
        total += rewards["red"]
    assert total == pytest.approx(env.mission.progress(env.world)) and total > 0.2


def test_bad_input_is_a_value_error_naming_the_field():
    with pytest.raises(ValueError, match="^mission: unknown mission 'nope'"):
        TeamEnv("nope")
    with pytest.raises(ValueError, match="^agents: no robot 'x'"):
        TeamEnv("navigate", agents=["x"])
    with pytest.raises(ValueError, match="density"):
        TeamEnv("navigate", settings=["density=7"])
    with pytest.raises(ValueError, match="^mission: hazardous-waste has 3 robots"):
        SingleRobotEnv("hazardous-waste")
    env = TeamEnv("navigate", duration=1.0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^actions\['red'\]: expected 2 finite numbers"):
        env.step({"red": np.array([np.nan, 0.0])})

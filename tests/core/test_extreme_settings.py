"""Extreme but valid settings (issue 29, part 6): a crowd of robots in a small room, the coarsest physics step, the
smallest rooms, the largest teams, the fastest radio and positioning. Each short run ends as a trial (completed,
failed or unstable, never ``error``) with every output written, or is refused before it starts with one line,
``teamsim: error: ...``, exit 2; never a traceback. The runs are real (nothing stubbed) and a few simulated seconds
each."""
from __future__ import annotations

import json

import numpy as np
import pytest

from teamsim.cli import main
from teamsim.config import ConfigError, PositioningConfig
from teamsim.positioning import PositioningService
from teamsim.tasks import MISSIONS
from teamsim.tasks.worlds.exploration import ExploreWorldParams, explore_world
from teamsim.tasks.worlds.navigation import NavWorldParams, random_world

SECONDS = "2"


def run(tmp_path, capfd, *argv: str) -> tuple[int, str, dict | None]:
    """``teamsim run ...`` in-process for SECONDS: (exit code, stderr, its summary or None)."""
    code = main(["run", *argv, "--duration", SECONDS, "--out", str(tmp_path), "--run-id", "x"])
    err = capfd.readouterr().err
    summary = tmp_path / argv[0] / "x" / "summary.json"
    return code, err, json.loads(summary.read_text()) if summary.exists() else None


def ends_as_a_trial(code: int, err: str, summary: dict | None) -> None:
    """Exit 0 (completed) or 1 (failed, unstable) with a finished summary and every output: never ``error``."""
    assert "Traceback" not in err
    assert summary is not None, err
    assert summary["status"] in ("completed", "failed", "unstable"), (summary["status"], summary.get("error"))
    assert code == (0 if summary["status"] == "completed" else 1), err
    assert summary["sim_time_s"] > 0 and {"events.jsonl", "trajectory.npz", "timeline.png"} <= set(summary["outputs"])


def refused_in_one_line(code: int, err: str, summary: dict | None, fragment: str) -> None:
    assert (code, summary) == (2, None), err
    assert err.startswith("teamsim: error: ") and err.count("\n") == 1 and fragment in err, err


@pytest.mark.parametrize("mission", MISSIONS)
def test_the_coarsest_physics_step_runs_every_mission(tmp_path, capfd, mission):
    """``timing.physics_dt=0.02``, the largest allowed, with a control period shorter than it (rounded up to one
    physics step): the mission runs, or its physics is reported unstable."""
    coarse = ["--set", "timing.physics_dt=0.02", "--set", "timing.control_dt=0.01"]
    ends_as_a_trial(*run(tmp_path, capfd, mission, *coarse))


@pytest.mark.parametrize("argv", [
    ["wander", "--set", "robots=30", "--set", "room_size=10", "--set", "obstacles=0", "--set", "kind=tricycle"],
    ["wander", "--set", "robots=30", "--set", "room_size=10", "--set", "obstacles=0", "--set", "kind=r2",
     "--set", "timing.physics_dt=0.02"],
    ["hazardous-waste", "--set", "robots=3", "--set", "pucks=30", "--set", "spill_size=0.5", "--set",
     "report_interval=1"],
    ["formation", "--set", "robots=14", "--set", "crossing=4", "--set", "spacing=0.6", "--set", "turns=8"],
    ["bounding-overwatch", "--set", "per_kind=6", "--set", "lane=1", "--set", "bound=1"],
    ["janitorial", "--set", "size_x=3,3", "--set", "size_y=3,3", "--set", "cans=0", "--set", "objects=0",
     "--set", "obstacles=0"],
    ["box-pushing", "--set", "right=genghis2", "--set", "advance=0.1"],
    ["wander", "--set", "positioning.period=1e-9", "--set", "radio.rate_hz=100", "--set", "radio.latency=60",
     "--set", "radio.loss=1", "--set", "positioning.noise_moving=10", "--set", "timing.control_dt=1"],
], ids=["30-tricycles-10m", "30-r2s-coarse-step", "cleanup-3-robots-30-pucks", "formation-14-crossing-4",
        "overwatch-12-robots", "janitorial-3m-room", "box-genghis-short", "radio-and-positioning-at-their-bounds"])
def test_extreme_valid_settings_run(tmp_path, capfd, argv):
    ends_as_a_trial(*run(tmp_path, capfd, *argv))


@pytest.mark.parametrize("argv, fragment", [
    (["wander", "--set", "robots=30", "--set", "room_size=4"], "a 4 m room has room for 4 robots and obstacles"),
    (["hazardous-waste", "--set", "robots=3", "--set", "arena.size=[3,2]"], "inside the 3 x 2 m arena"),
    (["hazardous-waste", "--set", "pucks=30", "--set", "spill_size=0.1"], "pucks=30: that many pucks"),
    (["janitorial", "--set", "size_x=3,3", "--set", "size_y=3,3", "--set", "cans=12"], "cans=12"),
    (["wander", "--set", "robots.red.pose=[0.2,0,0]", "--set", "robots.green.pose=[0,0,0]"], "overlaps"),
], ids=["30-robots-4m", "cleanup-3x2m-room", "30-pucks-10cm-spill", "12-cans-3m-room", "two-robots-one-spot"])
def test_settings_past_what_fits_are_refused_in_one_line(tmp_path, capfd, argv, fragment):
    refused_in_one_line(*run(tmp_path, capfd, *argv), fragment)


class CountedPeriod(float):
    """A positioning period that counts how often it is added to a time (and gives up past a thousand)."""
    additions = 0

    def __radd__(self, other):
        CountedPeriod.additions += 1
        assert CountedPeriod.additions < 1000, "the positioning service counts its periods one by one"
        return float(other) + float(self)


def test_a_tiny_positioning_period_is_skipped_over_not_counted():
    """``positioning.period=1e-9`` (allowed: > 0): an update far past the last one moves the next update time past
    now in a few steps (counting 1e-9 s periods one at a time took a minute per simulated second)."""
    service = PositioningService(PositioningConfig(period=CountedPeriod(1e-9)), {"red": np.random.default_rng(0)})
    for now in (0.0, 0.1, 0.2, 1e6):
        assert service.update(now, {"red": [0.0, 0.0, 0.0]}, {"red": 0.0})
        assert now < service._next_update <= now + 2e-9
    assert CountedPeriod.additions < 10


def test_worlds_out_of_reach_are_a_config_error_naming_the_setting():
    """A navigation world whose density no layout reaches (every ``teamsim run navigate --set density=0.3`` draws 200
    layouts, then gave up with a RuntimeError and a traceback) and an exploration world whose bogs never cover their
    share: each is one ConfigError naming the setting and what to do."""
    with pytest.raises(ConfigError, match=r"^density=0.6: no world of 60% obstacle density .*; allowed: a lower "):
        random_world(0.6, np.random.default_rng(0), NavWorldParams(layouts=3))
    with pytest.raises(ConfigError, match=r"^explore: bog_share=0.3: could not reach 30% boggy ground in 2 patches"):
        explore_world(ExploreWorldParams(bog_share=0.3, bog_attempts=2), np.random.default_rng(0))

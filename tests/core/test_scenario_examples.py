"""The ready scenario files under examples/: one per mission that supports scenarios, and a navigation world per
density of Chand's §3.6.2. Each loads and runs."""
from __future__ import annotations

from pathlib import Path

import pytest

from teamsim.cli import main
from teamsim.runner import mission_of
from teamsim.scenario import load, read, supports
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.navigate import nav_world_of
from teamsim.tasks.worlds.navigation import DENSITIES

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FILES = sorted(EXAMPLES.glob("*.yaml"))


def test_one_per_mission_and_one_per_density():
    names = {f.stem for f in FILES}
    assert {name for name, mission in MISSIONS.items() if supports(mission)} <= names
    assert {f"navigate-density-{round(d * 100):02d}" for d in DENSITIES} <= names


@pytest.mark.parametrize("file", FILES, ids=[f.stem for f in FILES])
def test_example_runs(capsys, tmp_path, file):
    mission = read(file)["mission"]
    code = main(["run", mission, "--scenario", str(file), "--duration", "0.5", "--out", str(tmp_path)])
    assert code in (0, 1), capsys.readouterr().err  # (1: navigate has not arrived, nor the cleanup finished)


@pytest.mark.parametrize("density", DENSITIES)
def test_density_worlds_have_their_density(density):
    file = EXAMPLES / f"navigate-density-{round(density * 100):02d}.yaml"
    world = nav_world_of(load(read(file), mission_of("navigate"), file.parent))
    assert world.density == pytest.approx(density, abs=0.01)

"""``teamsim allocate``: the thesis's example by default, files, --json, --explain, and bad files (exit 2)."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from teamsim.cli import main
from teamsim.controllers.allocation.fuzzy_capability import data_file


def run_cli(capsys, *argv):
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture
def thesis_files(tmp_path):
    tasks, robots = tmp_path / "tasks.toml", tmp_path / "robots.toml"
    tasks.write_text(data_file("thesis_tasks.toml").read_text())
    robots.write_text(data_file("thesis_robots.toml").read_text())
    return tasks, robots


def test_default_is_the_thesis_example(capsys):
    code, out, err = run_cli(capsys, "allocate")
    assert code == 0 and not err
    assert "  Robot4  mc     0.870 (0.87)" in out  # capability scores beside the published ones
    assert "Robot3 proc: 0.345, thesis 0.45: known gap:" in out  # a miss named with its cause
    assert "M1   Robot3 (manager)" in out and "M2   Robot1 (manager)" in out
    assert "W1   Robot4 (1.000)" in out
    assert "W2   Robot4 (1.000), Robot2 (" in out and "Robot5 (" in out and "Robot7 (" in out
    rtcm = out[out.index("robot-task capability matrix"):out.index("allocation (")]
    w2 = rtcm[rtcm.index("W2 explorer"):]
    assert [line.split()[1] for line in w2.splitlines()[2:7]] == ["Robot4", "Robot2", "Robot5", "Robot7", "Robot6"]


def test_json_has_the_same_data(capsys):
    code, out, _ = run_cli(capsys, "allocate", "--json")
    data = json.loads(out)
    assert code == 0
    assert data["managers"] == {"M1": "Robot3", "M2": "Robot1"}
    assert data["workers"] == {"W1": ["Robot4"], "W2": ["Robot4", "Robot2", "Robot5", "Robot7"]}
    assert [c["robot"] for c in data["rtcm"]["W1"]] == ["Robot4", "Robot2", "Robot5", "Robot7"]
    robot3 = next(row for row in data["scores"] if row["robot"] == "Robot3")
    assert [m["resource"] for m in robot3["misses"]] == ["proc"] and robot3["misses"][0]["thesis"] == 0.45
    assert data["ru"]["Robot4"]["W2"]["sense"] == [10, 10]
    assert "explain" not in data


def test_explain_shows_inputs_fired_rules_and_outputs(capsys):
    code, out, _ = run_cli(capsys, "allocate", "--explain")
    assert code == 0
    assert "communication: bandwidth_mbit_s=54 range_m=100 -> score=0.8700" in out
    assert "rule  3 1.000  if bandwidth_mbit_s is high then score is high (w 1)" in out
    assert "task_value: vots_proc=" in out and "(w vsw_sense)" in out
    code, out, _ = run_cli(capsys, "allocate", "--json", "--explain")
    explain = json.loads(out)["explain"]
    names = [t["name"] for t in explain["robots"]["Robot1"]]
    assert names == ["processing_pc", "communication", "sensor_score", "obstacle_avoidance", "mapping_exploration",
                     "sensing", "base_performance", "base_size", "actuation"]
    assert set(explain["task_value"]["W2"]) == {"Robot4", "Robot2", "Robot5", "Robot7", "Robot6"}
    assert set(explain["task_value"]["M1"]) == {"Robot1", "Robot3"}
    assert set(explain["task_value"]["M2"]) == {"Robot1"}  # Robot3 scores 0.34 on processing here (0.45 printed)


def test_files_give_the_same_result(capsys, thesis_files):
    code, out, _ = run_cli(capsys, "allocate", *map(str, thesis_files), "--json")
    assert code == 0 and json.loads(out)["managers"] == {"M1": "Robot3", "M2": "Robot1"}


@pytest.mark.parametrize("which, old, new, fragment", [
    (0, 'sensing = "medium"\n', "", "tasks.W2.sensing: missing"),
    (0, 'communication = "high"', 'communication = "very high"', "tasks.M2.communication: unknown grade 'very high'"),
    (0, "vsw = [0.05, 0.05, 0.45, 0.45]", "vsw = [0.05, 0.05, 0.45, 0.40]", "tasks.W2.vsw: weights must sum to 1"),
    (1, "actuation = [0.95, 0.60, 0.40, 1]\n", "", "robots.Robot8.actuation: missing"),
])
def test_bad_files_exit_2_with_one_line_naming_the_field(capsys, thesis_files, which, old, new, fragment):
    path = thesis_files[which]
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    code, out, err = run_cli(capsys, "allocate", *map(str, thesis_files))
    assert code == 2 and not out
    assert err.startswith(f"teamsim: error: {path}: ") and err.count("\n") == 1 and fragment in err


def test_one_file_alone_is_a_usage_error(capsys, thesis_files):
    code, _, err = run_cli(capsys, "allocate", str(thesis_files[0]))
    assert code == 2 and "give both TASKS and ROBOTS files, or neither" in err


def test_console_script(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "teamsim.cli", "allocate", "--json"], capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 0 and json.loads(proc.stdout)["workers"]["W1"] == ["Robot4"]

"""Task and robot specification files (teamsim.controllers.allocation.spec): the shipped thesis example and
one-line rejections of bad files naming the field."""
from __future__ import annotations

from pathlib import Path

import pytest

from teamsim.config import ConfigError
from teamsim.controllers.allocation.fuzzy_capability import data_file
from teamsim.controllers.allocation.spec import load_robots, load_tasks

MINIMAL_TASKS = """
[tasks.T1]
role = "worker"
processing = ["mc", "low"]
communication = "low"
sensing = "medium"
actuation = "medium"
"""

MINIMAL_ROBOTS = """
[robots.A]
processing = [6, 4, "mc"]
communication = [11, 100]
sensing = [10, 1.5, 360]
actuation = [1.25, 0.4, 0.5, 0.1]
"""


def write(tmp_path: Path, text: str, name: str = "spec.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_thesis_tasks_tables_5_20_5_21_and_5_29():
    tasks = {t.id: t for t in load_tasks()}
    assert list(tasks) == ["M1", "M2", "W1", "W2"]
    assert tasks["M2"].proc_class == "pc" and tasks["M2"].requirement == (0.35, 0.65, 0.0, 0.35)
    assert tasks["W1"].requirement == (0.35, 0.35, 0.0, 0.0) and tasks["W1"].vsw == (0.4, 0.4, 0.1, 0.1)
    # Robot quantity criteria [1600, medium] through the FIS, minimum 1, maximum the largest initial (§5.4)
    assert tasks["W1"].quantity == (1, 1, 4) and tasks["W2"].quantity == (4, 1, 4)
    assert tasks["W1"].concurrent == {"W2"} and tasks["W2"].concurrent == {"W1"}
    assert tasks["W2"].ru_on["sense"] == (10, 10) and tasks["W2"].ru_off["sense"] == (0, 0)
    feedback = tasks["W2"].feedback
    assert feedback.ws == (0.1, 0.05, 0.45, 0.4) and feedback.wl == (0, 0, 0.5, 0.5)
    assert (feedback.tes_threshold, feedback.otes_threshold) == (0.12, 0.65)
    assert feedback.ka == {"plan": "max", "comm": (1.0,), "sense": (0.5, 0.5), "act": (1.0,)}
    assert tasks["W1"].feedback.tes_threshold == -1


def test_thesis_robots_table_5_22():
    robots = load_robots()
    assert [r.id for r in robots] == [f"Robot{k}" for k in range(1, 9)]
    robot4 = robots[3]
    assert (robot4.proc_class, robot4.benchmark, robot4.memory) == ("mc", 10, 16)
    assert (robot4.ir_quantity, robot4.operation_h, robot4.radius, robot4.traversability) == (14, 2.53, 0.6, 1)
    assert robot4.published == {"proc": 0.87, "comm": 0.62, "sense": 0.55, "act": 0.67}


def test_thesis_files_are_package_data():
    assert data_file("thesis_tasks.toml").is_file() and data_file("thesis_robots.toml").is_file()
    assert data_file("fis.toml").is_file()


def test_defaults_fill_a_basic_users_task(tmp_path):
    (task,) = load_tasks(write(tmp_path, MINIMAL_TASKS))
    assert task.name == "T1" and task.kind == "continuous" and task.size == "any"
    assert task.vsw == (0.25, 0.25, 0.25, 0.25) and task.quantity == (1, 1, 1)
    assert task.initial_ru == "on" and task.feedback is None and not task.concurrent


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('sensing = "medium"\n', ""),
     "spec.toml: tasks.T1.sensing: missing; expected low, medium or high"),
    (lambda t: t.replace('sensing = "medium"', 'sensing = "moderate"'),
     "spec.toml: tasks.T1.sensing: unknown grade 'moderate'; allowed: low, medium, high"),
    (lambda t: t + "vsw = [0.5, 0.3, 0.1, 0.0]\n",
     "spec.toml: tasks.T1.vsw: weights must sum to 1 (sum 0.9)"),
    (lambda t: t + "vsw = [0.5, 0.5]\n", "spec.toml: tasks.T1.vsw: expected a list of 4 numbers"),
    (lambda t: t.replace('["mc", "low"]', '["gpu", "low"]'),
     "spec.toml: tasks.T1.processing[0]: unknown processor class 'gpu'; allowed: mc, pc"),
    (lambda t: t.replace('actuation = "medium"', 'actuation = ["medium", "huge"]'),
     "spec.toml: tasks.T1.actuation[1]: unknown size 'huge'; allowed: any, small, medium, large"),
    (lambda t: t.replace('role = "worker"', 'role = "boss"'),
     "spec.toml: tasks.T1.role: unknown role 'boss'; allowed: manager, worker"),
    (lambda t: t + "speed = 3\n", "spec.toml: tasks.T1.speed: unknown field; allowed:"),
    (lambda t: t + 'concurrent = ["T9"]\n', "spec.toml: tasks.T1.concurrent: unknown task 'T9'"),
    (lambda t: t + "quantity = [1, 2, 4]\n", "spec.toml: tasks.T1.quantity: expected [initial, minimum, maximum] "
                                             "with minimum <= initial <= maximum"),
    (lambda t: t + "quantity = 2\nquantity_criteria = { area = 1600, ratio = 'medium', output = 'planners' }\n",
     "tasks.T1.quantity_criteria: give quantity or quantity_criteria, not both"),
    (lambda t: t + "quantity_criteria = { area = 1600, ratio = 'medium', output = 'pilots' }\n",
     "tasks.T1.quantity_criteria.output: unknown 'pilots'; allowed: explorers, planners"),
    (lambda t: t + "[tasks.T1.feedback]\nws = [0.5, 0.5, 0, 0]\nwl = [0, 0, 0.5, 0.5]\ntes_threshold = 0.1\n"
                   "otes_threshold = 0.5\nachievement = { plan = ['a', 'b'], comm = ['bytes'] }\n",
     "tasks.T1.feedback.ka.plan: missing; 2 sub-categories need weights or 'max'"),
    (lambda t: t + "[tasks.T1.feedback]\nws = [0.5, 0.5, 0, 0]\nwl = [0, 0, 0.6, 0.5]\ntes_threshold = 0.1\n"
                   "otes_threshold = 0.5\nachievement = { plan = ['a'], comm = ['bytes'] }\n",
     "tasks.T1.feedback.wl: weights must sum to 1 (sum 1.1)"),
    (lambda t: "tasks = 3\n", "spec.toml: tasks: missing; expected one [tasks.ID] table per task"),
    (lambda t: t + "[robots.A]\n", "spec.toml: robots: unknown top-level table"),
    (lambda t: t + "oops = = 1\n", "spec.toml: not valid TOML"),
])
def test_bad_task_files_are_rejected_naming_the_field(tmp_path, edit, message):
    with pytest.raises(ConfigError) as caught:
        load_tasks(write(tmp_path, edit(MINIMAL_TASKS)))
    text = str(caught.value)
    assert "\n" not in text and text.startswith(f"{tmp_path / 'spec.toml'}: ")
    assert message in text


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('communication = [11, 100]\n', ""),
     "robots.A.communication: missing; expected [Mbit/s, range m]"),
    (lambda t: t.replace('[6, 4, "mc"]', '[6, 4, "fpga"]'),
     "robots.A.processing[2]: unknown processor class 'fpga'; allowed: mc, pc"),
    (lambda t: t.replace("[1.25, 0.4, 0.5, 0.1]", "[1.25, 0.4, 0.5, 3]"),
     "robots.A.actuation[3]: traversability must be in [0, 1], got 3"),
    (lambda t: t.replace("[10, 1.5, 360]", "[10, 1.5]"), "robots.A.sensing: expected a list of 3 numbers"),
    (lambda t: t.replace("[11, 100]", "[11, -5]"), "robots.A.communication[1]: expected a number in [0, inf]"),
    (lambda t: t + "published = { proc = 'high' }\n", "robots.A.published.proc: expected a number"),
])
def test_bad_robot_files_are_rejected_naming_the_field(tmp_path, edit, message):
    with pytest.raises(ConfigError) as caught:
        load_robots(write(tmp_path, edit(MINIMAL_ROBOTS)))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="nosuch.toml: no such file"):
        load_robots(tmp_path / "nosuch.toml")

"""The dependency rule of docs/architecture.md, read from the imports of every product module.

models <- controllers <- tasks <- core runtime <- studies <- CLI and benchmarks, with the core's foundation
(settings, random streams, files, radio, positioning, faults: nothing that knows a robot) below them all but
models, and the world description (``teamsim.scene``, ``teamsim.scenario``) between models and tasks. A module may
import its own layer and the layers its row allows, and nothing above; imports inside functions count too.
"""
from __future__ import annotations

import ast
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# Where each installed package lives in the tree (pyproject.toml's [tool.setuptools.package-dir]).
PACKAGE_DIRS = {"teamsim": "teamsim", "teamsim.models": "models", "teamsim.controllers": "controllers",
                "teamsim.tasks": "tasks"}

FOUNDATION = ("teamsim", "teamsim.config", "teamsim.rng", "teamsim.files", "teamsim.gl", "teamsim.progress",
              "teamsim.stats", "teamsim.plots", "teamsim.positioning", "teamsim.radio", "teamsim.network",
              "teamsim.faults")
RUNTIME = ("teamsim.world", "teamsim.runner", "teamsim.recording", "teamsim.timeline", "teamsim.video",
           "teamsim.rerender", "teamsim.sweep", "teamsim.viewer", "teamsim.env")
LAYER_OF = {  # module or package (its modules too; "teamsim" alone) -> layer; the longest prefix wins
    **{name: "foundation" for name in FOUNDATION},
    "teamsim.models": "models",
    "teamsim.scene": "world description", "teamsim.scenario": "world description",
    "teamsim.controllers": "controllers",
    "teamsim.tasks": "tasks",
    **{name: "runtime" for name in RUNTIME},
    "teamsim.tasks.studies": "studies",
    "teamsim.cli": "cli", "teamsim.bench": "cli",
}
MAY_IMPORT = {  # layer -> the other layers it may import
    "foundation": set(),
    "models": set(),  # models import nothing else of teamsim's (DESIGN.md)
    "world description": {"foundation", "models"},
    "controllers": {"foundation", "models"},
    "tasks": {"foundation", "models", "world description", "controllers"},
    "runtime": {"foundation", "models", "world description", "controllers", "tasks"},
    "studies": {"foundation", "models", "world description", "controllers", "tasks", "runtime"},
    "cli": {"foundation", "models", "world description", "controllers", "tasks", "runtime", "studies"},
}


def modules(package_dirs: dict[str, Path]) -> dict[str, Path]:
    """Every module of the product: dotted name -> file."""
    found = {}
    for package, folder in package_dirs.items():
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            found[".".join((package, *parts))] = path
    return found


def layer_of(name: str) -> str | None:
    matches = [prefix for prefix in LAYER_OF if name == prefix or prefix != "teamsim" and name.startswith(prefix + ".")]
    return LAYER_OF[max(matches, key=len)] if matches else None


def imported(path: Path, known: set[str]) -> set[str]:
    """The teamsim modules a file imports anywhere in it (``from a import b`` is ``a.b`` when that is a module)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.update(f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in known else node.module
                         for a in node.names)
    return {name for name in names if name == "teamsim" or name.startswith("teamsim.")}


def violations(package_dirs: dict[str, Path]) -> list[str]:
    """Every import that breaks the rule, and every module no layer claims, one line each."""
    found = modules(package_dirs)
    problems = [f"{name}: in no layer (add it to LAYER_OF)" for name in found if layer_of(name) is None]
    for name, path in found.items():
        mine = layer_of(name)
        for target in sorted(imported(path, set(found))):
            theirs = layer_of(target)
            if mine and theirs and theirs != mine and theirs not in MAY_IMPORT[mine]:
                problems.append(f"{name} ({mine}) imports {target} ({theirs})")
    return problems


def test_no_module_imports_upwards():
    assert violations({p: ROOT / d for p, d in PACKAGE_DIRS.items()}) == []


def _tree(tmp_path: Path, files: dict[str, str]) -> dict[str, Path]:
    for relative, text in files.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    return {p: tmp_path / d for p, d in PACKAGE_DIRS.items()}


def test_an_upward_import_is_caught(tmp_path):
    dirs = _tree(tmp_path, {
        "teamsim/__init__.py": "", "teamsim/config.py": "", "teamsim/runner.py": "import teamsim.tasks\n",
        "models/__init__.py": "", "models/robot.py": "from teamsim.config import ConfigError\n",
        "controllers/__init__.py": "",
        "controllers/navigation/__init__.py": "",
        "controllers/navigation/astar.py": "def plan():\n    from teamsim.tasks.missions import navigate\n",
        "tasks/__init__.py": "", "tasks/missions/__init__.py": "", "tasks/missions/navigate.py": "",
    })
    assert violations(dirs) == [
        "teamsim.models.robot (models) imports teamsim.config (foundation)",
        "teamsim.controllers.navigation.astar (controllers) imports teamsim.tasks.missions.navigate (tasks)",
    ]


def test_a_module_outside_every_layer_is_reported(tmp_path):
    dirs = _tree(tmp_path, {"teamsim/__init__.py": "", "teamsim/newthing.py": "", "models/__init__.py": "",
                            "controllers/__init__.py": "", "tasks/__init__.py": ""})
    assert violations(dirs) == ["teamsim.newthing: in no layer (add it to LAYER_OF)"]


def test_every_package_is_installed():
    """``pip install .`` installs only the packages pyproject.toml lists: a new folder must be added there."""
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    on_disk = {name for name, path in modules({p: ROOT / d for p, d in PACKAGE_DIRS.items()}).items()
               if path.name == "__init__.py"}
    assert on_disk == listed
    # A folder of modules without __init__.py would import in an editable install and be dropped by ``pip install .``
    folders = {path.parent for path in modules({p: ROOT / d for p, d in PACKAGE_DIRS.items()}).values()}
    assert not [str(f.relative_to(ROOT)) for f in folders if not (f / "__init__.py").exists()]

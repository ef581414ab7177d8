"""Fuzzing the command line (issue 29, part 6): mutated argument vectors for every subcommand end with exit 0, or
with exit 2 and exactly one line ``teamsim: error: ...`` on stderr; never a traceback.

The vectors are valid command lines mutated by a seeded ``random.Random``: unknown flags, wrong types, huge and
negative numbers, NaN and inf, empty strings, unicode, line breaks, every mission parameter at and past its bounds,
malformed ``--set`` (no ``=``, unknown keys, bad values, dotted paths into the scenario such as
``robots.red.pose=[1,2`` or ``arena.boxes[99].x=1``) and malformed ``--fault``. Argument parsing and configuration
building (the scenario a mission generates, its checks) run for real; what would then take minutes is a stub that
takes the built configuration and returns at once: ``run_trial``, the studies' ``run_study``, the benchmarks, the
renderer and the viewer's window. A stub checks what it is given (a study's trial configurations validate, a
benchmark's seconds are a positive number), so a bad value that slips past parsing fails the test instead of
running. stderr is caught at the file descriptor (``capfd``), so a native library's own message counts as a line.
"""
from __future__ import annotations

import dataclasses
import functools
import importlib
import json
import math
import pkgutil
import random
import shutil
import socket
from pathlib import Path

import pytest
import yaml

from teamsim.cli.main import _build_parser, main
from teamsim.config import ConfigError, validate
from teamsim.controllers.allocation.fuzzy_capability import data_file
from teamsim.faults import FAULT_KINDS
from teamsim.runner import TrialResult, mission_of, trial_config
from teamsim.scenario import resolve, scenario_of, to_data
from teamsim.tasks import MISSIONS

SEED = 29
CASES = 1200
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

# Values put where a value belongs, or anywhere: numbers of every odd kind, YAML and flag look-alikes, unicode,
# line breaks. (No NUL: a command line cannot hold one.)
ODD_VALUES = ["", " ", "0", "-0", "1", "-1", "3", "2.5", "-2.5", "1e-9", "1e400", "-1e400", "1e308", "nan", "NaN",
              "inf", "-inf", "Infinity", "9" * 40, "-" + "9" * 40, "0x10", "1_000", "1,2", "1,,2", ",", "[1,2",
              "[1, 2, 0]", "{}", "[]", "null", "true", "yes", "ß", "红色", "🤖", "ré@1", "\u202e", "a b", "\t",
              "1\n2", "line\r", "x" * 300, "%s", "{0}", "'", '"', "=", "a=b", "--", "-", "@", ":", "../..", "٣"]
UNKNOWN_FLAGS = ["--nope", "-z", "--Seed", "---seed", "--seed=", "--set=", "--fault=", "--se", "--dur", "--",
                 "-", "--video-sizes", "--robots", "—seed"]
# --set assignments that are malformed whatever the mission
BAD_SETTINGS = ["", "=", "==", "robots", "=3", "robots==3", " = ", ".=1", "..=1", "a..b=1", ".robots=1", "robots.=1",
                "params.robots=1", "timing.=1", "radio.nope=1", "nope.loss=1", "speed=3", "video.camera=",
                "robots[0]=1", "robots.red.pose=[1,2", "robots.red.pose=[1e9,0,0]", "robots.red.pose=[nan,0,0]",
                "robots.red.pose=[.nan, 0, 0]", "robots.red.pose=[.inf, 0, 0]", "robots.red=null", "robots={}",
                "robots.red.kind=hovercraft", "robots.red.options.radius=-1", "robots.red.options.ir_count=100000",
                "robots.red.options.nope=1", "robots.red.controller.nope=1", "robots.red.controller=7",
                "robots.zed={kind: r2}", "robots.zed={kind: r2, pose: [0, 0, 0]}", "robots.ré={}",
                "arena.boxes[99].x=1", "arena.boxes[-1].x=1", "arena.boxes[0]x=1", "arena.boxes[0][0]=1",
                "arena.size=[0,0]", "arena.size=[-1,5]", "arena.size=[0.5,0.5]", "arena.size=[1e9,1e9]",
                "arena.size=7", "arena.walls=maybe", "arena.image={file: nope.png}", "arena.image={file: ''}",
                "arena.bogs=[{x: 0}]", "arena.cylinders=[{radius: -1}]", "objects.pucks=[{x: 1e9}]",
                "objects.pucks[0].x=nan", "objects=[]", "task=null", "task=[]", "task.nope=1", "task.goal=[1e9,0]",
                "faults=[1]", "faults=[{kind: kill}]", "faults=[{kind: kill, robot: red, time: -1}]",
                "faults=[{kind: slow, robot: red, time: 1, options: {factor: [1]}}]", "seed=-1", "seed=1.5",
                "duration=0", "duration=.inf", "mission=wander", "mission=[]", "timing.physics_dt=0",
                "timing.physics_dt=1", "timing.physics_dt=nan", "timing.control_dt=1e-9", "radio.loss=2",
                "radio.rate_hz=0", "radio.range=-1", "radio={rate_hz: 0}", "positioning.period=0", "video.fps=0",
                "video.fps=1e3", "video.width=641", "video.width=10", "video.speedup=0.5", "video.enabled=maybe",
                "&a [*a]", "arena.boxes=&a [*a]", "task=!!python/object/apply:os.system ['true']", "x=*a",
                "size_x=3", "leg=4", "behaviour=1", "robots.red.controller.behaviour=1"]
FAULT_TIMES = ["0", "1", "2.5", "1e6", "-1", "nan", "inf", "-inf", "1e400", "", "x", "0x1", "1_0", "١"]
GROUP_KEYS = ["timing.physics_dt", "timing.control_dt", "timing.energy_dt", "radio.rate_hz", "radio.latency",
              "radio.loss", "radio.range", "radio.timeout_periods", "positioning.period", "positioning.noise_moving",
              "video.fps", "video.width", "video.speedup", "video.camera", "video.enabled"]
# A navigate world of 25-30 % density takes 30-40 s to draw, or to be found out of reach (a ConfigError): not here.
SLOW = {("navigate", "density"): 0.25}


# -- stubs of what would run for minutes ------------------------------------------------------------------------------
class Reached(Exception):
    """The viewer got as far as opening its window: every check of its arguments has passed."""


def _stub_run_trial(calls: list):
    def run_trial(config, seed=None, progress=None):
        """What run_trial checks before its first write (but the compiled world): then a completed result."""
        validate(config)
        resolve(config, mission_of(config.mission))
        calls.append(("run", config))
        summary = {"status": "completed", "sim_time_s": 0.0, "wall_time_s": 0.0, "real_time_factor": None}
        return TrialResult("completed", Path(config.out) / config.mission / str(config.run_id), summary)
    return run_trial


def _study_configs(module, study) -> list:
    """A study's trial configurations on a small grid: two per condition, its first and last seeds."""
    if not dataclasses.is_dataclass(study):
        return []
    small = {f.name: min(getattr(study, f.name), 2) for f in dataclasses.fields(study)
             if f.name in ("trials", "missions", "runs") and isinstance(getattr(study, f.name), int)}
    if isinstance(getattr(study, "seeds", None), tuple) and study.seeds:
        small["seeds"] = (study.seeds[0], study.seeds[-1])
    study = dataclasses.replace(study, **small)
    if hasattr(module, "trial_configs"):
        return module.trial_configs(study)
    if hasattr(module, "trial_config"):  # box pushing: one per experiment and trial
        return [module.trial_config(study, e, k) for e in study.experiments for k in range(study.trials)]
    return []


def _stub_run_study(calls: list, module):
    def run_study(*args, **kwargs):
        """Check the trial configurations the study would run, then return at once."""
        study = args[0] if args else kwargs.get("study")
        for config in _study_configs(module, study):
            try:
                validate(config)
            except ConfigError as exc:  # (not exit 2: the real study would start, and lose every such trial)
                raise AssertionError(f"the study accepted arguments that make a bad trial: {exc}") from None
        calls.append(("study", module.__name__))
        if module.__name__.endswith(("lalliance", "two_tier_astar")):
            return {"report": Path("report.md"), "results": Path("results.csv"), "rows": 0, "wall_s": 0.0}
        return Path("study")
    return run_study


def _stub_bench(calls: list, name: str):
    def bench(*args, seconds=None, **kwargs):
        """A benchmark given its simulated seconds: a positive number (or None: its default)."""
        assert seconds is None or (math.isfinite(seconds) and seconds > 0), f"bench {name} ran with {seconds=}"
        calls.append(("bench", name))
        return {}
    return bench


@pytest.fixture
def stubs(monkeypatch) -> list:
    """The heavy executors replaced by stubs that check what they get and return at once; the list of their calls."""
    import teamsim.bench
    import teamsim.rerender
    import teamsim.runner
    import teamsim.tasks.studies
    import teamsim.viewer

    calls: list = []
    cli = importlib.import_module("teamsim.cli.main")  # (teamsim.cli.main is also the function's name)
    monkeypatch.setattr(cli, "_build_parser", _parser)  # built once: 20 ms a time was a third of the test
    monkeypatch.setattr(teamsim.runner, "run_trial", _stub_run_trial(calls))

    def window():
        raise Reached()
    monkeypatch.setattr(teamsim.viewer, "require_display", window)

    def rerender(run_dir, camera="top", out=None, width=640, height=480, progress=None):
        teamsim.rerender.trajectory_of(run_dir)
        calls.append(("render", run_dir))
        return Path(out or Path(run_dir) / "video.mp4")
    monkeypatch.setattr(teamsim.rerender, "rerender", rerender)
    monkeypatch.setattr(teamsim.rerender, "rerender_all", lambda run_dirs, camera="top", width=640, height=480,
                        workers=None: [rerender(d, camera, None, width, height) for d in run_dirs])
    for info in pkgutil.iter_modules(teamsim.tasks.studies.__path__):
        module = importlib.import_module(f"teamsim.tasks.studies.{info.name}")
        if hasattr(module, "run_study"):
            monkeypatch.setattr(module, "run_study", _stub_run_study(calls, module))
    for info in pkgutil.iter_modules(teamsim.bench.__path__):
        module = importlib.import_module(f"teamsim.bench.{info.name}")
        for name, value in list(vars(module).items()):
            if callable(value) and not isinstance(value, type) and not name.startswith("_") \
                    and getattr(value, "__module__", None) == module.__name__:
                monkeypatch.setattr(module, name, _stub_bench(calls, f"{info.name}.{name}"))
    return calls


# -- the command lines ------------------------------------------------------------------------------------------------
@dataclasses.dataclass
class Files:
    """Inputs and output places inside the test's folder (nothing is ever written outside it)."""
    root: Path

    def __post_init__(self) -> None:
        root = self.root
        (root / "run").mkdir(parents=True)
        (root / "run" / "trajectory.npz").write_bytes(b"")  # (the renderer is a stub: it is never read)
        (root / "cut").mkdir()  # a run killed by SIGKILL: its summary still says running, its process is gone
        (root / "cut" / "summary.json").write_text(json.dumps({"status": "running", "pid": 2**22 + 12345,
                                                               "host": socket.gethostname()}))
        (root / "tasks.toml").write_text(data_file("thesis_tasks.toml").read_text())
        (root / "robots.toml").write_text(data_file("thesis_robots.toml").read_text())
        (root / "garbage.toml").write_text("[tasks.x\nname = ")
        (root / "latin1.toml").write_bytes(b"[tasks.\xff]\n")
        (root / "a-file").write_text("not a folder")
        shutil.copy(EXAMPLES / "wander.yaml", root / "wander.yaml")
        (root / "broken.yaml").write_text("robots: [\n")
        (root / "out").mkdir()

    @property
    def inputs(self) -> list[str]:
        """Paths a command reads: good files, wrong files, folders, nothing, a name too long."""
        r = self.root
        return [str(p) for p in (r / "run", r / "cut", r / "tasks.toml", r / "robots.toml", r / "garbage.toml",
                                 r / "latin1.toml", r / "wander.yaml", r / "broken.yaml", r / "nope", r,
                                 r / "a-file" / "x", EXAMPLES / "navigate-density-15.yaml", EXAMPLES / "maps")] \
            + ["", "/", "/dev/null", "ré.yaml", "x" * 300]

    @property
    def outputs(self) -> list[str]:
        """Places a command writes to, all in the root: fresh files, folders, a path through a file, nothing."""
        r = self.root
        return [str(p) for p in (r / "out" / "x.xml", r / "out" / "deep" / "x.yaml", r / "out", r,
                                 r / "a-file" / "x", r / "ré 🤖.yaml", r / "a-file", r / ("x" * 300))] + ["", " "]


@pytest.fixture
def files(tmp_path, monkeypatch) -> Files:
    monkeypatch.chdir(tmp_path)  # (a default --out such as renders/ stays in the test's folder)
    return Files(tmp_path / "files")


def _choices(parser, name: str) -> dict:
    """The subcommands (or studies) of ``parser``'s ``name`` subparsers."""
    return next(a.choices for a in parser._actions if a.dest == name)


def base_vectors(files: Files) -> list[list[str]]:
    """Valid command lines, at least one for each subcommand, study and benchmark."""
    out = str(files.root / "out")
    parser = _parser()
    run = [["run", name, "--out", out] for name in MISSIONS]
    run += [["run", "wander", "--seed", "4", "--duration", "5", "--set", "robots=4", "--fault", "kill:red@2",
             "--fault", "slow:green@1,factor=0.5", "--video", "--video-size", "1280x720", "--camera", "perspective",
             "--out", out, "--run-id", "r"],
            ["run", "wander", "--set", "robots.red.pose=[1,2,0]", "--set", "arena.boxes[0].x=2", "--out", out],
            ["run", "hazardous-waste", "--set", "robots=2", "--fault", "kill:red@40", "--out", out],
            ["run", "box-pushing", "--set", "right=genghis2", "--fault", "remove:genghis@40", "--fault",
             "revive:genghis@120", "--out", out],
            ["run", "formation", "--set", "strategy=I", "--set", "route=smooth", "--set", "crossing=2", "--out", out],
            ["run", "janitorial", "--set", "rho=0.1", "--set", "size_x=6,7", "--fault", "break-gripper:r2@30",
             "--out", out],
            ["run", "explore", "--set", "team=1 3", "--set", "backend=kinematic", "--out", out],
            ["run", "navigate", "--scenario", str(EXAMPLES / "navigate-density-15.yaml"), "--set", "radio.loss=0.2",
             "--out", out],
            ["run", "wander", "--scenario", str(files.root / "wander.yaml"), "--seed", "3", "--out", out]]
    show = [["scenario", "show", name, "--seed", "1"] for name in MISSIONS]
    show += [["scenario", "show", "wander", "--set", "robots=5", "--output", str(files.root / "out" / "s.yaml")]]
    study = [["study", name] for name in _choices(_choices(parser, "command")["study"], "study")]
    study += [["study", "navigation", "--robots", "A,B", "--densities", "0.05,0.1", "--controllers", "FRC,ODW",
               "--trials", "2", "--workers", "2", "--backend", "physics", "--worlds", "uniform", "--out", out],
              ["study", "awareness", "--missions", "2", "--duration", "100", "--seed", "3", "--out", out],
              ["study", "janitorial-rho", "--rhos", "0,0.5", "--duration", "60", "--out", out],
              ["study", "cleanup-faults", "--conditions", "none,kill-red", "--missions", "1", "--out", out],
              ["study", "box-pushing", "--trials", "2", "--experiments", "heterogeneity", "--seed", "1", "--out", out],
              ["study", "formation", "--runs", "2", "--strategies", "I,IV", "--duration", "50", "--out", out],
              ["study", "two-tier-astar", "--trials", "2", "--seed", "5", "--out", out],
              ["study", "lalliance", "--runs", "2", "--workers", "1", "--out", out]]
    bench = [["bench", what, "--seconds", "1"]
             for what in next(a.choices for a in _choices(parser, "command")["bench"]._actions if a.dest == "what")]
    return (run + show + study + bench
            + [["list"], ["view", "wander", "--speed", "2", "--set", "robots=2"],
               ["view", "formation", "--fault", "kill:A@3"],
               ["render", str(files.root / "run"), "--camera", "perspective", "--video-size", "1280x720"],
               ["render", str(files.root / "run"), str(files.root / "run"), "--workers", "2"],
               ["export", "diffdrive", "--out", str(files.root / "out" / "d.xml")],
               ["allocate"], ["allocate", str(files.root / "tasks.toml"), str(files.root / "robots.toml"), "--json"],
               ["allocate", "--explain"]])


@functools.cache
def _parser():
    """The command line's parser (argparse parsers keep no state between parses)."""
    return _build_parser()


def _options(argv: list[str]) -> dict:
    """The long options of ``argv``'s subcommand (or study), --help aside: {option: its argparse action}."""
    parser = _parser()
    for token in argv:
        commands = [a.choices for a in parser._actions if isinstance(a.choices, dict)]
        if not commands or token not in commands[0]:
            break
        parser = commands[0][token]
    return {s: a for a in parser._actions for s in a.option_strings if s.startswith("--") and s != "--help"}


def plausible(rng: random.Random, option: str, action, argv: list[str]) -> str:
    """A value ``option`` may well accept: one of its choices, its default, a small number, a size or a camera."""
    if action.choices:
        return str(rng.choice(list(action.choices)))
    if option == "--video-size":
        return rng.choice(["64x48", "320x240", "1920x1080", "3840x2160"])
    if option == "--camera":
        return rng.choice(["top", "perspective"] + _team(argv))
    if action.default not in (None, False) and not isinstance(action.default, Path):
        default = action.default
        return ",".join(map(str, default)) if isinstance(default, tuple) else str(default)
    return rng.choice(["1", "2", "7", "0.5", "30"])


def _team(argv: list[str]) -> list[str]:
    mission = next((token for token in argv if token in MISSIONS), "wander")
    return MISSION_DATA[mission][1]


def _leaves(node, prefix=""):
    """(--set path, value) of every leaf of a scenario's data (``arena.boxes[0].x``)."""
    if isinstance(node, dict):
        return [leaf for key, value in node.items() for leaf in _leaves(value, f"{prefix}.{key}" if prefix else key)]
    if isinstance(node, list) and node and isinstance(node[0], (dict, list)):
        return [leaf for k, value in enumerate(node) for leaf in _leaves(value, f"{prefix}[{k}]")]
    return [(prefix, node)]


def _missions() -> dict:
    """Per mission: its parameter fields, its team and the leaves of its seed-1 scenario."""
    found = {}
    for name, mission in MISSIONS.items():
        data = to_data(scenario_of(trial_config(name, seed=1), mission))
        found[name] = (dataclasses.fields(mission.Params), list(data["robots"]), _leaves(data))
    return found


MISSION_DATA = _missions()


def bounds(field: dataclasses.Field) -> list[str]:
    """--set values of a mission parameter: its choices, and its bounds and a step past each."""
    meta, default = field.metadata, field.default
    values = [str(c) for c in meta.get("choices") or ()]
    whole = isinstance(default, int) and not isinstance(default, bool)
    for bound, step in ((meta.get("lo"), -1), (meta.get("hi"), 1)):
        if bound is not None:
            for v in (bound, bound + step * (1 if whole else 1e-3)):
                text = str(int(v)) if whole else repr(float(v))
                values.append(",".join([text] * len(default)) if isinstance(default, tuple) else text)
    return values


def nearby(value) -> list[str]:
    """YAML texts near a scenario value: itself, other numbers, other lengths, other types."""
    if isinstance(value, bool):
        options = [not value, "maybe", 1]
    elif isinstance(value, (int, float)):
        options = [value, -value, value * 2, value + 0.5, 0, 1e4, -1e4, float("nan"), float("inf")]
    elif isinstance(value, str):
        options = [value, value + "x", "", 3]
    elif isinstance(value, list):
        options = [value, value[:-1], value + [0], [[v] for v in value], "x"]
    else:
        options = [value, 0, "x", {}]
    return [yaml.safe_dump(v, default_flow_style=True, width=10**6).strip().removesuffix("...").strip()
            for v in options] + ["1e-3"]


def too_slow(mission: str, key: str, text: str) -> bool:
    limit = SLOW.get((mission, key))
    try:
        return limit is not None and float(text) > limit
    except ValueError:
        return False


def a_setting(rng: random.Random, argv: list[str]) -> str:
    """One --set: a mission parameter, a group setting or a scenario path, with a nearby or an odd value; or a
    malformed one."""
    mission = next((token for token in argv if token in MISSIONS), "wander")
    fields, _, leaves = MISSION_DATA[mission]
    form = rng.choice(["param", "param", "group", "path", "path", "path", "malformed"])
    if form == "malformed":
        return rng.choice(BAD_SETTINGS)
    if form == "param":
        field = rng.choice(fields)
        key, value = field.name, rng.choice(bounds(field) + rng.sample(ODD_VALUES, 3))
        if too_slow(mission, key, value):
            value = "0.2"
    elif form == "group":
        key, value = rng.choice(GROUP_KEYS), rng.choice(ODD_VALUES + ["0.02", "1e-4", "0.5", "100", "12"])
    else:
        key, existing = rng.choice(leaves)
        value = rng.choice(nearby(existing) + rng.sample(ODD_VALUES, 2))
        key = rng.choice([key] * 6 + [key.replace("[0]", "[99]"), key + ".nope", key.rsplit(".", 1)[0] + ".colour"])
    return f"{key}={value}"


def a_fault(rng: random.Random, argv: list[str]) -> str:
    """One --fault spec, from a good one to none of KIND:ROBOT@SECONDS[,key=value...]."""
    if rng.random() < 0.4:  # a good one
        kind = rng.choice(["kill", "radio-off", "remove", "revive", "break-motor", "blind-ir", "slow"])
        option = {"slow": ",factor=0.3", "blind-ir": rng.choice(["", ",sensors=ir"])}.get(kind, "")
        return f"{kind}:{rng.choice(_team(argv))}@{rng.choice(['0', '1', '2.5', '40'])}{option}"
    kind = rng.choice(list(FAULT_KINDS) * 2 + ["explode", "KILL", "", "kill-"])
    robot = rng.choice(_team(argv) * 2 + ["nobody", "", "ré", "a b", "manager", "explorer", "planner2"])
    options = rng.choice(["", "", ",factor=0.5", ",factor=0", ",factor=2", ",factor=nan", ",factor=x", ",factor=",
                          ",sensors=ir", ",sensors=", ",sensors=nosuch+ir", ",motor=left", ",motor=nosuch",
                          ",kind=r2", ",kind=hovercraft", ",kind=", ",speed=1", ",", ",x", ",a=b=c", ",factor=0.5,"])
    spec = f"{kind}:{robot}@{rng.choice(FAULT_TIMES)}{options}"
    return rng.choice([spec] * 6 + [spec.replace(":", ""), spec.replace("@", ""), spec.split("@")[0], "kill red 1"])


def a_value(rng: random.Random, option: str, files: Files) -> str:
    """A value for ``option``: a path where it takes one (never a place outside the test's folder to write to)."""
    if option in ("--out", "--output", "--resume"):
        return rng.choice(files.outputs)
    if option == "--scenario":
        return rng.choice(files.inputs)
    return rng.choice(ODD_VALUES)


def mutate(rng: random.Random, argv: list[str], files: Files) -> list[str]:
    """``argv`` after one or two random mutations."""
    argv = list(argv)
    for _ in range(rng.randint(1, 2)):
        how = rng.choice(["option", "option", "value", "value", "set", "set", "set", "fault", "fault", "flag",
                          "drop", "swap", "truncate", "mission", "duplicate"])
        if how in ("set", "fault") and "--set" not in _options(argv):  # (a command that takes no --set)
            how = "option"
        options = _options(argv)
        values = [k for k, token in enumerate(argv) if k > 0 and not token.startswith("--")]
        if how == "option" and options:  # an option of this subcommand, with a likely or an odd value
            option = rng.choice(sorted(options))
            good = rng.random() < 0.5
            argv += [option, plausible(rng, option, options[option], argv) if good else a_value(rng, option, files)]
        elif how == "value" and values:
            k = rng.choice(values)
            option = argv[k - 1] if argv[k - 1] in options else ""
            if option:
                good = rng.random() < 0.4
                argv[k] = plausible(rng, option, options[option], argv) if good else a_value(rng, option, files)
            else:  # a positional: a file (allocate's, render's) for another file, else any value
                argv[k] = rng.choice(files.inputs if "/" in argv[k] else ODD_VALUES)
        elif how == "set":
            argv += ["--set", a_setting(rng, argv)]
        elif how == "fault":
            argv += ["--fault", a_fault(rng, argv)]
        elif how == "flag":
            argv.insert(rng.randint(0, len(argv)), rng.choice(UNKNOWN_FLAGS))
        elif how == "drop" and len(argv) > 1:
            del argv[rng.randrange(len(argv))]
        elif how == "swap" and len(argv) > 2:
            i, j = rng.sample(range(len(argv)), 2)
            argv[i], argv[j] = argv[j], argv[i]
        elif how == "truncate":
            argv = argv[:rng.randint(0, len(argv))]
        elif how == "mission":
            names = [k for k, token in enumerate(argv) if token in MISSIONS]
            if names:
                argv[names[0]] = rng.choice(list(MISSIONS) + ["nosuch", "", "Wander", "wander "])
        elif how == "duplicate" and argv:
            k = rng.randrange(len(argv))
            argv[k:k] = argv[k:k + 2]
    return argv


# -- running one ------------------------------------------------------------------------------------------------------
def invoke(argv: list[str], capfd) -> tuple[int, str, str]:
    """``main(argv)`` in-process: (exit code, stdout, stderr). The viewer reaching its window counts as exit 0,
    and so does argparse's own exit after printing help."""
    try:
        code = main(argv)
    except Reached:
        code = 0
    except SystemExit as exc:  # -h
        code = exc.code
    captured = capfd.readouterr()
    return code, captured.out, captured.err


def problem(code: int, err: str) -> str | None:
    """What is wrong with one outcome, or None: exit 0 and a quiet stderr, or exit 2 and one error line."""
    if "Traceback" in err:
        return "a traceback"
    if code == 0:
        return None if err == "" else f"exit 0 but stderr {err!r}"
    if code != 2:
        return f"exit {code}"
    if not err.startswith("teamsim: error: ") or err.count("\n") != 1 or not err.endswith("\n"):
        return f"stderr is not one error line: {err!r}"
    return None


def outcome(argv: list[str], capfd) -> tuple[int | None, str | None]:
    """(exit code, what is wrong or None) of one vector; an exception that escapes main is what is wrong."""
    try:
        code, _, err = invoke(argv, capfd)
    except Exception as exc:  # noqa: BLE001  (an escaped exception is a finding: name it with its vector)
        capfd.readouterr()
        return None, f"{type(exc).__name__}: {exc}"
    return code, problem(code, err)


def test_mutated_command_lines_exit_0_or_one_error_line(stubs, files, capfd):
    """1200 mutated vectors over every subcommand, study and benchmark; the failure lists every failing vector."""
    bases = base_vectors(files)
    trials = [argv for argv in bases if argv[0] in ("run", "scenario", "view")]
    rng = random.Random(SEED)
    failures, codes, reached, commands = [], {0: 0, 2: 0}, set(), set()
    for _ in range(CASES):
        argv = mutate(rng, rng.choice(trials if rng.random() < 0.5 else bases), files)
        stubs.clear()
        code, found = outcome(argv, capfd)
        if found:
            failures.append(f"{argv!r}: {found}")
        codes[code] = codes.get(code, 0) + 1
        reached.update(what for what, _ in stubs)
        commands.add(argv[0] if argv else "")
    assert not failures, f"{len(failures)} of {CASES} vectors failed:\n" + "\n".join(failures[:40])
    assert codes[0] > 200 and codes[2] > 600, codes  # both endings are well represented
    assert {"run", "study", "bench", "render"} <= reached  # the stubs were reached with accepted arguments
    assert {"run", "scenario", "view", "render", "export", "allocate", "study", "bench", "list"} <= commands


@pytest.mark.parametrize("mission", MISSIONS)
def test_every_mission_parameter_at_and_past_its_bounds_and_every_bad_setting(mission, stubs, files, capfd):
    """``run MISSION --set PARAM=VALUE`` for every parameter at its bounds, a step past them, each choice, NaN and a
    word, and ``--set`` of every malformed assignment of BAD_SETTINGS: the scenario is generated and checked for real
    (the stubbed run_trial gets it), and each ends in exit 0 or one error line."""
    settings = [f"{field.name}={value}" for field in MISSION_DATA[mission][0]
                for value in bounds(field) + ["nan", "x", ""] if not too_slow(mission, field.name, value)]
    failures = []
    for setting in settings + BAD_SETTINGS:
        argv = ["run", mission, "--set", setting]
        found = outcome(argv, capfd)[1]
        failures += [f"{argv!r}: {found}"] if found else []
    assert not failures, "\n".join(failures)


def test_every_file_argument_takes_any_path(stubs, files, capfd):
    """Each command that reads or writes a file, given every path of the pools: a folder, a path through a file, a
    name too long, a file of another kind, not UTF-8, an empty name, a device. Exit 0 or one error line."""
    tasks, robots = str(files.root / "tasks.toml"), str(files.root / "robots.toml")
    reads = [["allocate", "{}", robots], ["allocate", tasks, "{}"], ["render", "{}"],
             ["run", "wander", "--scenario", "{}"], ["scenario", "show", "navigate", "--scenario", "{}"]]
    writes = [["export", "diffdrive", "--out", "{}"], ["scenario", "show", "wander", "--output", "{}"],
              ["render", str(files.root / "run"), "--out", "{}"]]
    failures = []
    for templates, paths in ((reads, files.inputs), (writes, files.outputs)):
        for template in templates:
            for path in paths:
                argv = [token.replace("{}", path) for token in template]
                found = outcome(argv, capfd)[1]
                failures += [f"{argv!r}: {found}"] if found else []
    assert not failures, "\n".join(failures)


def test_the_base_vectors_are_valid(stubs, files, capfd):
    """Each unmutated vector succeeds: the mutations start from good command lines."""
    for argv in base_vectors(files):
        code, _, err = invoke(argv, capfd)
        assert (code, err) == (0, ""), (argv, err)


@pytest.mark.parametrize("argv", [["study", "awareness", "--seed", "-1"], ["study", "formation", "--duration", "inf"],
                                  ["study", "cleanup-faults", "--seed", "-" + "9" * 40],
                                  ["study", "navigation", "--seed", str(2**62)],
                                  ["study", "janitorial-rho", "--duration", "0"],
                                  ["study", "robustness", "--seeds", "9" * 40],
                                  ["study", "robustness", "--seeds", f"{2**62 - 1}-{2**62}"]],
                         ids=["negative-seed", "endless-duration", "huge-negative-seed", "seed-past-range",
                              "zero-duration", "huge-seeds", "seeds-past-range"])
def test_study_seeds_and_durations_are_range_checked(stubs, files, capfd, argv):
    """A study's --seed in [0, 2**62), --duration in (0, 1e7] and --seeds (at most a million, each a valid --seed)
    are checked before anything runs: one error line, exit 2."""
    assert outcome(argv, capfd) == (2, None)


def test_line_breaks_in_an_argument_stay_on_one_error_line(capfd):
    """An argument with a line break in it (``--set 'robots=1<newline>2'``) is quoted with the break escaped."""
    code, _, err = invoke(["run", "wander", "--set", "robots=1\n2\u2028\r3"], capfd)
    assert (code, err) == (2, "teamsim: error: --set robots=1\\n2\\u2028\\r3: expected an integer\n")


def test_bench_seconds_must_be_a_positive_number(stubs, capfd):
    """``bench --seconds`` is checked before any benchmark starts."""
    for seconds in ("-1", "0", "nan", "inf", "1e8", "x"):
        code, _, err = invoke(["bench", "physics", "--seconds", seconds], capfd)
        assert code == 2 and err == ("teamsim: error: argument --seconds: --seconds must be a number of simulated "
                                     "seconds in (0, 1e7]\n"), err
    assert not stubs


def test_a_real_short_run_and_the_real_viewer_without_a_display(tmp_path, monkeypatch, capfd):
    """Smoke cases with nothing stubbed: a 0.2 s wander run writes its summary; without a display the viewer is one
    error line, after its own check of --speed."""
    argv = ["run", "wander", "--duration", "0.2", "--out", str(tmp_path), "--run-id", "smoke"]
    code, out, err = invoke(argv, capfd)
    assert (code, err) == (0, "") and out.startswith("completed:")
    assert json.loads((tmp_path / "wander" / "smoke" / "summary.json").read_text())["status"] == "completed"
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    code, _, err = invoke(["view", "wander", "--speed", "nan"], capfd)
    assert code == 2 and err == "teamsim: error: --speed: must be > 0 (simulated seconds per wall-clock second)\n"
    code, _, err = invoke(["view", "wander"], capfd)
    assert code == 2 and err.startswith("teamsim: error: no display") and err.count("\n") == 1

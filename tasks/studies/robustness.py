"""``teamsim study robustness``: every mission under every fault kind it supports, over seeds (issue 29, part 1).

For each mission of ``teamsim list`` and each fault kind of :data:`teamsim.faults.FAULT_KINDS` the mission's robots
can suffer (:func:`supported`; the pairs left out and why are in :data:`NOT_SUPPORTED`), the study runs the mission
with its own defaults (duration included) on each trial seed, with the fault injected at a random time (in 5-60 %
of the mission's typical time, :data:`TYPICAL_S`, or of ``duration`` if that is shorter) on a random robot. The draws
come from a generator seeded by the study seed, the mission, the fault and the trial seed (:func:`faults_of`), so a
study is reproducible and adding a seed changes no other run. A mission whose headline fault strikes a role rather
than a robot gets it in that kind's cell (:data:`ROLE_TARGETS`: bounding overwatch's kill is ``kill:@leader@T``,
issue 29's "overwatch with a leader killed", the role resolved when the fault is due; exploration's is
``kill:explorer@T``, "an explorer killed", the first explorer of the allocation). Kinds that only make sense
after another fault are run after it: ``radio-on`` after a ``radio-off`` of the same robot, ``revive`` after a
``kill`` or a ``remove`` (drawn).

Each run gives one row of ``results.csv`` (mission, fault, fault spec, seed, status, completed, simulated time,
error, and the cause of a failure, classified: :func:`cause_of`); ``report.md`` gives per mission and fault the
completion rate, the status counts, and every run that did not complete with its measured cause. A run with status
``error`` is a bug in teamsim, not a statistic. Nothing wall-clock goes into either file, so a study resumed with
``--resume`` (its journal ``trials.jsonl``, :mod:`teamsim.sweep`) writes them byte for byte as an uninterrupted one.

``explore`` runs on its kinematic backend (``backend=kinematic``: the same world, team, controllers and faults
without contacts; its physics runs take minutes of wall time each); every other mission runs in physics.
"""
from __future__ import annotations

import functools
import math
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teamsim.config import ConfigError, TrialConfig, apply_setting
from teamsim.faults import FAULT_KINDS, Fault
from teamsim.files import write_atomic, write_csv
from teamsim.rng import RandomStreams
from teamsim.sweep import JOURNAL_NAME, run_trials

MISSIONS = ("wander", "navigate", "hazardous-waste", "box-pushing", "explore", "janitorial", "bounding-overwatch",
            "formation")
# s: about how long each mission takes to complete without faults (seed 1, measured 2026-11-26; janitorial and
# bounding overwatch from their docs). A fault comes at a uniform time in 5-60 % of it, while work is left.
TYPICAL_S = {"wander": 60.0, "navigate": 60.0, "hazardous-waste": 400.0, "box-pushing": 450.0, "explore": 1800.0,
             "janitorial": 1200.0, "bounding-overwatch": 250.0, "formation": 300.0}
SETTINGS = {"explore": ("backend=kinematic",)}  # --set per mission (module docstring)
# (mission, kind) -> the role that kind strikes instead of a drawn robot (@ROLE: resolved when the fault is due;
# explore's role names: resolved from the allocation before the run)
ROLE_TARGETS = {("bounding-overwatch", "kill"): "@leader", ("explore", "kill"): "explorer"}
NEWCOMER = {"wander": "diffdrive", "hazardous-waste": "r2", "box-pushing": "genghis2", "janitorial": "janitor"}
_NO_GRIPPER = "its robots have no gripper"
_NO_RADIO = "its robots send no messages, so the radio faults change nothing"
_FIXED_TEAM = "the mission refuses add-robot: its team is fixed at the start"
_KINEMATIC = ("explore's kinematic backend, which the study runs, does not model it (kill, remove, radio-off, "
              "break-motor and slow only); explore in physics does, at minutes of wall time a run")
NOT_SUPPORTED = {
    ("wander", "radio-off"): _NO_RADIO, ("wander", "radio-on"): _NO_RADIO, ("wander", "break-gripper"): _NO_GRIPPER,
    ("navigate", "kill"): "one robot and no teammate: it fails by construction",
    ("navigate", "remove"): "one robot and no teammate: it fails by construction",
    # The study's navigate robot (B, a differential drive) has two locomotion motors: with one limp a single input
    # is left and it can only retrace one curve (measured: a loop of 3.6 m every 29 s, seed 0)
    ("navigate", "break-motor"): "its robot has two drive motors: one limp leaves a single input, so it can only "
                                 "retrace one curve and fails by construction",
    ("navigate", "radio-off"): _NO_RADIO, ("navigate", "radio-on"): _NO_RADIO,
    ("navigate", "break-gripper"): _NO_GRIPPER,
    ("navigate", "add-robot"): "the mission refuses add-robot: it drives one robot to its goal",
    ("box-pushing", "break-gripper"): "the R-2s push the box with their bodies; the gripper is never used",
    ("explore", "break-gripper"): _NO_GRIPPER,
    ("explore", "add-robot"): "the mission refuses add-robot: its roles are allocated at the start (ch.5)",
    ("explore", "blind-ir"): _KINEMATIC, ("explore", "radio-on"): _KINEMATIC, ("explore", "revive"): _KINEMATIC,
    ("bounding-overwatch", "break-gripper"): _NO_GRIPPER, ("bounding-overwatch", "add-robot"): _FIXED_TEAM,
    ("formation", "break-gripper"): _NO_GRIPPER, ("formation", "add-robot"): _FIXED_TEAM,
}
STATUSES = ("completed", "failed", "unstable", "error", "interrupted", "crashed")
COLUMNS = ("mission", "fault", "fault_spec", "seed", "status", "completed", "sim_time_s", "duration_s", "error",
           "cause_class", "cause")
MOTION_WINDOW_S = 60.0  # s: how far back from the end a failed run's robots are checked for motion
MOVING_M = 0.3  # m travelled in that window above which a robot counts as moving


@dataclass(frozen=True)
class RobustnessStudy:
    seeds: tuple[int, ...] = (0,)  # trial seeds (--seeds N: 0..N-1, or A-B)
    seed: int = 0  # the study seed: fault times and robots are drawn from it
    missions: tuple[str, ...] = MISSIONS
    faults: tuple[str, ...] = FAULT_KINDS
    duration: float | None = None  # simulated seconds per run (None: each mission's own default)
    workers: int | None = None
    out: Path = Path("renders/study-robustness")
    resume: bool = False  # continue the study in ``out`` from its journal (trials.jsonl)


def supported(mission: str, fault: str) -> bool:
    return (mission, fault) not in NOT_SUPPORTED


def cells(study: RobustnessStudy) -> list[tuple[str, str]]:
    """The (mission, fault) pairs the study runs, in its order."""
    return [(m, f) for m in study.missions for f in study.faults if supported(m, f)]


@functools.lru_cache(maxsize=None)
def team_of(mission: str, seed: int) -> tuple[tuple[str, str], ...]:
    """(name, kind) of each robot a mission starts with at a trial seed (some draw their kinds from the seed)."""
    from teamsim.runner import mission_of, trial_config
    from teamsim.scenario import resolve

    config = trial_config(mission, seed=seed, settings=SETTINGS.get(mission, ()))
    config = resolve(config, mission_of(mission))
    if config.scenario is None:
        raise ConfigError(f"mission {mission}: no scenario to draw robots from")
    return tuple((name, spec.kind) for name, spec in config.scenario.robots.items())


@functools.lru_cache(maxsize=None)
def _parts(kind: str) -> tuple[tuple[str, ...], bool]:
    """A robot kind's locomotion motors and whether it has a gripper (effectors)."""
    from teamsim.models import build_robot

    robot = build_robot(kind, "x")
    return tuple(robot.motors), bool(robot.effectors)


def faults_of(study: RobustnessStudy, mission: str, fault: str, seed: int) -> list[Fault]:
    """The faults of one run: ``fault`` on a random robot at a random time (and the fault it follows)."""
    rng = RandomStreams(study.seed).get("robustness", mission, fault, str(seed))
    team = team_of(mission, seed)
    candidates = [(n, k) for n, k in team if fault != "break-gripper" or _parts(k)[1]]
    name, kind = candidates[int(rng.integers(len(candidates)))]
    name = ROLE_TARGETS.get((mission, fault), name)  # (drawn all the same: the time's draw stays as it was)
    typical = min(TYPICAL_S[mission], study.duration or math.inf)  # a short study draws within its duration
    at = round(float(rng.uniform(0.05, 0.6) * typical), 1)
    later = round(at + float(rng.uniform(0.1, 0.3) * typical), 1)
    first = ("kill", "remove")[int(rng.integers(2))]
    if fault == "radio-on":
        return [Fault("radio-off", name, at), Fault("radio-on", name, later)]
    if fault == "revive":
        return [Fault(first, name, at), Fault("revive", name, later)]
    if fault == "break-motor":
        motors = _parts(kind)[0]
        return [Fault(fault, name, at, {"motor": motors[int(rng.integers(len(motors)))]})]
    if fault == "slow":
        return [Fault(fault, name, at, {"factor": 0.5})]
    if fault == "add-robot":
        newcomer = "newcomer"
        return [Fault(fault, newcomer, at, {"kind": NEWCOMER[mission]})]
    return [Fault(fault, name, at)]


def spec_of(faults: list[Fault]) -> str:
    """The faults as ``--fault`` specs, joined by spaces: the run is ``teamsim run MISSION --fault ...``."""
    return " ".join(f"{f.kind}:{f.robot}@{f.time:g}" + "".join(f",{k}={v}" for k, v in f.options.items())
                    for f in faults)


def trial_configs(study: RobustnessStudy) -> list[TrialConfig]:
    from teamsim.tasks import MISSIONS as REGISTRY

    configs = []
    for mission, fault in cells(study):
        for seed in study.seeds:
            config = TrialConfig(mission=mission, params=REGISTRY[mission].Params(), seed=seed,
                                 duration=study.duration, out=str(study.out / "trials"),
                                 run_id=f"{fault}-s{seed}", faults=faults_of(study, mission, fault, seed))
            for assignment in SETTINGS.get(mission, ()):
                apply_setting(config, assignment)
            config.video.fps = 2  # the trajectory of a study run is for inspection, not for video
            configs.append(config)
    return configs


# -- one run, measured in its worker ---------------------------------------------------------------------------------
def end_motion(run_dir: Path, window: float = MOTION_WINDOW_S) -> dict[str, float]:
    """Metres each robot travelled (x-y path) over the last ``window`` simulated seconds of a run, from its
    trajectory.npz; {} when there is none (physics-free runs)."""
    import mujoco

    path = run_dir / "trajectory.npz"
    if not path.exists():
        return {}
    data = np.load(path)
    times, qpos = data["time"], data["qpos"]
    if len(times) < 2:
        return {}
    model = mujoco.MjModel.from_xml_string(str(data["model_xml"]))
    last = times >= times[-1] - window
    moved = {}
    for name in (str(n) for n in data["robot_names"]):
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{name}/")
        if joint < 0 or model.jnt_type[joint] != mujoco.mjtJoint.mjJNT_FREE:
            continue
        xy = qpos[last][:, model.jnt_qposadr[joint]:model.jnt_qposadr[joint] + 2]
        moved[name] = round(float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum()), 2)
    return moved


def run_measured(config: TrialConfig) -> dict:
    """Run one trial (in a worker) and keep what the study needs of its summary: status, times, error, metrics,
    which robots were working at the end, and how far each moved in the last minute."""
    from teamsim.runner import run_trial

    result = run_trial(config, progress=False)
    summary = result.summary
    robots = summary.get("robots") or {}
    return {"status": summary["status"], "completed": summary.get("completed", False), "error": summary.get("error"),
            "sim_time_s": summary.get("sim_time_s"), "duration_s": summary.get("duration_s"),
            "wall_time_s": summary.get("wall_time_s"),  # (kept in the journal, for costing; never in the report)
            "metrics": summary.get("metrics") or {}, "run_id": summary.get("run_id"),
            "working": sorted(n for n, r in robots.items() if r.get("alive", True) and r.get("joined", True)),
            "moved_m": end_motion(result.run_dir) if summary["status"] == "failed" else {}}


# -- causes ----------------------------------------------------------------------------------------------------------
def work_left(mission: str, metrics: dict) -> str:
    """What a mission's metrics say was left undone."""
    m = metrics
    if mission == "hazardous-waste":
        return f"{m.get('pucks_at_goal')} of {m.get('target')} pucks at the goal"
    if mission == "box-pushing":
        return f"box advanced {m.get('advance_m', 0.0):.2f} m of 3 m ({m.get('pushes')} pushes)"
    if mission == "explore":
        status = m.get("status") or {}
        return (f"{m.get('explored_share', 0.0):.0%} explored; environments "
                + ", ".join(f"{k} {v}" for k, v in status.items()))
    if mission == "janitorial":
        return (f"cans {m.get('cans_emptied')}/{m.get('cans')}, objects dusted {m.get('objects_dusted')}/"
                f"{m.get('objects')}, floor {m.get('floor_cleaned', 0.0):.0%} cleaned")
    if mission == "bounding-overwatch":
        return (f"{m.get('bounds_completed')} bounds completed (groups {m.get('groups')}, leaders "
                f"{m.get('leaders')})")
    if mission == "formation":
        return (f"the line did not settle at the route's end (turned round {m.get('turned_round_s')} s, order "
                f"broken {m.get('order_broken_s')} s)")
    if mission == "navigate":
        return f"goal not reached ({m.get('failure') or 'no failure kind'}, {m.get('path_length')} m driven)"
    return "the mission's verdict was failure"


def _manager_lost(faults: tuple[tuple[str, str], ...], roles: dict) -> str | None:
    """The robot holding exploration's manager role that a kill or remove took, if one did."""
    return next((robot for kind, robot in faults if kind in ("kill", "remove")
                 and (robot.lstrip("@") == "manager" or "manager" in roles.get(robot, ()))), None)


def cause_of(mission: str, result: dict, faults: tuple[tuple[str, str], ...] = ()) -> tuple[str, str]:
    """(class, one-line cause) of a run that did not complete, from its measured result and the faults it ran under
    ((kind, robot) each); ("", "") if it did."""
    status = result.get("status")
    error = result.get("error") or ""
    if status == "completed":
        return "", ""
    if status == "unstable":
        return "physics instability", error
    if status == "error":
        return "exception (a bug)", error
    if status == "crashed":
        return "worker crash", error
    if status == "interrupted":
        return "interrupted", error
    metrics = result.get("metrics") or {}
    left = work_left(mission, metrics)
    kinds = tuple(kind for kind, _ in faults)
    if mission == "explore" and (manager := _manager_lost(faults, metrics.get("roles") or {})):
        return "outside the architecture", (f"{left}; the manager (M1, {manager}) was lost: feedback "
                                            "coordination and reallocation run on it (Chand §5.6), nothing stands in")
    if mission == "navigate" and metrics.get("failure") == "looping":  # teamsim.tasks.missions.looping
        looping = "disabled drive (a limp motor turns it in circles)" if "break-motor" in kinds else \
            "controller livelock"
        return looping, (f"{left}: a loop of {metrics.get('loop_diameter')} m every "
                                       f"{metrics.get('loop_period')} s")
    if mission == "navigate" and metrics.get("failure") == "stalled":
        return "time limit, robots stuck", f"{left}: its mean speed stayed near zero"
    duration, sim_time = result.get("duration_s"), result.get("sim_time_s") or 0.0
    if duration is not None and sim_time < duration - 0.5 and mission != "navigate":
        return "mission logic", f"ended at {sim_time:.0f} s of {duration:.0f} s without success: {left}"
    working = result.get("working") or []
    moved = {n: d for n, d in (result.get("moved_m") or {}).items() if n in working}
    if not working:
        return "time limit, no robot working", f"{left}; no robot left working"
    motion = ", ".join(f"{n} {d:g} m" for n, d in moved.items())
    window = f"in the last {MOTION_WINDOW_S:.0f} s"
    if not moved:
        return "time limit with work left", left
    if any(d > MOVING_M for d in moved.values()):
        return "time limit, robots moving (livelock or too slow)", f"{left}; moved {window}: {motion}"
    return "time limit, robots stuck", f"{left}; moved {window}: {motion}"


def result_row(config: TrialConfig, result: dict) -> dict:
    fault = config.run_id.rsplit("-s", 1)[0]
    cause_class, cause = cause_of(config.mission, result, tuple((f.kind, f.robot) for f in config.faults))
    sim = result.get("sim_time_s")
    return {"mission": config.mission, "fault": fault, "fault_spec": spec_of(config.faults), "seed": config.seed,
            "status": result.get("status"), "completed": bool(result.get("completed", False)),
            "sim_time_s": None if sim is None else round(float(sim), 1),
            "duration_s": result.get("duration_s"), "error": result.get("error") or "",
            "cause_class": cause_class, "cause": cause}


def run_study(study: RobustnessStudy, run=None) -> Path:
    """Run the study (``run``: how one trial is run, :func:`run_measured` unless a test says otherwise) and write
    ``results.csv`` and ``report.md`` into ``study.out``."""
    configs = trial_configs(study)
    results = run_trials(configs, workers=study.workers, run=run or run_measured,
                         journal=study.out / JOURNAL_NAME, resume=study.resume)
    rows = [result_row(c, r) for c, r in zip(configs, results)]
    study.out.mkdir(parents=True, exist_ok=True)
    write_csv(study.out / "results.csv", COLUMNS, rows)
    write_atomic(study.out / "report.md", report(study, rows).encode())
    return study.out


# -- report ----------------------------------------------------------------------------------------------------------
def _seeds_text(seeds: tuple[int, ...]) -> str:
    ordered = sorted(seeds)
    if ordered == list(range(ordered[0], ordered[-1] + 1)):
        return f"{ordered[0]}-{ordered[-1]}" if len(ordered) > 1 else str(ordered[0])
    return ", ".join(map(str, ordered))


def report(study: RobustnessStudy, rows: list[dict]) -> str:
    from teamsim.tasks import MISSIONS as REGISTRY

    durations = ", ".join(f"{m} {study.duration or REGISTRY[m].default_duration:g} s" for m in study.missions)
    lines = ["# Robustness: every mission under every fault it supports", "",
             f"Trial seeds {_seeds_text(study.seeds)}, study seed {study.seed} (fault times and robots drawn from it). "
             f"Simulated time limits: {durations}. "
             + ("explore on its kinematic backend. " if "explore" in study.missions else "")
             + "Each run's faults are in `results.csv` (`fault_spec`: `teamsim run MISSION --seed SEED --fault ...` "
               "repeats the run); its outputs are in `trials/MISSION/FAULT-sSEED/`. `error` is a bug in teamsim, "
               "never a statistic.", "",
             "| mission | fault | completed | " + " | ".join(STATUSES[1:]) + " |",
             "|---|---|---|" + "---|" * (len(STATUSES) - 1)]
    for mission, fault in cells(study):
        chosen = [r for r in rows if r["mission"] == mission and r["fault"] == fault]
        counts = Counter(r["status"] for r in chosen)
        done = counts["completed"]
        rate = f"{done}/{len(chosen)} ({done / len(chosen):.0%})" if chosen else "-"
        lines.append(f"| {mission} | {fault} | {rate} | " + " | ".join(str(counts[s] or "") for s in STATUSES[1:])
                     + " |")
    total = Counter(r["status"] for r in rows)
    lines += ["", f"All {len(rows)} runs: " + ", ".join(f"{s} {total[s]}" for s in STATUSES if total[s]) + ".", ""]
    failures = [r for r in rows if not r["completed"]]
    lines += ["## Runs that did not complete", ""]
    if not failures:
        lines.append("None.")
    classes = Counter(r["cause_class"] for r in failures)
    if failures:
        lines += ["By cause: " + ", ".join(f"{c} {n}" for c, n in classes.most_common()) + ".", ""]
    for mission, fault in cells(study):
        chosen = [r for r in failures if r["mission"] == mission and r["fault"] == fault]
        if chosen:
            lines.append(f"- **{mission}, {fault}**: " + "; ".join(
                f"seed {r['seed']} (`{r['fault_spec']}`, {r['status']} at {r['sim_time_s']} s): {r['cause_class']}: "
                f"{r['cause']}" for r in chosen))
    skipped = [(m, f) for m in study.missions for f in study.faults if not supported(m, f)]
    if skipped:
        lines += ["", "## Pairs not run", ""]
        lines += [f"- {m}, {f}: {NOT_SUPPORTED[(m, f)]}" for m, f in skipped]
    return "\n".join(lines) + "\n"


MAX_SEED, MAX_SEEDS = 2**62, 10**6  # as a study's --seed; a million runs is days of work


def seeds_from(text: str) -> tuple[int, ...]:
    """``--seeds``: N (seeds 0..N-1) or A-B (seeds A..B, both included)."""
    first, dash, last = text.strip().partition("-")
    try:
        seeds = range(int(first), int(last) + 1) if dash else range(int(first))
    except ValueError:
        raise ConfigError(f"--seeds {text!r}: a number of seeds N or a range A-B") from None
    if not seeds:
        raise ConfigError(f"--seeds {text!r}: no seeds (N >= 1, A <= B)")
    if seeds[0] < 0 or seeds[-1] >= MAX_SEED or len(seeds) > MAX_SEEDS:
        raise ConfigError(f"--seeds {text!r}: at most {MAX_SEEDS} seeds, each in [0, 2**62)")
    return tuple(seeds)


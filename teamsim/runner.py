"""The trial runner: ``run_trial(config, seed)`` runs one mission and writes its outputs (DESIGN.md, "A
trial's outputs").

A trial ends ``completed`` or ``failed`` (the mission's verdict), ``unstable`` (NaN/Inf or a MuJoCo warning
that invalidates the physics), ``error`` (a Python exception) or ``interrupted`` (Ctrl-C or SIGTERM). Whatever
the ending, the summary, the events so far and the trajectory so far are saved. Only SIGKILL (or a machine that
stops) leaves a summary saying ``running``; it names the process and host, so :func:`cut_off` can tell.
"""
from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import os
import signal
import socket
import threading
import time
import traceback
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import mujoco
import numpy as np

import teamsim
from teamsim.config import ConfigError, TrialConfig, VideoConfig, apply_setting, validate
from teamsim.faults import parse_fault
from teamsim.files import write_json
from teamsim.progress import Progress
from teamsim.recording import EventLog, MotivationRecorder, TrajectoryRecorder
from teamsim.scenario import configure, resolve, scenario_of, supports, to_data
from teamsim.tasks import MISSIONS
from teamsim.timeline import write_timeline
from teamsim.world import PhysicsUnstable, World


@dataclass(frozen=True)
class TrialResult:
    status: str
    run_dir: Path
    summary: dict

    @property
    def completed(self) -> bool:
        return self.status == "completed"


def mission_of(name: str):
    if name not in MISSIONS:
        raise ConfigError(f"unknown mission {name!r}; known: {', '.join(MISSIONS)}")
    return MISSIONS[name]


def trial_config(mission_name: str, *, scenario: Path | str | None = None, seed: int | None = None,
                 duration: float | None = None, settings: tuple | list = (), faults: tuple | list = (),
                 out: str = "renders", run_id: str | None = None, video: VideoConfig | None = None) -> TrialConfig:
    """A trial's configuration as ``teamsim run`` builds it from its arguments: ``settings`` are ``--set KEY=VALUE``
    strings and ``faults`` are ``--fault`` specs (precedence: teamsim/cli/scenario.py). Bad input raises
    ConfigError naming the field."""
    mission = mission_of(mission_name)
    config = TrialConfig(mission=mission_name, params=mission.Params(), seed=seed or 0, duration=duration,
                         out=str(out), run_id=run_id, video=video or VideoConfig())
    if scenario or supports(mission):
        return configure(mission, config, scenario, seed, duration, list(settings), list(faults))
    for assignment in settings:
        apply_setting(config, assignment)
    config.faults = [parse_fault(spec) for spec in faults]
    validate(config)
    return config


def make_run_dir(config: TrialConfig) -> Path:
    """Create ``OUT/<mission>/<run-id>/``; an unwritable OUT is a ConfigError naming it."""
    run_id = config.run_id or f"seed{config.seed}-{datetime.now(timezone.utc):%Y%m%d-%H%M%S}"
    parent = Path(config.out) / config.mission
    try:
        parent.mkdir(parents=True, exist_ok=True)
        run_dir, suffix = parent / run_id, 1
        while run_dir.exists() and any(run_dir.iterdir()):
            suffix += 1
            run_dir = parent / f"{run_id}-{suffix}"
        run_dir.mkdir(exist_ok=True)
        probe = run_dir / ".write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise ConfigError(f"--out {config.out}: not writable ({exc.strerror or exc})") from None
    return run_dir


def state_digest(world: World) -> str:
    """SHA-256 of MuJoCo's full integration state: equal digests mean bit-identical simulations."""
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.empty(mujoco.mj_stateSize(world.model, spec))
    mujoco.mj_getState(world.model, world.data, state, spec)
    return hashlib.sha256(state.tobytes()).hexdigest()


def simulate(world: World, mission, duration: float, recorder: TrajectoryRecorder, on_frame,
             on_tick=lambda sim_time: None) -> None:
    """Run the control loop to ``duration`` (or until the mission is done), calling ``on_frame()`` at every
    frame step of ``recorder`` and ``on_tick(time)`` after every control period."""
    end_step = round(duration / world.physics_dt)

    def at_frame() -> None:
        if world.step == recorder.next_step:
            on_frame()

    while world.step < end_step and not mission.done(world):
        world.tick()
        at_frame()
        tick_end = min(world.step + world.steps_per_tick, end_step)
        while world.step < tick_end:
            frame_step = recorder.next_step
            world.advance((frame_step if world.step < frame_step < tick_end else tick_end) - world.step)
            at_frame()
        on_tick(world.time)
    world.check_stable()


class Terminated(BaseException):
    """SIGTERM arrived during a trial: it ends as ``interrupted``, with every output written (as Ctrl-C does)."""


def _raise_terminated(signum, frame) -> None:
    raise Terminated()


@contextlib.contextmanager
def _sigterm_interrupts():
    """While a trial runs in the main thread, SIGTERM raises :class:`Terminated` there (else it kills the process
    with nothing saved); the previous handler comes back afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def cut_off(summary: dict) -> bool:
    """A run whose summary still says ``running`` though the process that ran it (on this machine) is gone: it was
    killed by SIGKILL or the machine stopped, and its trajectory, timeline and video were never written. A run of
    another machine cannot be told apart from a live one: False."""
    if summary.get("status") != "running" or summary.get("host") != socket.gethostname():
        return False
    try:
        os.kill(int(summary["pid"]), 0)
    except ProcessLookupError:
        return True
    except (OSError, KeyError, TypeError, ValueError):
        return False
    return False


def _in_run(filename, run_dir: Path) -> str | None:
    """The path inside the run folder of the file an OSError names (``learned/red.json``; a temporary or streaming
    file as the file it would become), or None when it names none there."""
    if not isinstance(filename, (str, bytes, os.PathLike)):
        return None
    path = Path(os.fsdecode(filename))
    path = path.with_name(path.name.removesuffix(".tmp").removesuffix(".part"))
    return path.relative_to(run_dir).as_posix() if path.is_relative_to(run_dir) else None


def _outputs(run_dir: Path) -> list[str]:
    """The files a run wrote beside its summary (none if its folder is gone)."""
    try:
        return sorted(p.name for p in run_dir.iterdir() if p.name != "summary.json")
    except OSError:
        return []


def _run_without_physics(config: TrialConfig, mission) -> TrialResult:
    """A mission's physics-free backend (``mission.run_without_physics(config, run_dir)`` returns its summary):
    the same run folder and summary.json, and whatever figures the mission draws; no video or trajectory."""
    if config.video.enabled:
        raise ConfigError("--video: a physics-free run has nothing to render; allowed with the physics backend")
    run_dir = make_run_dir(config)
    started = time.perf_counter()
    try:
        summary = mission.run_without_physics(config, run_dir)  # (it writes its figures)
        wall = time.perf_counter() - started
        summary.update(run_id=run_dir.name, wall_time_s=round(wall, 3), teamsim=teamsim.__version__,
                       real_time_factor=round(summary["sim_time_s"] / wall, 2) if wall > 0 else None,
                       faults=[f.describe() for f in config.faults], outputs=_outputs(run_dir) + ["summary.json"])
        write_json(run_dir / "summary.json", summary)
    except OSError as exc:  # a full disk, a folder gone
        name = _in_run(exc.filename, run_dir) or "its outputs"
        raise ConfigError(f"--out {run_dir}: could not write {name} ({exc.strerror or exc}); what was written "
                          "before is kept") from None
    return TrialResult(summary["status"], run_dir, summary)


def _as_struck(described: dict) -> dict:
    """A fault as the timeline marks it: on the robot a fault by role struck, when it struck (a role that stayed
    vacant is on nobody's row)."""
    if "hit" not in described:
        return described
    return {**described, "robot": described["hit"], "time": described["hit_at"]}


def run_trial(config: TrialConfig, seed: int | None = None, progress: bool | None = None) -> TrialResult:
    """Run one trial and write its outputs. ``seed`` overrides ``config.seed``. Bad configuration raises
    ConfigError before anything is written; everything after that ends in a saved summary."""
    if seed is not None:
        config = dataclasses.replace(config, seed=seed)
    validate(config)
    mission = mission_of(config.mission)
    config = resolve(config, mission)  # the mission's world as a scenario, if it describes its worlds so
    if getattr(mission, "without_physics", None) and mission.without_physics(config):
        return _run_without_physics(config, mission)
    duration = config.duration or mission.default_duration
    world = World(config, mission)
    video = None
    if config.video.enabled:
        from teamsim.video import VideoProcess, camera_id  # imports GL only when a video is asked for
        try:
            camera_id(world.model, config.video.camera)
        except ValueError as exc:
            raise ConfigError(f"video.camera: {exc}") from None
    run_dir = make_run_dir(config)
    summary = {"mission": config.mission, "seed": config.seed, "run_id": run_dir.name, "status": "running",
               "pid": os.getpid(), "host": socket.gethostname(),
               "completed": False, "duration_s": duration, "teamsim": teamsim.__version__,
               "mujoco": mujoco.__version__,
               "config": {k: v for k, v in dataclasses.asdict(config).items() if k != "scenario"},
               "scenario": to_data(scenario_of(config, mission)) if config.scenario is not None else None}
    try:  # (the folder took a probe file, yet the disk may be full or the folder gone by now)
        write_json(run_dir / "summary.json", summary)
        events = EventLog(run_dir / "events.jsonl")
    except OSError as exc:
        raise ConfigError(f"--out {run_dir}: not writable ({exc.strerror or exc})") from None
    world.record = events
    motivation = MotivationRecorder(events)
    world.record_trace = motivation
    speedup = config.video.speedup or getattr(mission, "video_speedup", 1.0)
    recorder = TrajectoryRecorder(world.xml, list(world.robots), config.video.fps, world.physics_dt, speedup)
    panel_of = None
    if config.video.enabled:
        # A mission's optional ``video_panel(world)``: an RGB uint8 image shown beside the view at every video frame,
        # or None to keep the last one; a new array when it changes, else the same one (teamsim.video.VideoProcess).
        panel_of = getattr(mission, "video_panel", None)
        video = VideoProcess(run_dir / "video.mp4", world.xml, list(world.robots), config.video.width,
                             config.video.height, config.video.camera, config.video.fps, panel=panel_of is not None)
    bar = Progress(duration, f"{config.mission} seed {config.seed}", enabled=progress)
    events({"t": 0.0, "event": "trial_start", "mission": config.mission, "seed": config.seed,
            "robots": list(world.robots)})

    def capture() -> None:
        behaviours = [r.behaviour if r.active else ("absent" if r.dormant or r.health.removed else "dead")
                      for r in world.robots.values()]  # (a removed robot is out of the arena: absent)
        recorder.capture(world.time, world.data.qpos, behaviours)
        if video is not None:
            video.write(world.time, world.data.qpos, behaviours, panel_of(world) if panel_of else None)

    status, error, completed, metrics = "running", None, False, {}
    failed_writes: list[str] = []

    def keep(name: str, write) -> None:
        """Write one output; a failed write (a full disk, a folder gone) is noted, naming the file the error names
        (timeline.svg, learned/red.json) or else ``name``, and the others still go."""
        try:
            write()
        except OSError as exc:
            failed_writes.append(f"{_in_run(exc.filename, run_dir) or name} ({exc.strerror or exc})")

    started = time.perf_counter()
    try:
        with _sigterm_interrupts():
            simulate(world, mission, duration, recorder, capture, bar.update)
        completed, metrics = mission.outcome(world)
        status = "completed" if completed else "failed"
        if hasattr(mission, "write_outputs"):  # what a mission keeps beyond the summary (learned statistics, ...)
            keep("the mission's outputs", lambda: mission.write_outputs(world, run_dir))
    except PhysicsUnstable as exc:
        status, error = "unstable", str(exc)
    except KeyboardInterrupt:
        status, error = "interrupted", "interrupted by the user"
    except Terminated:
        status, error = "interrupted", "terminated (SIGTERM)"
    except Exception as exc:  # noqa: BLE001  (any failure must still leave a summary)
        status, error = "error", f"{type(exc).__name__}: {exc}"
        keep("events.jsonl", lambda: events({"t": round(world.time, 6), "event": "exception",
                                             "traceback": traceback.format_exc()}))
    finally:
        bar.finish()
        keep("events.jsonl", lambda: events({"t": round(world.time, 6), "event": "trial_end", "status": status}))
        keep("events.jsonl", events.close)
        keep("trajectory.npz", lambda: recorder.save(run_dir / "trajectory.npz", motivation.arrays()))
        if recorder.times:
            keep("timeline.png", lambda: write_timeline(
                run_dir / "timeline.png", recorder.times, recorder.behaviour_array(), recorder.robot_names,
                [_as_struck(f) for f in world.fault_report()], motivation.series))
        video_failure = video.close() if video is not None else None
        if video_failure:
            error = f"{error}; video: {video_failure}" if error else f"video: {video_failure}"
        failed_writes = list(dict.fromkeys(failed_writes))
        if failed_writes:
            status = "error" if status in ("completed", "failed", "running") else status
            error = "; ".join(filter(None, [error, "could not write " + ", ".join(failed_writes)]))
        wall = time.perf_counter() - started
        summary.update(status=status, completed=status == "completed", error=error,
                       sim_time_s=round(world.time, 6), wall_time_s=round(wall, 3),
                       real_time_factor=round(world.time / wall, 2) if wall > 0 else None,
                       metrics=metrics, robots=world.robot_summary(), final_state_sha256=state_digest(world),
                       faults=world.fault_report(),  # (a fault by role: whom it struck, and when)
                       outputs=_outputs(run_dir))
        keep("summary.json", lambda: write_json(run_dir / "summary.json", summary))
        if failed_writes:
            raise ConfigError(f"--out {run_dir}: could not write {', '.join(dict.fromkeys(failed_writes))}; what "
                              "was written before is kept")
    return TrialResult(status, run_dir, summary)

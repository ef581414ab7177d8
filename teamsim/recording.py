"""A trial's outputs on disk, written so that a crash never leaves a half-written file.

- ``summary.json``: replaced atomically (write to a temporary file, then rename). It is first written with
  status ``running`` so even a killed process leaves a summary saying what was attempted.
- ``events.jsonl``: one JSON event per line, flushed as it happens to ``events.jsonl.part`` and renamed
  when the trial ends; after a crash the ``.part`` file holds everything up to the crash.
- ``trajectory.npz``: the state at the video rate (full ``qpos``, robot behaviours) plus the compiled scene's
  MJCF, enough to re-render the trial with no other input; written atomically at the end. For robots whose
  controller returns a motivation trace (``Command.trace``, see :mod:`teamsim.controllers.base`) it also holds
  their motivation series at the control rate (:class:`MotivationRecorder`), which ``timeline.png`` plots.

Motivation traces in ``events.jsonl``: every event of a trace is logged as it happens, as
``{"event": "motivation", "robot", "kind", "behaviour_set", "teammate", "detail"}`` (kind: activate, deactivate,
impatience, impatience_reset, acquiescence for ALLIANCE); the levels are logged as
``{"event": "motivation_sample", "robot", "threshold", "active", "m": {set: level}}`` only when they changed,
right after an event and otherwise at most once per ``SAMPLE_PERIOD`` of simulated time, which keeps the log
small (the full series is in ``trajectory.npz``).
"""
from __future__ import annotations

import io
import os
from array import array
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from teamsim.controllers.base import MotivationTrace
from teamsim.files import to_json, write_atomic

SAMPLE_PERIOD = 1.0  # s of simulated time between motivation samples in events.jsonl while nothing happens


class EventLog:
    """Append-only JSON-lines log, streamed to disk; ``close`` publishes it under its final name."""

    def __init__(self, path: Path):
        self.path = path
        self._part = path.with_name(path.name + ".part")
        self._handle = open(self._part, "w", encoding="utf-8")

    def __call__(self, event: dict) -> None:
        self._handle.write(to_json(event, sort_keys=True) + "\n")
        self._handle.flush()

    def close(self) -> None:
        if not self._handle.closed:
            self._handle.close()
            os.replace(self._part, self.path)


class TrajectoryRecorder:
    """Keeps the scene state at each video frame; a frame is a few hundred bytes of qpos, not pixels."""

    def __init__(self, xml: str, robot_names: list[str], fps: int, physics_dt: float, speedup: float = 1.0):
        self.xml = xml
        self.robot_names = robot_names
        self.fps = fps  # frames per second of video
        self.speedup = speedup  # simulated seconds per second of video
        self.physics_dt = physics_dt
        self.times: list[float] = []
        self.qpos: list[np.ndarray] = []
        self.behaviours: list[list[str]] = []

    def step_of_frame(self, frame: int) -> int:
        """The physics step at which frame ``frame`` is taken (frames sit on the nearest physics step)."""
        return round(frame * self.speedup / self.fps / self.physics_dt)

    @property
    def next_step(self) -> int:
        return self.step_of_frame(len(self.times))

    def capture(self, time: float, qpos: np.ndarray, behaviours: list[str]) -> None:
        self.times.append(time)
        self.qpos.append(qpos.copy())
        self.behaviours.append(list(behaviours))

    @property
    def frames(self) -> int:
        """Frames captured whole (a Ctrl-C inside :meth:`capture` can leave one list a frame longer)."""
        return min(len(self.times), len(self.qpos), len(self.behaviours))

    def behaviour_array(self) -> np.ndarray:
        """Behaviours as a (frames, robots) array of strings."""
        n = self.frames
        return np.array(self.behaviours[:n], dtype=str).reshape(n, len(self.robot_names))

    def save(self, path: Path, extra: dict[str, np.ndarray] | None = None) -> None:
        """Write the frames, and ``extra`` arrays under their own names (the motivation series)."""
        n = self.frames
        buffer = io.BytesIO()
        np.savez_compressed(
            buffer, model_xml=np.array(self.xml), robot_names=np.array(self.robot_names), fps=np.array(self.fps),
            speedup=np.array(self.speedup),
            time=np.array(self.times[:n]), qpos=np.array(self.qpos[:n]).reshape(n, -1),
            behaviour=self.behaviour_array(), **(extra or {}))
        write_atomic(path, buffer.getvalue())


@dataclass
class MotivationSeries:
    """One robot's motivation trace at every control tick: its behaviour sets (priority order), theta, the tick
    times, the levels (ticks x sets), the active set's index (-1: none) and the events (time, set index, kind,
    detail)."""

    sets: tuple[str, ...]
    threshold: float
    times: array = field(default_factory=lambda: array("d"))
    levels: array = field(default_factory=lambda: array("d"))  # flattened, row-major
    active: array = field(default_factory=lambda: array("i"))
    events: list[tuple[float, int, str, str]] = field(default_factory=list)

    @property
    def ticks(self) -> int:
        """Ticks recorded whole (a Ctrl-C inside the recorder can leave one array a tick longer)."""
        return min(len(self.times), len(self.levels) // max(len(self.sets), 1), len(self.active))

    def columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The whole ticks' (times, levels (ticks x sets), active set indices)."""
        n = self.ticks
        return (np.frombuffer(self.times, dtype=float)[:n],
                np.frombuffer(self.levels, dtype=float)[:n * len(self.sets)].reshape(n, len(self.sets)),
                np.frombuffer(self.active, dtype=np.int32)[:n])

    def arrays(self, prefix: str) -> dict[str, np.ndarray]:
        """The series as named arrays for ``trajectory.npz``, each name starting with ``prefix``."""
        times, sets, kinds, details = zip(*self.events) if self.events else ((), (), (), ())
        tick_times, levels, active = self.columns()
        return {f"{prefix}sets": np.array(self.sets, dtype=str), f"{prefix}threshold": np.array(self.threshold),
                f"{prefix}time": tick_times.copy(), f"{prefix}m": levels.copy(),
                f"{prefix}active": active.copy(), f"{prefix}event_time": np.array(times, dtype=float),
                f"{prefix}event_set": np.array(sets, dtype=int), f"{prefix}event_kind": np.array(kinds, dtype=str),
                f"{prefix}event_detail": np.array(details, dtype=str)}


class MotivationRecorder:
    """Records the motivation traces the world hands over (``World.record_trace``): events and throttled samples
    into the event log, the full series in memory (:class:`MotivationSeries` per robot)."""

    def __init__(self, log: Callable[[dict], None], sample_period: float = SAMPLE_PERIOD):
        self.log = log
        self.sample_period = sample_period
        self.series: dict[str, MotivationSeries] = {}
        self._logged: dict[str, tuple[float, tuple]] = {}  # robot -> (time, levels) of its last logged sample

    def __call__(self, robot: str, time: float, trace: MotivationTrace) -> None:
        series = self.series.setdefault(robot, MotivationSeries(tuple(trace.motivation), float(trace.threshold)))
        sets = series.sets  # (a restarted controller may rank the same sets in another priority order)
        if set(trace.motivation) != set(sets):
            raise ValueError(f"motivation trace of {robot}: behaviour sets changed from {list(sets)} to "
                             f"{list(trace.motivation)}")
        t = round(time, 6)
        levels = tuple(round(float(trace.motivation[s]), 6) for s in sets)
        series.times.append(time)
        series.levels.extend(levels)
        series.active.append(sets.index(trace.active) if trace.active is not None else -1)
        for event in trace.events:
            series.events.append((time, sets.index(event.behaviour_set), event.kind, event.detail))
            self.log({"t": t, "event": "motivation", "robot": robot, "kind": event.kind,
                      "behaviour_set": event.behaviour_set, "teammate": event.teammate, "detail": event.detail})
        last = self._logged.get(robot)
        due = last is None or bool(trace.events) or time - last[0] >= self.sample_period - 1e-9
        if due and (last is None or levels != last[1]):
            self.log({"t": t, "event": "motivation_sample", "robot": robot, "threshold": series.threshold,
                      "active": trace.active, "m": dict(zip(sets, levels))})
            self._logged[robot] = (time, levels)

    def arrays(self) -> dict[str, np.ndarray]:
        """Every robot's series for ``trajectory.npz``, named ``motivation/<robot>/<field>``."""
        return {name: value for robot, series in self.series.items()
                for name, value in series.arrays(f"motivation/{robot}/").items()}


def load_trajectory(path: Path) -> dict:
    with np.load(path) as npz:
        return {key: npz[key] for key in npz.files}

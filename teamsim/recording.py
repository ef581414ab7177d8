"""A trial's outputs on disk, written so that a crash never leaves a half-written file.

- ``summary.json``: replaced atomically (write to a temporary file, then rename). It is first written with
  status ``running`` so even a killed process leaves a summary saying what was attempted.
- ``events.jsonl``: one JSON event per line, flushed as it happens to ``events.jsonl.part`` and renamed
  when the trial ends; after a crash the ``.part`` file holds everything up to the crash.
- ``trajectory.npz``: the state at the video rate (full ``qpos``, robot behaviours) plus the compiled scene's
  MJCF, enough to re-render the trial with no other input; written atomically at the end.
"""
from __future__ import annotations

import io
import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np


def _jsonable(value: Any) -> Any:
    """Plain-JSON form: non-finite floats become strings ("inf"), numpy scalars become Python ones."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        items = sorted(value) if isinstance(value, (set, frozenset)) else value
        return [_jsonable(v) for v in items]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def to_json(value: Any, **kwargs) -> str:
    return json.dumps(_jsonable(value), allow_nan=False, **kwargs)


def write_atomic(path: Path, data: bytes) -> None:
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as handle:
        handle.write(data)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, path)


def write_json(path: Path, value: Any) -> None:
    write_atomic(path, (to_json(value, indent=2) + "\n").encode())


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

    def __init__(self, xml: str, robot_names: list[str], fps: int, physics_dt: float):
        self.xml = xml
        self.robot_names = robot_names
        self.fps = fps
        self.physics_dt = physics_dt
        self.times: list[float] = []
        self.qpos: list[np.ndarray] = []
        self.behaviours: list[list[str]] = []

    def step_of_frame(self, frame: int) -> int:
        """The physics step at which frame ``frame`` is taken (frames sit on the nearest physics step)."""
        return round(frame / self.fps / self.physics_dt)

    @property
    def next_step(self) -> int:
        return self.step_of_frame(len(self.times))

    def capture(self, time: float, qpos: np.ndarray, behaviours: list[str]) -> None:
        self.times.append(time)
        self.qpos.append(qpos.copy())
        self.behaviours.append(list(behaviours))

    def behaviour_array(self) -> np.ndarray:
        """Behaviours as a (frames, robots) array of strings."""
        return np.array(self.behaviours, dtype=str).reshape(len(self.times), len(self.robot_names))

    def save(self, path: Path) -> None:
        buffer = io.BytesIO()
        np.savez_compressed(
            buffer, model_xml=np.array(self.xml), robot_names=np.array(self.robot_names), fps=np.array(self.fps),
            time=np.array(self.times), qpos=np.array(self.qpos).reshape(len(self.times), -1),
            behaviour=self.behaviour_array())
        write_atomic(path, buffer.getvalue())


def load_trajectory(path: Path) -> dict:
    with np.load(path) as npz:
        return {key: npz[key] for key in npz.files}

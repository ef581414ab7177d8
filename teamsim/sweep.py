"""Run many trials: a local process pool by default, Ray when a user has a cluster (DESIGN.md, "Sweeps").

``run_trials(configs)`` runs ``run_trial`` on each configuration and returns their summaries in the same
order. Each worker is a fresh ``spawn``ed process that builds its own MjModel, MjData and renderer (GL
contexts are not fork-safe). A trial that fails still returns its summary (status ``error``/``unstable``); a
worker that dies returns a summary with status ``crashed``, so one bad trial never loses the others. Workers die
with their parent (:func:`worker_pool`): a study killed by SIGKILL leaves no trials running.

**Journal** (``journal=PATH``, issue 29): every finished trial is appended to PATH as one JSON line, flushed and
fsynced: ``{"index", "fingerprint", "trial", "config", "result"}``. With ``resume=True`` the trials already in
the journal are not run again: their results are read back, and only the missing ones run (and those whose status
was ``crashed``, ``interrupted`` or ``error``, which give no verdict on the trial; an ``error`` is a bug, perhaps
fixed since). A journal line whose fingerprint (a hash of
the trial's whole configuration but its output folder) is not that of the same trial now is refused with a
one-line :class:`JournalError` naming the first setting that differs; so is a journal that already exists when
``resume`` is not asked for (nothing is thrown away without being asked). Every result, freshly run or read back,
goes through the same JSON round trip, so a resumed sweep returns exactly what an uninterrupted one does.
"""
from __future__ import annotations

import concurrent.futures as futures
import dataclasses
import hashlib
import json
import multiprocessing
import os
import threading
import time
from collections.abc import Callable, Iterable
from pathlib import Path, PurePath

import numpy as np

from teamsim.config import ConfigError, TrialConfig
from teamsim.progress import Progress

JOURNAL_NAME = "trials.jsonl"  # a study's journal, in its --out folder
RERUN_STATUSES = ("crashed", "interrupted", "error")  # run again on resume: no verdict on the trial (error: a bug,
# perhaps fixed since)


def _run_one(config: TrialConfig) -> dict:
    from teamsim.runner import run_trial  # imported in the worker, after its GL choice

    return run_trial(config, progress=False).summary


PARENT_CHECK_S = 0.5  # how often a worker looks for its parent


def _watch_parent(parent: int) -> None:
    """Exit this worker as soon as its parent process is gone (it is then re-parented, so its parent id changes).
    Without it, a pool's spawned workers outlive a parent killed by SIGKILL and run their trials on."""
    while os.getppid() == parent:
        time.sleep(PARENT_CHECK_S)
    os._exit(1)


def _die_with_parent(parent: int) -> None:
    threading.Thread(target=_watch_parent, args=(parent,), name="teamsim-parent-watch", daemon=True).start()


def worker_pool(workers: int) -> futures.ProcessPoolExecutor:
    """A pool of ``workers`` spawned processes that end when this process ends, however it ends."""
    return futures.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                                       initializer=_die_with_parent, initargs=(os.getpid(),))


def default_workers() -> int:
    return max(1, (os.cpu_count() or 1))


# -- the journal -----------------------------------------------------------------------------------------------------
class JournalError(ConfigError):
    """A journal that does not belong to this sweep, or one that exists when resuming was not asked for."""


def _plain(value):
    """``value`` as plain JSON data (dataclasses as dicts, numpy as Python, paths as text; non-finite floats kept)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (set, frozenset)):
        return [_plain(v) for v in sorted(value)]
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, PurePath):
        return str(value)
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)


def _dumps(value) -> str:
    return json.dumps(_plain(value), allow_nan=True, separators=(",", ":"))


def config_fields(config) -> dict:
    """A trial's configuration as flat ``dotted.key -> value`` pairs, less its output folder (``out``), which
    says where a trial writes, not what it is."""
    flat: dict = {}

    def walk(prefix: str, value) -> None:
        if isinstance(value, dict) and value:
            for key, item in value.items():
                walk(f"{prefix}.{key}" if prefix else key, item)
        elif isinstance(value, list) and value and not prefix.endswith("options"):
            for k, item in enumerate(value):
                walk(f"{prefix}[{k}]", item)
        else:
            flat[prefix or "config"] = value

    plain = _plain(config)
    if isinstance(plain, dict):
        plain.pop("out", None)
    walk("", plain)
    return flat


def fingerprint(config) -> str:
    """A short hash of ``config_fields(config)``: equal for the same trial, whatever folder it writes to."""
    return hashlib.sha256(_dumps(sorted(config_fields(config).items())).encode()).hexdigest()[:16]


def _label(config) -> str:
    mission, seed, run_id = (getattr(config, name, None) for name in ("mission", "seed", "run_id"))
    return " ".join(str(p) for p in (mission, f"seed {seed}" if seed is not None else None, run_id) if p) or repr(
        config)[:60]


def _mismatch(path: Path, index: int, entry: dict, config) -> JournalError:
    old, new = entry.get("config") or {}, config_fields(config)
    keys = [k for k in list(new) + [k for k in old if k not in new] if old.get(k, "(unset)") != new.get(k, "(unset)")]
    what = (f"{keys[0]}={old.get(keys[0], '(unset)')!r} there, {new.get(keys[0], '(unset)')!r} now"
            + (f" (and {len(keys) - 1} more)" if len(keys) > 1 else "")) if keys else "a different configuration"
    return JournalError(f"{path}: trial {index} ({entry.get('trial')}) was run with {what}: resume with the same "
                        "settings, or start afresh in another --out")


def read_journal(path: Path, configs: list) -> dict[int, object]:
    """The results a journal holds for ``configs``, by index (lines whose status asks for a re-run left out). A
    last line cut short by a kill is dropped from the file; any other bad line, or one for another trial, is a
    JournalError."""
    data = path.read_bytes()
    lines = data.split(b"\n")
    tail = lines.pop()  # b"" when the file ends in a newline; else a line cut short
    results: dict[int, object] = {}
    for number, line in enumerate(lines, start=1):
        try:
            entry = json.loads(line)
            index, result = int(entry["index"]), entry["result"]
        except (ValueError, KeyError, TypeError):
            if number == len(lines) and not tail:  # the last line, written when the kill came
                lines.pop()
                break
            raise JournalError(f"{path}: line {number} is not a journal entry; start afresh in another --out") from None
        if index >= len(configs):
            raise JournalError(f"{path}: trial {index} ({entry.get('trial')}) is not in this study, which has "
                               f"{len(configs)} trials: resume with the same settings, or start afresh in another "
                               "--out")
        if entry.get("fingerprint") != fingerprint(configs[index]):
            raise _mismatch(path, index, entry, configs[index])
        status = result.get("status") if isinstance(result, dict) else None
        if status in RERUN_STATUSES:
            results.pop(index, None)
        else:
            results[index] = result
    kept = b"".join(line + b"\n" for line in lines)
    if kept != data:  # drop the cut line, so the next one starts on a line of its own
        with open(path, "wb") as handle:
            handle.write(kept)
            handle.flush()
            os.fsync(handle.fileno())
    return results


class Journal:
    """Appends one JSON line per finished trial, flushed and fsynced, so a kill loses at most the trial running."""

    def __init__(self, path: Path, configs: list, resume: bool):
        self.path, self.configs = Path(path), configs
        if self.path.exists() and self.path.stat().st_size and not resume:
            raise JournalError(f"{self.path.parent} holds trials of an earlier run ({self.path.name}): --resume "
                               f"{self.path.parent} to continue it, or another --out to start afresh")
        if resume and not self.path.exists():
            raise JournalError(f"--resume {self.path.parent}: no {self.path.name} there, nothing to resume")
        self.done = read_journal(self.path, configs) if resume else {}
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.handle = open(self.path, "a", encoding="utf-8")

    def add(self, index: int, result) -> object:
        config = self.configs[index]
        line = _dumps({"index": index, "fingerprint": fingerprint(config), "trial": _label(config),
                       "config": config_fields(config), "result": result})
        self.handle.write(line + "\n")
        self.handle.flush()
        os.fsync(self.handle.fileno())
        return json.loads(line)["result"]

    def close(self) -> None:
        self.handle.close()


# -- sweeps ----------------------------------------------------------------------------------------------------------
def _crashed(config, exc: BaseException) -> dict:
    return {"mission": getattr(config, "mission", None), "seed": getattr(config, "seed", None), "status": "crashed",
            "completed": False, "error": f"{type(exc).__name__}: {exc}"}


def run_trials(configs: Iterable[TrialConfig], workers: int | None = None, backend: str = "process",
               run: Callable[[TrialConfig], dict] | None = None, journal: Path | None = None,
               resume: bool = False) -> list[dict]:
    """Summaries of ``run(config)`` (default: ``run_trial``'s) for every configuration, in order. ``backend`` is
    "process" or "ray". ``journal``: a file that keeps each finished trial's result; ``resume``: read it and run only
    the trials it lacks (see the module's docstring)."""
    run = run or _run_one
    configs = list(configs)
    workers = workers or default_workers()
    if backend not in ("process", "ray"):
        raise ValueError(f"backend {backend!r}: allowed: process, ray")
    book = Journal(journal, configs, resume) if journal is not None else None
    results: list = [None] * len(configs)
    for k, result in (book.done if book else {}).items():
        results[k] = result
    todo = [k for k in range(len(configs)) if book is None or k not in book.done]

    def finished(k: int, result) -> None:
        results[k] = book.add(k, result) if book else result

    try:
        if backend == "ray":
            _run_on_ray(configs, todo, run, finished)
        else:
            _run_here(configs, todo, run, workers, finished, len(configs) - len(todo))
    finally:
        if book:
            book.close()
    return results


def _run_here(configs: list, todo: list[int], run, workers: int, finished, already: int) -> None:
    what = f"{len(configs)} trials on {workers} workers" + (f", {already} done before" if already else "")
    bar = Progress(len(todo), what, unit="trials done")
    if not todo:
        bar.finish()
        return
    if workers == 1:
        for done, k in enumerate(todo, start=1):
            result = run(configs[k])
            finished(k, result)
            bar.update(done)
            if isinstance(result, dict) and result.get("status") == "interrupted":
                raise KeyboardInterrupt  # Ctrl-C (or SIGTERM) ended the trial: the sweep stops too
        bar.finish()
        return
    pool = worker_pool(workers)
    try:
        pending = {pool.submit(run, configs[k]): k for k in todo}
        for done, future in enumerate(futures.as_completed(pending), start=1):
            k = pending[future]
            try:
                result = future.result()
            except Exception as exc:  # noqa: BLE001  (a dead worker must not lose the other trials)
                result = _crashed(configs[k], exc)
            finished(k, result)
            bar.update(done)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)  # queued trials stay unrun; running ones end with us
        raise
    pool.shutdown()
    bar.finish()


def _run_on_ray(configs: list, todo: list[int], run, finished) -> None:
    try:
        import ray
    except ImportError:
        raise ValueError("backend 'ray' needs Ray: pip install 'teamsim[ray]'") from None
    if not ray.is_initialized():
        ray.init()
    remote = ray.remote(run)
    pending = {remote.remote(configs[k]): k for k in todo}
    while pending:
        ready, _ = ray.wait(list(pending), num_returns=1)
        for ref in ready:
            finished(pending.pop(ref), ray.get(ref))

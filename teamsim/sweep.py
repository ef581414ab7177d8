"""Run many trials: a local process pool by default, Ray when a user has a cluster (DESIGN.md, "Sweeps").

``run_trials(configs)`` runs ``run_trial`` on each configuration and returns their summaries in the same
order. Each worker is a fresh ``spawn``ed process that builds its own MjModel, MjData and renderer (GL
contexts are not fork-safe). A trial that fails still returns its summary (status ``error``/``unstable``); a
worker that dies returns a summary with status ``crashed``, so one bad trial never loses the others. Workers die
with their parent (:func:`worker_pool`): a study killed by SIGKILL leaves no trials running.
"""
from __future__ import annotations

import concurrent.futures as futures
import multiprocessing
import os
import threading
import time
from collections.abc import Callable, Iterable

from teamsim.config import TrialConfig
from teamsim.progress import Progress


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


def run_trials(configs: Iterable[TrialConfig], workers: int | None = None, backend: str = "process",
               run: Callable[[TrialConfig], dict] | None = None) -> list[dict]:
    """Summaries of ``run(config)`` (default: ``run_trial``'s) for every configuration, in order. ``backend`` is
    "process" or "ray"."""
    run = run or _run_one
    configs = list(configs)
    workers = workers or default_workers()
    if backend == "ray":
        return _run_on_ray(configs, run)
    if backend != "process":
        raise ValueError(f"backend {backend!r}: allowed: process, ray")
    bar = Progress(len(configs), f"{len(configs)} trials on {workers} workers", unit="trials done")
    results: list[dict | None] = [None] * len(configs)
    if workers == 1:
        for k, config in enumerate(configs):
            results[k] = run(config)
            bar.update(k + 1)
        bar.finish()
        return results
    with worker_pool(workers) as pool:
        pending = {pool.submit(run, config): k for k, config in enumerate(configs)}
        for done, future in enumerate(futures.as_completed(pending), start=1):
            k = pending[future]
            try:
                results[k] = future.result()
            except Exception as exc:  # noqa: BLE001  (a dead worker must not lose the other trials)
                results[k] = {"mission": configs[k].mission, "seed": configs[k].seed, "status": "crashed",
                              "completed": False, "error": f"{type(exc).__name__}: {exc}"}
            bar.update(done)
    bar.finish()
    return results


def _run_on_ray(configs: list[TrialConfig], run: Callable[[TrialConfig], dict]) -> list[dict]:
    try:
        import ray
    except ImportError:
        raise ValueError("backend 'ray' needs Ray: pip install 'teamsim[ray]'") from None
    if not ray.is_initialized():
        ray.init()
    remote = ray.remote(run)
    return ray.get([remote.remote(config) for config in configs])

"""A sweep whose trials sleep, for tests that kill its parent: ``python -m tests.core.sweep_sleeper DIR`` runs two
trials on two workers; each worker writes its pid to DIR/worker-<k> and sleeps for a minute."""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path


def sleepy(job: tuple[str, int]) -> dict:
    folder, k = job
    part = Path(folder) / f".worker-{k}"
    part.write_text(str(os.getpid()))
    os.replace(part, Path(folder) / f"worker-{k}")  # whole or absent: the test reads it while this runs
    time.sleep(60.0)
    return {"status": "completed"}


if __name__ == "__main__":
    from teamsim.sweep import run_trials

    run_trials([(sys.argv[1], k) for k in range(2)], workers=2, run=sleepy)

"""Progress of long runs: simulated time (or trials) done of total.

On a terminal it is a one-line bar redrawn in place, with the real-time factor. Logged or piped, it writes a
plain line every ``log_every`` seconds instead (none for runs shorter than that), so a study left running under
``nohup`` or in CI still says how far it got.
"""
from __future__ import annotations

import sys
import time

SIMULATED = "s sim"  # the unit of a trial's progress, which also shows the real-time factor


class Progress:
    def __init__(self, total: float, label: str, enabled: bool | None = None, stream=None, unit: str = SIMULATED,
                 log_every: float = 60.0):
        """``enabled``: None draws on a terminal and logs elsewhere; True always draws; False stays quiet."""
        stream = stream or sys.stderr
        self.total, self.label, self.stream, self.unit = total, label, stream, unit
        self.mode = ("bar" if stream.isatty() else "log") if enabled is None else ("bar" if enabled else "off")
        self.log_every = log_every
        self.start = time.perf_counter()
        self._last = self.start if self.mode == "log" else 0.0

    def update(self, done: float) -> None:
        now = time.perf_counter()
        if self.mode == "off" or now - self._last < (0.25 if self.mode == "bar" else self.log_every):
            return
        self._last = now
        if self.mode == "bar":
            fraction = min(done / self.total, 1.0) if self.total else 1.0
            self.stream.write(f"\r{self.label} [{'#' * int(30 * fraction):<30}] {self._figures(done, now)}")
        else:
            self.stream.write(f"{self.label}: {self._figures(done, now)}\n")
        self.stream.flush()

    def _figures(self, done: float, now: float) -> str:
        elapsed = max(now - self.start, 1e-9)
        if self.unit == SIMULATED:
            return f"{done:7.1f}/{self.total:.1f} {self.unit}  {done / elapsed:6.1f}x real time"
        return f"{done:g}/{self.total:g} {self.unit}  {elapsed:.0f} s elapsed"

    def finish(self) -> None:
        if self.mode == "bar":
            self.stream.write("\n")
            self.stream.flush()

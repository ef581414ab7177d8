"""A one-line progress bar for long runs: simulated time done of total, and the real-time factor.

It draws only when standard error is a terminal; piped or logged output stays quiet.
"""
from __future__ import annotations

import sys
import time


class Progress:
    def __init__(self, total: float, label: str, enabled: bool | None = None, stream=None):
        stream = stream or sys.stderr
        self.total, self.label, self.stream = total, label, stream
        self.enabled = stream.isatty() if enabled is None else enabled
        self.start = time.perf_counter()
        self._last_draw = 0.0

    def update(self, done: float) -> None:
        now = time.perf_counter()
        if not self.enabled or now - self._last_draw < 0.25:
            return
        self._last_draw = now
        fraction = min(done / self.total, 1.0) if self.total else 1.0
        bar = "#" * int(30 * fraction)
        rtf = done / max(now - self.start, 1e-9)
        self.stream.write(f"\r{self.label} [{bar:<30}] {done:7.1f}/{self.total:.1f} s sim  {rtf:6.1f}x real time")
        self.stream.flush()

    def finish(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()

"""Infra-red range sensor model on top of MuJoCo's rangefinder (DESIGN.md, "IR model").

MuJoCo's rangefinder returns the true distance along the site's +Z axis, or -1 on a miss, and ignores its
``noise`` attribute. Following Webots' ``DistanceSensor`` lookup table, this model maps that distance to a raw
response through a calibration table ``(distance, response, noise fraction)``, adds Gaussian noise whose
standard deviation is that fraction of the response, clips and quantises it. A robot knows its own
calibration, so it converts raw readings back to range estimates by inverting the table; a raw reading of
zero means "nothing in range" and converts to ``inf``. A blinded sensor reads zero.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Shape of the default calibration, as fractions of maximum range -> response out of full scale, and the noise
# fraction at each point. Near-IR rangers respond roughly with inverse-square fall-off and get noisier with
# distance; the thesis simulators used noise of this order (Parker's about 20 %, §2.1). Assumed, not measured.
_RANGE_FRACTIONS = (0.0, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0)
_RESPONSE_FRACTIONS = (1.0, 0.8, 0.56, 0.29, 0.14, 0.05, 0.0)
_NOISE_FRACTIONS = (0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.12)


@dataclass(frozen=True)
class IRModel:
    distances: tuple[float, ...]
    responses: tuple[float, ...]
    noise_fractions: tuple[float, ...]
    resolution: float = 1.0

    def __post_init__(self):
        d, r = np.asarray(self.distances), np.asarray(self.responses)
        if len(d) < 2 or len(d) != len(r) or len(d) != len(self.noise_fractions):
            raise ValueError("IR table needs at least two rows of (distance, response, noise fraction)")
        if np.any(np.diff(d) <= 0) or np.any(np.diff(r) >= 0) or r[-1] != 0:
            raise ValueError("IR table must have increasing distances and strictly falling responses ending at 0")
        object.__setattr__(self, "_d", d)
        object.__setattr__(self, "_r", r)
        object.__setattr__(self, "_noise", np.asarray(self.noise_fractions))

    @classmethod
    def for_range(cls, max_range: float, full_scale: float = 1023.0, resolution: float = 1.0) -> "IRModel":
        """The default calibration stretched to a sensor of ``max_range`` metres and a 10-bit converter."""
        return cls(tuple(max_range * f for f in _RANGE_FRACTIONS),
                   tuple(full_scale * f for f in _RESPONSE_FRACTIONS), _NOISE_FRACTIONS, resolution)

    @property
    def max_range(self) -> float:
        return float(self._d[-1])

    def response(self, distance: np.ndarray) -> np.ndarray:
        """Noise-free response to true distances (negative = rangefinder miss)."""
        distance = np.asarray(distance, dtype=float)
        hit = (distance >= 0) & (distance < self._d[-1])
        return np.where(hit, np.interp(distance, self._d, self._r), 0.0)

    def read(self, distance: np.ndarray, noise: np.ndarray) -> np.ndarray:
        """Raw readings for true distances, given standard-normal draws ``noise`` of the same shape."""
        distance = np.asarray(distance, dtype=float)
        clean = self.response(distance)
        sigma = np.interp(distance, self._d, self._noise) * clean
        levels = np.round((clean + sigma * noise) / self.resolution)
        # Clip in quantisation levels, so a reading is always a multiple of the resolution within full scale.
        return np.clip(levels, 0.0, np.floor(self._r[0] / self.resolution)) * self.resolution

    def to_range(self, raw: np.ndarray) -> np.ndarray:
        """Range estimates (m) from raw readings, by inverting the calibration; ``inf`` where nothing is seen."""
        raw = np.asarray(raw, dtype=float)
        estimate = np.interp(raw, self._r[::-1], self._d[::-1])
        return np.where(raw > 0, estimate, np.inf)

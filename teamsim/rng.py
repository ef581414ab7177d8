"""Seeded random streams: one per robot and per subsystem, all derived from the trial seed.

A stream is named by a path such as ``("robot", "red", "ir")``. Its generator depends only on the seed and
that path, never on the order in which streams are created, so adding a robot or a subsystem leaves every
other stream's draws unchanged.
"""
from __future__ import annotations

import zlib

import numpy as np


class RandomStreams:
    def __init__(self, seed: int):
        self.seed = int(seed)

    def get(self, *path: str) -> np.random.Generator:
        key = tuple(zlib.crc32(part.encode()) for part in path)
        return np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=key))

"""Files written atomically (write to a temporary file, then rename), so a crash never leaves a half-written one:
bytes, JSON (non-finite floats as strings, numpy values as plain ones) and CSV tables."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
from pathlib import Path
from typing import Any, Iterable, Sequence

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
    """Write ``path`` whole or not at all; a failed write (a full disk) leaves the old file, and no temporary one. Its
    OSError names ``path`` when the system did not name a file (a write to a full disk)."""
    tmp = path.with_name(path.name + ".tmp")
    try:
        with open(tmp, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError) and exc.filename is None:
            exc.filename = str(path)
        raise


def write_csv(path: Path, columns: Sequence[str], rows: Iterable[dict], float_format: str | None = None) -> None:
    """A study's results table, one row per trial, written atomically. With ``float_format`` (e.g. ".6g"), floats
    are written in it and NaN as an empty cell."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(columns), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        if float_format is not None:
            row = {k: ("" if math.isnan(v) else format(v, float_format)) if isinstance(v, float) else v
                   for k, v in row.items()}
        writer.writerow(row)
    write_atomic(path, buffer.getvalue().encode())


def write_json(path: Path, value: Any) -> None:
    write_atomic(path, (to_json(value, indent=2) + "\n").encode())

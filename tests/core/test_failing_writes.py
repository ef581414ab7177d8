"""Failing writes (issue 29, part 5): a full disk or an unwritable output folder, before a run or in the middle of
one, gives one line ``teamsim: error: ...``, exit 2, and keeps what was already written, whole: a file is written
atomically (or streamed, the event log), so a failed write leaves its previous version or nothing, never half a file
and no temporary file.

The disk is simulated (:class:`Disk`): teamsim's writers (``teamsim.files``: summaries, trajectories, figures,
learned statistics; ``teamsim.recording``: the streamed event log) open and rename their files through a stand-in
that fails as a full disk (ENOSPC) or a read-only folder (EACCES) would. The tests run as root here, where chmod
does not stop writes, so a read-only folder is simulated as well as chmodded (the chmod counts when not root). The
event log filling the disk mid-run is tests/core/test_interrupted_runs.py's."""
from __future__ import annotations

import builtins
import errno
import json
import os
import stat
from pathlib import Path

import pytest

import teamsim.runner
from teamsim import files as atomic_files
from teamsim import recording
from teamsim.cli import main


class _FullFile:
    """An open file on a full disk: every write fails with ENOSPC (nothing of it lands)."""

    def __init__(self, handle):
        self._handle = handle

    def write(self, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def __getattr__(self, name):
        return getattr(self._handle, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._handle.close()


class Disk:
    """Stands in for the disk under teamsim's writers: ``full[name] = k`` lets the first ``k`` writes of the file
    ``name`` (``summary.json``, ``learned/red.json``) through and fails the later ones with ENOSPC; no file can be
    made or renamed inside ``read_only`` (EACCES) once it is set."""

    def __init__(self, monkeypatch):
        self.full: dict[str, int] = {}
        self.read_only: Path | None = None
        outer = self

        class Os:  # os, but for replace
            def __getattr__(self, name):
                return getattr(os, name)

            @staticmethod
            def replace(src, dst):
                outer.check(Path(dst))
                os.replace(src, dst)

        for module in (atomic_files, recording):
            monkeypatch.setattr(module, "open", self.open, raising=False)
            monkeypatch.setattr(module, "os", Os())
        make_dir, write_bytes = Path.mkdir, Path.write_bytes
        monkeypatch.setattr(Path, "mkdir", lambda path, *a, **k: (self.check(path), make_dir(path, *a, **k))[1])
        monkeypatch.setattr(Path, "write_bytes", lambda path, data: (self.check(path), write_bytes(path, data))[1])

    def check(self, path: Path) -> None:
        """EACCES for a file or folder made inside the read-only folder."""
        if self.read_only is not None and Path(path).resolve().is_relative_to(self.read_only.resolve()):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))

    def open(self, path, mode="r", *args, **kwargs):
        if not any(m in mode for m in "wax"):
            return builtins.open(path, mode, *args, **kwargs)
        self.check(Path(path))
        handle = builtins.open(path, mode, *args, **kwargs)
        name = next((n for n in self.full if Path(path).as_posix().removesuffix(".tmp").endswith("/" + n)), None)
        if name is None:
            return handle
        self.full[name] -= 1
        return _FullFile(handle) if self.full[name] < 0 else handle


@pytest.fixture
def disk(monkeypatch) -> Disk:
    return Disk(monkeypatch)


def run(capfd, out: Path, mission: str = "wander", *extra: str) -> tuple[int, str]:
    """``teamsim run MISSION`` for a simulated second into ``out``: (exit code, stderr)."""
    code = main(["run", mission, "--duration", "1", "--out", str(out), "--run-id", "r", *extra])
    return code, capfd.readouterr().err


def one_error_line(err: str) -> str:
    assert err.startswith("teamsim: error: ") and err.count("\n") == 1 and "Traceback" not in err, err
    return err.removeprefix("teamsim: error: ").strip()


def no_temporary_files(folder: Path) -> None:
    assert not [p for p in folder.rglob("*") if p.name.endswith((".tmp", ".write-test"))]


@pytest.fixture
def read_only_folder(tmp_path):
    """An output folder made read-only (r-x) before the run; writable again afterwards, for the clean-up."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    folder.chmod(stat.S_IRUSR | stat.S_IXUSR)
    yield folder
    folder.chmod(stat.S_IRWXU)


def test_a_read_only_output_folder_is_one_line_exit_2_before_anything_runs(disk, capfd, read_only_folder):
    disk.read_only = read_only_folder  # what chmod does for anyone but root
    code, err = run(capfd, read_only_folder)
    assert code == 2
    assert one_error_line(err) == f"--out {read_only_folder}: not writable (Permission denied)"
    assert list(read_only_folder.iterdir()) == []


def test_a_folder_turned_read_only_mid_run_keeps_the_summary_and_the_event_log(disk, capfd, tmp_path, monkeypatch):
    """Once the run simulates, its folder takes no new file and no rename: trajectory, timeline and the final
    summary cannot be written, the event log cannot take its final name. One line names them all; the summary
    written at the start (status running) and the whole event log, under its streaming name, are kept."""
    simulate = teamsim.runner.simulate

    def then_read_only(*args, **kwargs):
        disk.read_only = tmp_path / "wander" / "r"
        simulate(*args, **kwargs)
    monkeypatch.setattr(teamsim.runner, "simulate", then_read_only)
    code, err = run(capfd, tmp_path)
    run_dir = tmp_path / "wander" / "r"
    assert code == 2
    assert one_error_line(err) == (f"--out {run_dir}: could not write events.jsonl (Permission denied), "
                                   "trajectory.npz (Permission denied), timeline.png (Permission denied), "
                                   "summary.json (Permission denied); what was written before is kept")
    assert json.loads((run_dir / "summary.json").read_text())["status"] == "running"
    events = [json.loads(line) for line in (run_dir / "events.jsonl.part").read_text().splitlines()]
    assert events[0]["event"] == "trial_start" and events[-1] == {"t": 1.0, "event": "trial_end",
                                                                   "status": "completed"}
    assert sorted(p.name for p in run_dir.iterdir()) == ["events.jsonl.part", "summary.json"]


@pytest.mark.parametrize("mission, full, kept", [
    ("wander", "trajectory.npz", ["events.jsonl", "timeline.png", "timeline.svg"]),
    ("wander", "timeline.png", ["events.jsonl", "trajectory.npz"]),
    ("wander", "timeline.svg", ["events.jsonl", "timeline.png", "trajectory.npz"]),
    ("hazardous-waste", "learned/green.json", ["events.jsonl", "learned/red.json", "timeline.png", "trajectory.npz"]),
])
def test_a_full_disk_at_the_end_is_one_line_exit_2_and_keeps_the_rest(disk, capfd, tmp_path, mission, full, kept):
    """The disk is full when one output is written at the end: one line names it; the run's summary says
    ``error`` and why; the other outputs are written whole; the failed one is not there, half or temporary."""
    disk.full[full] = 0
    code, err = run(capfd, tmp_path, mission)
    run_dir = tmp_path / mission / "r"
    assert code == 2
    assert one_error_line(err) == (f"--out {run_dir}: could not write {full} (No space left on device); what was "
                                   "written before is kept")
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["status"] == "error" and summary["error"] == f"could not write {full} (No space left on device)"
    assert set(kept) <= {p.relative_to(run_dir).as_posix() for p in run_dir.rglob("*")}
    assert not (run_dir / full).exists()
    no_temporary_files(run_dir)
    assert json.loads((run_dir / "events.jsonl").read_text().splitlines()[-1])["event"] == "trial_end"


def test_a_full_disk_for_the_final_summary_keeps_the_first_one(disk, capfd, tmp_path):
    """The summary written at the start goes through; the final one does not: the first stays, whole (status
    running), beside every other output."""
    disk.full["summary.json"] = 1
    code, err = run(capfd, tmp_path)
    run_dir = tmp_path / "wander" / "r"
    assert code == 2
    assert one_error_line(err) == (f"--out {run_dir}: could not write summary.json (No space left on device); what "
                                   "was written before is kept")
    assert json.loads((run_dir / "summary.json").read_text())["status"] == "running"
    assert {"events.jsonl", "trajectory.npz", "timeline.png"} <= {p.name for p in run_dir.iterdir()}
    no_temporary_files(run_dir)


def test_a_full_disk_when_the_run_starts_is_one_line_exit_2(disk, capfd, tmp_path):
    """Even the first summary cannot be written (the folder took the empty probe file): one line, no traceback,
    nothing half-written."""
    disk.full["summary.json"] = 0
    code, err = run(capfd, tmp_path)
    run_dir = tmp_path / "wander" / "r"
    assert code == 2
    assert one_error_line(err) == f"--out {run_dir}: not writable (No space left on device)"
    assert list(run_dir.iterdir()) == []


def test_a_full_disk_in_a_physics_free_run_is_one_line_exit_2(disk, capfd, tmp_path):
    """explore's kinematic backend writes its figures itself: a full disk there is one line too, and keeps the
    figures written before."""
    disk.full["coverage.png"] = 0
    code, err = run(capfd, tmp_path, "explore", "--set", "backend=kinematic")
    run_dir = tmp_path / "explore" / "r"
    assert code == 2
    assert one_error_line(err) == (f"--out {run_dir}: could not write coverage.png (No space left on device); what "
                                   "was written before is kept")
    assert {"map.png", "map.svg"} <= {p.name for p in run_dir.iterdir()}
    no_temporary_files(run_dir)

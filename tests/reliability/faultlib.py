"""Helpers of the fault catalogue (issue 17): a CLI runner and the assertions every case makes.

Every case asserts the exit code, a message naming the file or parameter, no traceback on stderr, and
no partial or misleading output (no ``.part`` file, no output where the run was refused).
"""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from cageless.app.cli import main

REPO = Path(__file__).resolve().parents[2]
SAMPLE_LAB = REPO / "sample_data" / "lab"


@dataclass
class Run:
    """What one CLI run gave."""

    code: int
    out: str
    err: str

    @property
    def text(self) -> str:
        return self.out + self.err


def cli(capsys: pytest.CaptureFixture[str], *argv: object) -> Run:
    """Run ``cageless argv`` in-process; return its exit code and output."""
    capsys.readouterr()
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return Run(code, captured.out, captured.err)


def cli_subprocess(*argv: object, cwd: Path | None = None, timeout: float = 300) -> Run:
    """Run ``cageless argv`` in a fresh interpreter (for faults that kill or crash the process)."""
    proc = subprocess.run([sys.executable, "-m", "cageless", *map(str, argv)], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    return Run(proc.returncode, proc.stdout, proc.stderr)


def assert_clean(run: Run, code: int, *needles: str) -> None:
    """Exit ``code``, every ``needle`` in the output, and no traceback anywhere."""
    assert run.code == code, f"exit {run.code}, expected {code}\nstdout: {run.out}\nstderr: {run.err}"
    assert "Traceback" not in run.err and "Traceback" not in run.out, run.err
    for needle in needles:
        assert needle in run.text, f"{needle!r} not in output:\n{run.text}"


def parts(folder: Path) -> list[Path]:
    """Temporary ``.part`` files left anywhere under ``folder``."""
    return sorted(folder.rglob("*.part")) if folder.exists() else []


#: Report options that keep the simulation tiny: 2 ms of start-up and 3 ms of comparison.
QUICK_REPORT = ("--settle", "0.002", "--duration", "0.003", "-q")


def flip_bits(path: Path, n: int = 64, seed: int = 17) -> None:
    """Corrupt ``path`` in place: flip ``n`` bytes spread over its middle, keeping its size."""
    import numpy as np

    data = bytearray(path.read_bytes())
    rng = np.random.default_rng(seed)
    for i in rng.integers(len(data) // 8, len(data), n):
        data[int(i)] ^= 0xFF
    path.write_bytes(bytes(data))

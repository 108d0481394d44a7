"""Fixtures of the fault catalogue (issue 17): a small lab, traces, a finished report, a full disk."""

from __future__ import annotations

import errno
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from faultlib import SAMPLE_LAB  # noqa: E402


@pytest.fixture(scope="session")
def mini_lab(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A lab folder with one short video (the sample's 3000 r/min clip, 172 frames) and its conditions."""
    folder = tmp_path_factory.mktemp("mini_lab")
    shutil.copy(SAMPLE_LAB / "clip_3000rpm.mkv", folder)
    shutil.copy(SAMPLE_LAB / "conditions.csv", folder)
    return folder


@pytest.fixture
def in_process_pool(monkeypatch: pytest.MonkeyPatch) -> None:
    """Run the report's jobs in threads of this process (the fast path for tests of the workflow itself)."""
    monkeypatch.setattr("cageless.app.lab.job_pool", lambda workers=2, scheduler=None: ThreadPoolExecutor(1))


@pytest.fixture(scope="session")
def video_trace(tmp_path_factory: pytest.TempPathFactory, mini_lab: Path) -> Path:
    """A video trace of the mini lab's clip."""
    from cageless.bearing import default_bearing
    from cageless.conditions import discover_lab
    from cageless.tracking.pipeline import track_video

    out = tmp_path_factory.mktemp("video_trace")
    entry = discover_lab(mini_lab)[0]
    return track_video(entry.video, entry.resolved.conditions, default_bearing(), out_dir=out, progress=False).path


@pytest.fixture(scope="session")
def sim_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 5 ms simulation trace at the mini lab's conditions (3000 r/min, 500 N)."""
    from cageless.bearing import default_bearing
    from cageless.conditions import OperatingConditions
    from cageless.simulation.effects import choose_model
    from cageless.simulation.run import simulate
    from cageless.simulation.scene import Scene

    out = tmp_path_factory.mktemp("sim_trace") / "sim.trace.h5"
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), bearing=default_bearing(), duration_s=0.005)
    simulate(scene, choose_model(scene), out=out, progress=False)
    return out


@pytest.fixture(scope="session")
def report_template(tmp_path_factory: pytest.TempPathFactory, mini_lab: Path) -> Path:
    """A finished report of the mini lab (made once; tests copy it and re-run on the copy)."""
    from cageless.app.lab import LabOptions, run_lab

    out = tmp_path_factory.mktemp("report_template") / "report"
    mp = pytest.MonkeyPatch()
    mp.setattr("cageless.app.lab.job_pool", lambda workers=2, scheduler=None: ThreadPoolExecutor(1))
    try:
        res = run_lab(mini_lab, out, LabOptions(duration_s=0.003, settle_s=0.002), progress=False)
    finally:
        mp.undo()
    assert res.n_failed == 0, [r.message for r in res.rows]
    return out


@pytest.fixture
def full_disk(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """A folder on a full disk: a 16 kB tmpfs when this runs as root, else writes that raise ENOSPC."""
    mount = tmp_path / "full"
    mount.mkdir()
    mounted = False
    if hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("mount"):
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16k", "tmpfs", str(mount)],
                                 capture_output=True).returncode == 0
    if not mounted:
        import cageless.atomic as atomic

        def no_space(fd: int) -> None:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        monkeypatch.setattr(atomic.os, "fsync", no_space)
    try:
        yield mount
    finally:
        if mounted:
            subprocess.run(["umount", str(mount)], capture_output=True)

"""The catalogue's rows about killed runs (issue 17): workers die with their parent, and ``kill -9`` at
random moments (a fixed seed) leaves nothing that a re-run does not repair."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from faultlib import QUICK_REPORT, assert_clean, cli_subprocess, parts

from cageless.trace import read_trace


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def _children(pid: int) -> list[int]:
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.split(")")[-1].split()[1]) == pid:
                out.append(int(entry.name))
    return out


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_r41_pool_workers_die_with_their_parent(tmp_path):
    """A parent killed by SIGKILL while its worker runs a job: the worker is gone within seconds."""
    script = tmp_path / "parent.py"
    script.write_text(textwrap.dedent("""
        import os, signal, sys, time
        from cageless.parallel import job_pool
        if __name__ == "__main__":
            pool = job_pool(1)
            pool.submit(time.sleep, 120)
            time.sleep(0.5)
            while not pool._processes:
                time.sleep(0.1)
            print(*pool._processes, flush=True)
            time.sleep(3)  # the worker has taken its job
            os.kill(os.getpid(), signal.SIGKILL)
    """))
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    workers = [int(x) for x in proc.stdout.split()]
    assert workers
    deadline = time.monotonic() + 10
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(w) for w in workers), "a worker outlived its killed parent"


def test_kill_term_stops_the_pool_at_once(tmp_path):
    """``kill -TERM`` (as Ctrl-C) leaves a job pool at once: queued jobs cancelled, running ones ended.

    The standard executor's ``with`` block would first run all four 60-s jobs (two minutes); and a
    terminated run must not leave leaked-semaphore warnings behind.
    """
    script = tmp_path / "parent.py"
    script.write_text(textwrap.dedent("""
        import signal, sys, time
        from cageless.app.cli import _terminated
        from cageless.parallel import job_pool
        if __name__ == "__main__":
            signal.signal(signal.SIGTERM, _terminated)
            try:
                with job_pool(2) as pool:
                    futures = [pool.submit(time.sleep, 60) for _ in range(4)]
                    while len(pool._processes) < 2:
                        time.sleep(0.1)
                    print(*pool._processes, flush=True)
                    [f.result() for f in futures]
            except KeyboardInterrupt:
                sys.exit(130)
    """))
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    workers = [int(x) for x in proc.stdout.readline().split()]
    time.sleep(1.0)  # the workers have taken their jobs
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert time.monotonic() - t0 < 15.0
    assert len(workers) == 2 and not any(_alive(w) for w in workers)
    assert "leaked" not in err and "Traceback" not in err, err


def _kill_at(argv: list[str], delay_s: float, cwd: Path) -> list[int]:
    """Start ``cageless argv``, SIGKILL the parent only after ``delay_s``; return the pids of its children."""
    proc = subprocess.Popen([sys.executable, "-m", "cageless", *argv], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    time.sleep(delay_s)
    children = _children(proc.pid)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    return children


@pytest.mark.slow
@pytest.mark.parametrize("command", ["track", "simulate", "report"])
def test_kill_9_at_random_moments_then_rerun(tmp_path, mini_lab, command):
    """Kill at three random moments (seeded); each re-run completes, reads, and leaves no temporary file."""
    rng = np.random.default_rng(1717)
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    out = tmp_path / "out"
    argv = {
        "track": ["track", str(lab), "-o", str(out), "-q"],
        "simulate": ["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "0.01", "-q",
                     "-o", str(out / "sim.trace.h5")],
        "report": ["report", str(lab), "-o", str(out), *QUICK_REPORT],
    }[command]
    for delay in rng.uniform(1.0, 12.0, size=3):
        children = _kill_at(argv, float(delay), tmp_path)
        deadline = time.monotonic() + 10
        while any(_alive(c) for c in children) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not any(_alive(c) and "spawn_main" in Path(f"/proc/{c}/cmdline").read_text() for c in children
                       if _alive(c))
        time.sleep(2.5)  # temporary files of the killed run are now old enough to count as abandoned
        run = cli_subprocess(*argv, cwd=tmp_path)
        assert_clean(run, 0)
        assert not parts(out)
        for trace in out.rglob("*.trace.h5"):
            read_trace(trace)

"""Where independent jobs run: local spawned processes on both cores, or an existing Dask cluster.

Both executors offer ``submit(fn, *args)`` returning a future with ``result()``, so callers do not
care which one they got (nothing home-made stands in for a scheduler). Local workers are
spawned, not forked: numba's thread pool does not survive a fork.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import Any

from tqdm.auto import tqdm

from cageless.errors import CagelessError

__all__ = ["job_pool", "gather", "die_with_parent"]


def job_pool(workers: int = 2, scheduler: str | None = None) -> Any:
    """A context-managed executor: a ``distributed.Client`` for ``scheduler``, else ``workers`` processes."""
    if scheduler:
        from distributed import Client

        try:
            return Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise CagelessError(f"--scheduler {scheduler}: cannot reach the Dask scheduler ({exc}). Check the "
                                "address and that the scheduler is running, or leave out --scheduler.") from None
    return _LocalPool(max_workers=max(1, workers), mp_context=get_context("spawn"),
                      initializer=die_with_parent, initargs=(os.getpid(),))


class _LocalPool(ProcessPoolExecutor):
    """A process pool that, left by an exception (Ctrl-C, ``kill -TERM``, an error), stops at once.

    The standard executor's ``with`` block waits for every queued job before it lets the exception
    through; this one cancels the queued jobs and ends the running ones, which write nothing partial
    (outputs are atomic), so an interrupted run stops in about a second.
    """

    def __exit__(self, exc_type: Any, exc_val: Any, exc_tb: Any) -> bool:
        if exc_type is None:
            return bool(super().__exit__(exc_type, exc_val, exc_tb))
        processes = list((getattr(self, "_processes", None) or {}).values())
        self.shutdown(wait=False, cancel_futures=True)
        for proc in processes:
            proc.terminate()
        for proc in processes:
            proc.join(timeout=5.0)
        self.shutdown(wait=True)  # the pool is broken now: this only joins its threads and frees its queues
        return False


def die_with_parent(parent_pid: int) -> None:
    """Worker initializer: end this process when its parent dies (even by ``kill -9``).

    On Linux the kernel sends SIGKILL on the parent's death (``prctl(PR_SET_PDEATHSIG)``); everywhere,
    a daemon thread also checks once a second that the parent is still there. Ctrl-C is the parent's to
    handle: a worker ignores SIGINT (an idle worker would otherwise print a traceback), and ends with its
    parent.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # tqdm's default lock is a multiprocessing semaphore: a worker ended by an interrupted run could not
    # release it, and Python would warn of a leaked semaphore. A worker's bars need only a thread lock.
    tqdm.set_lock(threading.RLock())
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):  # pragma: no cover - no libc prctl
            pass
    if os.getppid() != parent_pid:  # the parent died before the line above took effect
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(1.0)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="cageless-parent-watch", daemon=True).start()


def gather(futures: Sequence[Any], desc: str, progress: bool = True) -> list[Any]:
    """The futures' results in submission order, with a progress bar over them."""
    return [f.result() for f in tqdm(futures, desc=desc, disable=not progress or not futures, leave=False)]

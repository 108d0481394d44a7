"""Where independent jobs run: local spawned processes on both cores, or an existing Dask cluster.

Both executors offer ``submit(fn, *args)`` returning a future with ``result()``, so callers do not
care which one they got (DESIGN §10: nothing home-made stands in for a scheduler). Local workers are
spawned, not forked: numba's thread pool does not survive a fork.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import Any

from tqdm.auto import tqdm

__all__ = ["job_pool", "gather"]


def job_pool(workers: int = 2, scheduler: str | None = None) -> Any:
    """A context-managed executor: a ``distributed.Client`` for ``scheduler``, else ``workers`` processes."""
    if scheduler:
        from distributed import Client

        return Client(scheduler)
    return ProcessPoolExecutor(max_workers=max(1, workers), mp_context=get_context("spawn"))


def gather(futures: Sequence[Any], desc: str, progress: bool = True) -> list[Any]:
    """The futures' results in submission order, with a progress bar over them."""
    return [f.result() for f in tqdm(futures, desc=desc, disable=not progress or not futures, leave=False)]

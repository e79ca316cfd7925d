"""Thread pools for work that releases the GIL (compiled kernels, decompression), one per process, use and size."""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

__all__ = ["shared_pool"]

_POOLS: dict[tuple[int, str, int], ThreadPoolExecutor] = {}
_LOCK = threading.Lock()


def shared_pool(threads: int, purpose: str = "kernel") -> ThreadPoolExecutor:
    """A pool of ``threads`` worker threads, made once per process and kept (kernels run on it chunk after chunk).

    Parameters
    ----------
    threads : int
        Worker threads, at least 1.
    purpose : str
        Name of the pool's use: work of one purpose never waits in the queue behind another's
        (e.g. decompressing the next chunk of a file and parsing this one).

    Returns
    -------
    concurrent.futures.ThreadPoolExecutor
    """
    if threads < 1:
        raise ValueError(f"threads must be at least 1, got {threads}")
    key = (os.getpid(), purpose, threads)  # a forked process makes its own
    with _LOCK:
        if key not in _POOLS:
            _POOLS[key] = ThreadPoolExecutor(max_workers=threads, thread_name_prefix=f"greybox-{purpose}")
        return _POOLS[key]

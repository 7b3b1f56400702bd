"""One BLAS/LAPACK thread while an analysis runs.

mbdsim's dense linear algebra works on small matrices (a few hundred rows at most; large models go
through sparse or recursive O(N) paths), where a multi-threaded BLAS only adds synchronisation, and
where it is catastrophic when the cores are shared (two study workers, or other processes, on a
2-core machine: a 160 x 224 QR measured 0.5 s instead of 1 ms). Each analysis therefore runs with
one BLAS thread (threadpoolctl, restored afterwards; about 20 us per call). Set the environment
variable MBDSIM_BLAS_THREADS to another number, or to 0 to leave the BLAS settings alone.
"""
from __future__ import annotations

import contextlib
import functools
import os

_controller = None


def _limit():
    """Context manager limiting BLAS threads for the duration of an analysis."""
    global _controller
    n = int(os.environ.get("MBDSIM_BLAS_THREADS", "1") or 0)
    if n <= 0:
        return contextlib.nullcontext()
    if _controller is None:
        try:
            from threadpoolctl import ThreadpoolController
            _controller = ThreadpoolController()
        except Exception:   # threadpoolctl missing or no BLAS found: run as is  # pragma: no cover
            _controller = False
    if not _controller:
        return contextlib.nullcontext()
    return _controller.limit(limits=n, user_api="blas")


def blas_single_thread(fn):
    """Decorator: run `fn` with MBDSIM_BLAS_THREADS (default 1) BLAS threads."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with _limit():
            return fn(*args, **kwargs)
    return wrapper

"""One BLAS/LAPACK thread while an analysis runs.

mbdsim's dense linear algebra works on small matrices (a few hundred rows at most; large models go
through sparse or recursive O(N) paths), where a multi-threaded BLAS only adds synchronisation, and
where it is catastrophic when the cores are shared (two study workers, or other processes, on a
2-core machine: a 160 x 224 QR measured 0.5 s instead of 1 ms). Each analysis therefore runs with
one BLAS thread (threadpoolctl, restored afterwards; 50-100 us per call). A limit inside a limit of
the same thread (an analysis run by a study chunk, an assembly inside a simulate) is a no-op. Set the
environment variable MBDSIM_BLAS_THREADS to another number, or to 0 to leave the BLAS settings alone.

threadpoolctl limits the libraries loaded when it looks: scipy.linalg is imported on first use (it
costs ~0.3 s at start-up and a simple model never needs it) and brings its own BLAS, so the modules
that use it get it from `scipy_linalg()`, which limits that BLAS too when the import happens inside
an analysis, and later analyses see it. A low-level module (below system and solvers): any layer may
import it.
"""
from __future__ import annotations

import contextlib
import functools
import importlib
import os
import sys
import threading

_controller = None
_scanned_with_scipy = False   # whether scipy.linalg (and its BLAS) was loaded when _controller looked
_held = threading.local()   # .depth: limits entered and not yet left by this thread; .extra: limits of
#                             libraries loaded inside them, left before the outer one


def _threads() -> int:
    return int(os.environ.get("MBDSIM_BLAS_THREADS", "1") or 0)


def _get_controller(rescan: bool = False):
    """threadpoolctl's controller of the loaded BLAS libraries (False without threadpoolctl)."""
    global _controller, _scanned_with_scipy
    if _controller is None or (rescan and _controller is not False):
        _scanned_with_scipy = "scipy.linalg" in sys.modules
        try:
            from threadpoolctl import ThreadpoolController
            _controller = ThreadpoolController()
        except Exception:   # threadpoolctl missing or no BLAS found: run as is  # pragma: no cover
            _controller = False
    return _controller


@contextlib.contextmanager
def _counted(limit):
    """The outermost `limit` of this thread entered (`_limit` makes inner ones no-ops), with the depth
    counted around it; limits added inside it by `lazy_import` are left first."""
    _held.depth, _held.extra = 1, []
    try:
        with limit:
            try:
                yield
            finally:
                while _held.extra:
                    _held.extra.pop().__exit__(None, None, None)
    finally:
        _held.depth = 0


def _limit():
    """Context manager limiting BLAS threads for the duration of an analysis."""
    n = _threads()
    if n <= 0 or getattr(_held, "depth", 0):
        return contextlib.nullcontext()
    controller = _get_controller(rescan=not _scanned_with_scipy and "scipy.linalg" in sys.modules)
    if controller is False:
        return contextlib.nullcontext()
    return _counted(controller.limit(limits=n, user_api="blas"))


def lazy_import(name: str):
    """The module `name` (a scipy module: 'scipy.linalg', 'scipy.sparse.linalg', ...), imported on first
    use; when the import loads scipy.linalg's BLAS inside an analysis, that BLAS is limited at once
    (and restored with the analysis' own limit), and every later limit includes it."""
    module = sys.modules.get(name)
    if module is not None:
        return module
    fresh = "scipy.linalg" not in sys.modules
    module = importlib.import_module(name)
    if fresh and "scipy.linalg" in sys.modules and _controller is not None:
        controller = _get_controller(rescan=True)
        n = _threads()
        if controller is not False and n > 0 and getattr(_held, "depth", 0):
            _held.extra.append(controller.limit(limits=n, user_api="blas"))
    return module


def scipy_linalg():
    """scipy.linalg through `lazy_import`."""
    return lazy_import("scipy.linalg")


def blas_single_thread(fn):
    """Decorator: run `fn` with MBDSIM_BLAS_THREADS (default 1) BLAS threads."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with _limit():
            return fn(*args, **kwargs)
    return wrapper

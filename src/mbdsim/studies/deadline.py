"""The per-variant time limit of a study (`analysis.time_limit` [s] of wall time).

A watchdog timer raises `_VariantTimeout` in the thread running the variant (CPython's
PyThreadState_SetAsyncExc) once the limit has passed. It is a KeyboardInterrupt, so every place that
already ends a run cleanly on Ctrl-C ends it on the limit too: the compiled step loop between its
chunks, a Python callable called back from it, the reference path; the analysis returns its
outputs so far (success False) or the exception reaches `run_variant`, which turns either into a
'failed' row naming the limit. It is delivered when the thread next runs Python code: a variant stuck
inside one call into C that never returns (none of mbdsim's kernels: they return every chunk of
steps) is not stopped.
"""
from __future__ import annotations

import ctypes
import threading
from contextlib import contextmanager


class _VariantTimeout(KeyboardInterrupt):
    """Raised in a study variant's thread when its time limit has passed (see the module docstring)."""


class _Watch:
    def __init__(self):
        self.fired = False
        self.active = True


def _raise_in(thread_id: int, exc) -> int:
    return ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id),
                                                      ctypes.py_object(exc) if exc is not None else None)


@contextmanager
def time_limit(seconds: float | None):
    """Run the block with a watchdog: after `seconds` [s] of wall time _VariantTimeout is raised in this
    thread (None: no limit). Yields the watch: `.fired` tells whether the limit ended the block."""
    watch = _Watch()
    if seconds is None:
        yield watch
        return
    lock, tid = threading.Lock(), threading.get_ident()

    def fire():
        with lock:
            if watch.active:
                watch.fired = True
                _raise_in(tid, _VariantTimeout)

    timer = threading.Timer(float(seconds), fire)
    timer.daemon = True
    timer.start()
    try:
        yield watch
    finally:
        with lock:
            watch.active = False
        timer.cancel()
        if watch.fired:
            _raise_in(tid, None)   # a limit that fired as the block ended: nothing left pending here

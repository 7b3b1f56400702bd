"""`progress=True`: a rich progress bar of the analysis time reached, on stderr.

`simulate`, `kinematics` and `quasi_static` take `progress` as False (nothing), a callable progress(t) of
the time reached [s] (the user's own reporting), True (this bar: "<label> ━━━  t = 0.42 s 0:00:03") or
None, the default: in a terminal or a notebook the bar appears once the run has taken DELAY = 2 s of
wall time (the runs expected to take more than a few seconds), elsewhere nothing. A call stores the time reached and hands it to the bar at most REFRESH_HZ times per second
(its cost per solver report is a clock read and a comparison); rich redraws at the same rate and
removes the bar at the end (transient) in a terminal; it draws nothing where stderr is not a terminal. The command line
(`mbdsim run`, `kinematics`, `statics`) uses the same bar.
"""
from __future__ import annotations

import contextlib
import sys
import time
from typing import Any, Iterator

from .errors import ModelError

REFRESH_HZ = 10.0      # redraws per second, at most
DELAY = 2.0            # [s] of wall time before the default bar (progress=None) appears


def interactive() -> bool:
    """True in a terminal (stderr is a TTY) or in a Jupyter kernel: where the default shows a bar."""
    return sys.stderr.isatty() or "ipykernel" in sys.modules


class ProgressBar:
    """Callable progress(t) drawing a rich bar from start to end [s]; use it as a context manager
    (`with ProgressBar("simulating", 0.0, 2.0) as bar: ...`); `console`: a rich Console (default stderr)."""

    def __init__(self, label: str, start: float, end: float, console: Any = None) -> None:
        from rich.console import Console
        from rich.markup import escape
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
        self.start, self.end = float(start), float(end)
        console = console or Console(stderr=True, highlight=False,
                                     width=None if sys.stderr.isatty() else 120)
        self._bar = Progress(TextColumn(escape(label)), BarColumn(), TextColumn("t = {task.fields[t]:.4g} s"),
                             TimeElapsedColumn(), console=console, transient=True,
                             refresh_per_second=REFRESH_HZ, auto_refresh=True)
        span = self.end - self.start
        self._task = self._bar.add_task(label, total=span if span > 0 else 1.0, t=self.start)
        self.t, self._last, self.updates = self.start, -float("inf"), 0

    def __enter__(self) -> "ProgressBar":
        self._bar.start()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._update()
        self._bar.stop()

    def __call__(self, t: float) -> None:
        """Record the time reached t [s]; the bar takes it at most REFRESH_HZ times per second."""
        self.t = float(t)
        now = time.monotonic()
        if now - self._last >= 1.0 / REFRESH_HZ:
            self._last = now
            self._update()

    def _update(self) -> None:
        done = min(max(self.t - self.start, 0.0), self.end - self.start)
        self._bar.update(self._task, completed=done, t=self.t, refresh=False)
        self.updates += 1


class DelayedBar:
    """The default (progress=None) in a terminal or notebook: a ProgressBar that appears once the analysis
    has run DELAY s of wall time (the runs expected to take more than a few seconds), nothing before."""

    def __init__(self, label: str, start: float, end: float) -> None:
        self.args, self.t0, self.bar = (label, start, end), time.monotonic(), None

    def __call__(self, t: float) -> None:
        if self.bar is None:
            if time.monotonic() - self.t0 < DELAY:
                return
            self.bar = ProgressBar(*self.args).__enter__()
        self.bar(t)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)


@contextlib.contextmanager
def progress_of(progress: Any, entity: str, label: str, start: float, end: Any) -> Iterator[Any]:
    """The progress argument an analysis passes on: None for False (and for None outside a terminal or
    notebook), the user's callable as it is, for True a ProgressBar from start to end [s], shown while the
    block runs, and for None in a terminal or notebook a DelayedBar (shown after DELAY s). Anything else is a
    ModelError naming `entity`.progress (before any work)."""
    if progress is None and interactive():
        delayed = DelayedBar(label, *_times(start, end))
        try:
            yield delayed
        finally:
            delayed.close()
    elif progress is None or progress is False:
        yield None
    elif progress is True:
        with ProgressBar(label, *_times(start, end)) as bar:
            yield bar
    elif callable(progress):
        yield progress
    else:
        raise ModelError(entity, "progress", f"expected True, False, None or a callable progress(t) of the time "
                         f"reached [s], got {progress!r}")


def _times(start: Any, end: Any) -> tuple[float, float]:
    """(start, end) [s] as floats; bad times are the analysis's own error, raised inside the block."""
    try:
        return float(start), float(end)
    except (TypeError, ValueError):
        return 0.0, 1.0

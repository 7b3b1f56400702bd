"""`progress=True`: a rich progress bar of the analysis time reached, on stderr.

`simulate`, `kinematics` and `quasi_static` take `progress` as None / False (nothing), a callable
progress(t) of the time reached [s] (the user's own reporting), or True (this bar: "<label> ━━━  t = 0.42 s
0:00:03"). A call stores the time reached and hands it to the bar at most REFRESH_HZ times per second
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


@contextlib.contextmanager
def progress_of(progress: Any, entity: str, label: str, start: float, end: Any) -> Iterator[Any]:
    """The progress argument an analysis passes on: None for None / False, the user's callable as it
    is, or for True a ProgressBar from start to end [s], shown while the block runs. Anything else is a
    ModelError naming `entity`.progress (before any work)."""
    if progress is None or progress is False:
        yield None
    elif progress is True:
        try:
            start, end = float(start), float(end)
        except (TypeError, ValueError):   # bad times are the analysis's own error, raised inside the block
            start, end = 0.0, 1.0
        with ProgressBar(label, start, end) as bar:
            yield bar
    elif callable(progress):
        yield progress
    else:
        raise ModelError(entity, "progress", f"expected True, False, None or a callable progress(t) of the time "
                         f"reached [s], got {progress!r}")

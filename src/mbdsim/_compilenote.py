"""Say so when the compiled kernels are being compiled: one line on stderr, and a bar in a terminal or
notebook (issue 32: a first run that waited minutes in silence looked broken).

numba reports every compilation as a "numba:compile" event. `CompileNote` listens to those of mbdsim's
kernels: when a compilation (with the kernels it calls) is still going after DELAY = 2 s, it prints

    mbdsim: compiling the numba kernels this analysis uses (once per mbdsim version and machine,
    cached in ~/.cache/mbdsim/numba/...; about 40 s)

(once per process) and, where `mbdsim._progress.interactive()` (a terminal or a Jupyter kernel), shows a
transient bar of the kernels compiled while each compilation lasts. The estimate is that of the last
compilation of the same kernel on this machine that compiled the most kernels (kept in `base_dir()/compile-times.json`, whatever the
version), else ESTIMATE_S. Set MBDSIM_QUIET_COMPILE=1 to silence it. Nothing is printed for loads from the
cache (a fraction of a second).
"""
from __future__ import annotations

import json
import os
import sys
import threading
import time
from pathlib import Path

from numba.core import event

DELAY = 2.0          # [s] of compilation before the note appears
# [s] a cold compilation of the step loop (fastdop.run and what it calls) on a 2-core machine, when this
# machine has no record yet: the README pendulum's first simulate on an empty cache took 48 s of CPU, 73 s
# wall on the shared 2-core VM at load 3 (issue 32 after Slots and link-only kernels; bench/RESULTS.md)
ESTIMATE_S = 50.0


def _times_file() -> Path:
    from ._jitcache import base_dir
    return Path(base_dir()) / "compile-times.json"


def _load_times() -> dict:
    try:
        return json.loads(_times_file().read_text())
    except (OSError, ValueError):
        return {}


def _save_time(name: str, seconds: float, count: int) -> None:
    """Record the compilation of `name` that compiled `count` kernels in `seconds`, unless an earlier one
    compiled more (a compilation whose callees were cached is no estimate for a full one: it said
    "about 3 s" before minutes of compiling after an edit of the kernels)."""
    try:
        times = _load_times()
        if count < times.get(name, (0.0, 0))[1]:
            return
        times[name] = [round(seconds, 1), count]
        path = _times_file()
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}")
        tmp.write_text(json.dumps(times, indent=1, sort_keys=True))
        os.replace(tmp, path)
    except OSError:   # a read-only cache: no record, only the default estimate next time
        pass


def _name(ev) -> str | None:
    """'module.qualname' of an mbdsim kernel's compile event, else None."""
    f = getattr(ev.data.get("dispatcher"), "py_func", None)
    module = getattr(f, "__module__", "") or ""
    if not module.startswith("mbdsim."):
        return None
    return module[len("mbdsim."):] + "." + f.__qualname__


class CompileNote(event.Listener):
    """The listener (one per process, installed by `install`); `stream` is where the lines go (stderr)."""

    def __init__(self, stream=None) -> None:
        self.stream = stream
        self.depth, self.count, self.top, self.t0 = 0, 0, None, 0.0
        self.timer, self.bar, self.shown, self.said = None, None, False, False
        self.lock = threading.Lock()

    def on_start(self, ev) -> None:
        name = _name(ev)
        if name is None:
            return
        with self.lock:
            if self.depth == 0:
                self.top, self.t0, self.count, self.shown = name, time.monotonic(), 0, False
                self.timer = threading.Timer(DELAY, self._show)
                self.timer.daemon = True
                self.timer.start()
            self.depth += 1

    def on_end(self, ev) -> None:
        if _name(ev) is None:
            return
        with self.lock:
            self.depth -= 1
            self.count += 1
            if self.bar is not None:
                self.bar.update(self.task, completed=self.count)
            if self.depth > 0:
                return
            if self.timer is not None:
                self.timer.cancel()
            seconds = time.monotonic() - self.t0
            self.timer = None
            self._close_bar()
        if seconds >= DELAY:
            _save_time(self.top, seconds, self.count)

    def _estimate(self) -> tuple[float, int | None]:
        seconds, count = _load_times().get(self.top, (ESTIMATE_S, None))
        return float(seconds), count

    def _show(self) -> None:
        with self.lock:
            if self.depth == 0:
                return
            self.shown = True
            seconds, count = self._estimate()
            from ._jitcache import CACHE_DIR
            if not self.said:   # one line per process; a terminal also gets the bar of each compilation
                self.said = True
                self._print(f"mbdsim: compiling the numba kernels this analysis uses (once per mbdsim version and "
                            f"machine, cached in {CACHE_DIR}); about {seconds:.0f} s")
            self._open_bar(count)

    def _print(self, line: str) -> None:
        stream = self.stream or sys.stderr
        try:
            print(line, file=stream, flush=True)
        except (OSError, ValueError):   # a closed stream: the note is not worth an error
            pass

    def _open_bar(self, total) -> None:
        from ._progress import interactive
        if self.stream is not None or not interactive():
            return
        try:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
            bar = Progress(TextColumn("compiling kernels"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                           transient=True)
            self.task = bar.add_task("compiling", total=total, completed=self.count)
            bar.start()
            self.bar = bar
        except Exception:  # noqa: BLE001 - another live display (the validate bar) is up: the line is enough
            self.bar = None

    def _close_bar(self) -> None:
        if self.bar is not None:
            try:
                self.bar.stop()
            except Exception:  # noqa: BLE001
                pass
            self.bar = None


_NOTE: CompileNote | None = None


def install() -> CompileNote | None:
    """Register the process's CompileNote with numba (once); None when MBDSIM_QUIET_COMPILE is set."""
    global _NOTE
    if _NOTE is None and not os.environ.get("MBDSIM_QUIET_COMPILE"):
        _NOTE = CompileNote()
        event.register("numba:compile", _NOTE)
    return _NOTE

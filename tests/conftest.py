"""Suite-wide set-up: with pytest-xdist, the controller fills the compiled-kernel cache before the workers
start (mbdsim._warmup: two processes compiling different kernels side by side), so that the workers load
the kernels instead of each compiling the same ones (issue 32). A warm cache makes this a second or two;
MBDSIM_NO_WARMUP=1 skips it."""
from __future__ import annotations

import os
import sys


def pytest_configure(config):
    if hasattr(config, "workerinput"):   # an xdist worker: the controller has warmed the cache
        return
    numprocesses = getattr(config.option, "numprocesses", None)
    if not numprocesses or os.environ.get("MBDSIM_NO_WARMUP"):
        return   # one process compiles what it uses as it goes
    src = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src")
    if src not in sys.path:
        sys.path.insert(0, src)
    from mbdsim import _warmup
    for part, (seconds, status) in _warmup.warm().items():
        print(f"mbdsim kernel warm-up ({part}): {seconds:.1f} s" + (f", exit status {status}" if status else ""),
              file=sys.stderr)

"""Where numba keeps mbdsim's compiled kernels: one directory per version of the kernel sources.

numba's on-disk cache checks only the source file of each function, not the functions it calls in
other modules, so after an edit or an upgrade a cached kernel could keep a stale copy of a callee.
Keying the cache directory on a hash of every kernel module makes any change start a fresh cache.
Imported (by `mbdsim.system`) before any kernel module is compiled or loaded. A user-set
NUMBA_CACHE_DIR is respected (the hash is appended below it).
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

_HERE = Path(__file__).parent
KERNEL_SOURCES = ("system/kernels.py", "system/exprvm.py", "system/_exprvm_ops.py", "system/exprloads_kernel.py", "solvers/kkt_tree.py",
                  "solvers/fastdyn.py", "solvers/fastdop.py", "solvers/fasttree.py", "solvers/minnorm.py",
                  "solvers/fastkin.py")


def _digest() -> str:
    h = hashlib.sha1()
    for rel in KERNEL_SOURCES:
        p = _HERE / rel
        if p.exists():
            h.update(rel.encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:16]


def configure() -> str:
    """Point numba's cache at the directory of this kernel version; returns it."""
    import numba
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "mbdsim", "numba")
    path = os.path.join(base, _digest())
    numba.config.CACHE_DIR = path
    return path


CACHE_DIR = configure()

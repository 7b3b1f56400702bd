"""What is in the compiled-kernel cache, and clearing it (`mbdsim cache info`, `mbdsim cache clear`).

The cache (mbdsim._jitcache) lives under `base_dir()`: one directory per version of the kernel sources,
named by the first 16 hex digits of their hash; inside, numba's index (.nbi) and data (.nbc) files per
kernel. Only those version directories are listed or removed, never anything else under a user-set
NUMBA_CACHE_DIR. No numba import here (the command line stays quick).
"""
from __future__ import annotations

import re
import shutil
from dataclasses import dataclass
from pathlib import Path

_VERSION_DIR = re.compile(r"[0-9a-f]{16}")


@dataclass(frozen=True)
class CacheVersion:
    """One version directory: its path, hash, kernels compiled (index files), size [bytes], and whether
    it is the version of this mbdsim's kernel sources."""

    path: Path
    digest: str
    kernels: int
    size: int
    current: bool


def _size(path: Path) -> tuple[int, int]:
    kernels = size = 0
    for f in path.rglob("*"):
        try:
            if f.is_file():
                size += f.stat().st_size
                kernels += f.suffix == ".nbi"
        except OSError:   # removed meanwhile (another process clearing or compiling)
            continue
    return kernels, size


def versions() -> list[CacheVersion]:
    """Every version directory under the cache's base directory, the current one first."""
    from ._jitcache import _digest, base_dir
    base, current = Path(base_dir()), _digest()
    out = []
    if base.is_dir():
        for p in sorted(base.iterdir()):
            if p.is_dir() and _VERSION_DIR.fullmatch(p.name):
                out.append(CacheVersion(p, p.name, *_size(p), current=p.name == current))
    if not any(v.current for v in out):
        out.append(CacheVersion(base / current, current, 0, 0, current=True))
    return sorted(out, key=lambda v: not v.current)


def clear(stale_only: bool = False) -> list[CacheVersion]:
    """Remove the version directories (with `stale_only`, all but the current one); returns those removed.
    The next analysis compiles (and caches) again what it uses."""
    removed = []
    for v in versions():
        if (stale_only and v.current) or not v.path.exists():
            continue
        shutil.rmtree(v.path, ignore_errors=True)
        removed.append(v)
    return removed


def human(n: int) -> str:
    """Bytes as '12.3 MB'."""
    for unit in ("B", "kB", "MB", "GB"):
        if n < 1000 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000.0
    return f"{n:.1f} GB"

"""Compiled kernels shipped with the package: a first result in seconds on a fresh install (issue 32).

Compiling mbdsim's kernels takes numba one to two minutes of CPU on a 2-core machine; a new user's first
command would sit in that. The package therefore carries the kernels that `mbdsim validate`, the README's
examples and the common analyses use, compiled for numba's *generic* x86-64 CPU (portable to any x86-64
machine), as one archive `kernels/<digest>-numba<version>-py<XY>-<machine>.tar.xz` (about 10-20 MB) built by
`python3 tools/build_kernel_pack.py`. On the first import of the kernels, `install` unpacks it into the
cache directory of this kernel version (mbdsim._jitcache: ~/.cache/mbdsim/numba/<digest>) unless that was
done already; later processes find numba's cache there as if they had compiled it themselves. Whatever the
archive lacks (a kernel specialisation no listed workload used) compiles on first use as before.

The archive fits only the kernel sources (`_jitcache._digest`), numba version, Python version and machine
architecture it was built for: anything else (an edited kernel, another numba) ignores it and compiles.
numba's own checks still guard every entry (function bytecode, numba version, CPU name and features).

The CPU: numba keys cached code on the CPU name and features, so shipped code must be compiled for one
CPU every machine has: mbdsim sets numba's CPU to "generic" (x86-64 baseline: SSE2, no AVX/FMA) for the whole
process before numba creates its code generator, unless NUMBA_CPU_NAME is set or MBDSIM_CPU=host (then
kernels compile for this machine's CPU, which a shipped archive cannot serve). Measured cost of "generic"
against the host CPU: bench/RESULTS.md, Start-up. A process that compiled numba code before importing
mbdsim keeps its CPU (numba's code generator exists already) and compiles mbdsim's kernels for it.

The archive holds numba's pickled index and data files: they are loaded exactly as numba loads its own
cache (the same trust as the package's Python files); unpacking takes only regular files with plain
relative names (no links, no absolute paths, no '..').
"""
from __future__ import annotations

import os
import platform
import sys
import tarfile
import tempfile
from pathlib import Path

PACK_DIR = Path(__file__).parent / "kernels"
MARKER = ".mbdsim-pack"   # written in the cache directory once an archive is unpacked there (its name inside)


def numba_version() -> str:
    from importlib.metadata import version
    return version("numba")


def pack_name(digest: str) -> str:
    """File name of the archive for kernel sources `digest` under this numba, Python and machine."""
    return (f"{digest}-numba{numba_version()}-py{sys.version_info[0]}{sys.version_info[1]}-"
            f"{platform.machine().lower()}.tar.xz")


def portable_cpu() -> bool:
    """Make numba compile for its generic CPU (see the module docstring); True when in force. Must run before
    numba's code generator exists (mbdsim._jitcache.configure, at the first import of the kernels)."""
    if os.environ.get("MBDSIM_CPU", "").lower() == "host":
        return False
    from numba.core import config
    name = os.environ.get("NUMBA_CPU_NAME")
    if name is not None:   # the user chose a CPU
        return name.lower() == "generic" and not os.environ.get("NUMBA_CPU_FEATURES")
    from numba.core.registry import cpu_target
    if "_toplevel_target_context" in vars(cpu_target):   # numba compiled already: its CPU is fixed
        return config.CPU_NAME == "generic" and not config.CPU_FEATURES
    # the environment too: numba re-reads its whole configuration from it whenever a NUMBA_ variable changes
    # (config.reload_config, at every compilation), and child processes (study workers) then agree
    os.environ["NUMBA_CPU_NAME"], os.environ["NUMBA_CPU_FEATURES"] = "generic", ""
    config.CPU_NAME, config.CPU_FEATURES = "generic", ""
    return True


def _members(tar: tarfile.TarFile):
    for m in tar.getmembers():
        parts = Path(m.name).parts
        if m.isfile() and parts and not Path(m.name).is_absolute() and ".." not in parts:
            yield m


def _kernel(name: str) -> str:
    """The kernel a cache file belongs to: numba names them `<function>-<line>.py<XY>.nbi` (the index) and
    `<function>-<line>.py<XY>.<n>.nbc` (its data files)."""
    stem = name[:-4]
    return stem if name.endswith(".nbi") else stem.rsplit(".", 1)[0]


def install(cache_dir: str, digest: str) -> str | None:
    """Unpack the archive of kernel version `digest` into `cache_dir` unless it was unpacked before; returns
    the archive's name when unpacked now, else None. A kernel whose index is in the cache already is left as
    it is (its data files are numbered by that index: mixing them with the archive's would pair an index
    entry with another entry's code). Never raises: a missing, foreign or broken archive leaves the cache as
    it is (the kernels then compile)."""
    try:
        name = pack_name(digest)
        archive = PACK_DIR / name
        target = Path(cache_dir)
        marker = target / MARKER
        if not archive.is_file() or (marker.is_file() and marker.read_text().strip() == name):
            return None
        target.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=target.parent, prefix=".unpack-") as tmp, \
                tarfile.open(archive, "r:xz") as tar:
            members = list(_members(tar))
            kept = {_kernel(m.name) for m in members if m.name.endswith(".nbi") and (target / m.name).exists()}
            # data files first, then the indexes: a process reading beside this one never meets an index
            # whose data is not there yet
            for m in sorted(members, key=lambda m: m.name.endswith(".nbi")):
                if _kernel(m.name) in kept:
                    continue
                staged = Path(tmp) / f"{len(os.listdir(tmp))}"
                with open(staged, "wb") as out:
                    out.write(tar.extractfile(m).read())
                dest = target / m.name
                dest.parent.mkdir(parents=True, exist_ok=True)
                os.replace(staged, dest)   # atomic: a second process unpacking beside this one is harmless
        marker.write_text(name + "\n")
        return name
    except Exception:  # noqa: BLE001 - the archive is an optimisation; compiling is the fallback
        return None

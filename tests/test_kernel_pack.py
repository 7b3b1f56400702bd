"""The compiled kernels shipped with the package (mbdsim._kernelpack; issue 32): the archive matches the kernel
sources, and a process with an empty cache unpacks it and runs the README pendulum without compiling."""
from __future__ import annotations

import os
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

import mbdsim
from mbdsim import _jitcache, _kernelpack
from test_kernel_cache import CHILD as KERNEL_CACHE_CHILD

# the README pendulum in a child process (test_kernel_cache's), then whether it unpacked the archive
CHILD = KERNEL_CACHE_CHILD + "from mbdsim import _jitcache\nprint(_jitcache.UNPACKED)\n"


def _archive() -> Path:
    return _kernelpack.PACK_DIR / _kernelpack.pack_name(_jitcache._digest())


def test_shipped_archive_matches_the_kernel_sources():
    """Fails while the archive is stale: run `python3 tools/build_kernel_pack.py` after editing a kernel."""
    digest = _jitcache._digest()
    archives = sorted(_kernelpack.PACK_DIR.glob("*.tar.xz"))
    assert archives, "no compiled-kernel archive in src/mbdsim/kernels: run python3 tools/build_kernel_pack.py"
    assert [a.name.split("-")[0] for a in archives] == [digest], (
        f"the shipped kernels {[a.name for a in archives]} are not those of these kernel sources ({digest}): "
        "run python3 tools/build_kernel_pack.py")


def test_archive_holds_only_plain_cache_files():
    for archive in _kernelpack.PACK_DIR.glob("*.tar.xz"):
        with tarfile.open(archive, "r:xz") as tar:
            for m in tar.getmembers():
                assert m.isfile() and not os.path.isabs(m.name) and ".." not in Path(m.name).parts, m.name
                assert (m.name.startswith("mbdsim/") and m.name.endswith((".nbi", ".nbc"))) or \
                    (m.name.startswith("nrt-") and m.name.endswith(".pickle") and "/" not in m.name), m.name


def test_empty_cache_runs_the_readme_pendulum_without_compiling(tmp_path):
    if not _archive().is_file():
        pytest.skip(f"no archive for this numba and Python ({_archive().name})")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_") and k not in ("MBDSIM_CPU", "MBDSIM_NO_PACK")}
    env.update(NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(Path(mbdsim.__file__).parents[1]),
               MBDSIM_QUIET_COMPILE="1")
    out = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=1200)
    assert out.returncode == 0, out.stderr[-3000:]
    compiled, unpacked = out.stdout.splitlines()[-2:]
    assert unpacked == _archive().name
    assert int(compiled) == 0, f"{compiled} kernels compiled despite the shipped archive"


def test_a_broken_archive_is_ignored(tmp_path, monkeypatch):
    monkeypatch.setattr(_kernelpack, "PACK_DIR", tmp_path)
    (tmp_path / _kernelpack.pack_name("0123456789abcdef")).write_bytes(b"not an archive")
    assert _kernelpack.install(str(tmp_path / "cache"), "0123456789abcdef") is None


def test_unsafe_members_are_skipped(tmp_path, monkeypatch):
    import io
    monkeypatch.setattr(_kernelpack, "PACK_DIR", tmp_path / "pack")
    (tmp_path / "pack").mkdir()
    name = _kernelpack.pack_name("0123456789abcdef")
    with tarfile.open(tmp_path / "pack" / name, "w:xz") as tar:
        for member, data in (("mbdsim/a.nbi", b"ok"), ("../evil.nbi", b"x"), ("/abs.nbi", b"x")):
            info = tarfile.TarInfo(member)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
        link = tarfile.TarInfo("mbdsim/link.nbi")
        link.type, link.linkname = tarfile.SYMTYPE, "/etc/passwd"
        tar.addfile(link)
    cache = tmp_path / "work" / "cache"
    assert _kernelpack.install(str(cache), "0123456789abcdef") == name
    files = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*") if p.is_file() or p.is_symlink())
    assert files == ["pack/" + name, "work/cache/.mbdsim-pack", "work/cache/mbdsim/a.nbi"]
    assert _kernelpack.install(str(cache), "0123456789abcdef") is None   # once


def test_kernels_already_cached_are_left_whole(tmp_path, monkeypatch):
    """A kernel whose index is in the cache keeps its own index and data files (never mixed with the
    archive's); the others are unpacked."""
    import io
    monkeypatch.setattr(_kernelpack, "PACK_DIR", tmp_path / "pack")
    (tmp_path / "pack").mkdir()
    name = _kernelpack.pack_name("0123456789abcdef")
    files = {"mbdsim/solvers/f-1.py311.nbi": b"new f", "mbdsim/solvers/f-1.py311.1.nbc": b"new f data",
             "mbdsim/solvers/g-9.py311.nbi": b"new g", "mbdsim/solvers/g-9.py311.1.nbc": b"new g data"}
    with tarfile.open(tmp_path / "pack" / name, "w:xz") as tar:
        for member, data in files.items():
            info = tarfile.TarInfo(member)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    cache = tmp_path / "cache"
    (cache / "mbdsim" / "solvers").mkdir(parents=True)
    (cache / "mbdsim/solvers/f-1.py311.nbi").write_bytes(b"old f")
    assert _kernelpack.install(str(cache), "0123456789abcdef") == name
    assert (cache / "mbdsim/solvers/f-1.py311.nbi").read_bytes() == b"old f"
    assert not (cache / "mbdsim/solvers/f-1.py311.1.nbc").exists()
    assert (cache / "mbdsim/solvers/g-9.py311.nbi").read_bytes() == b"new g"
    assert (cache / "mbdsim/solvers/g-9.py311.1.nbc").read_bytes() == b"new g data"

"""Build the compiled kernels shipped with the package (mbdsim._kernelpack; issue 32).

    python3 tools/build_kernel_pack.py            # compile the workloads below, write src/mbdsim/kernels/*.tar.xz

Run it after any change to a kernel module (mbdsim._jitcache.KERNEL_SOURCES) before committing: the archive
matches one digest of the kernel sources, and tests/test_kernel_pack.py fails while it is stale. It compiles,
in a fresh private cache and for numba's generic CPU, what a new user's first commands use: `mbdsim
validate`, the README's Python examples, the CLI commands of the README on examples/, the example scripts,
the warm-up of the test suite (mbdsim._warmup) and the other analyses, methods and elements as the test suite uses them; then archives the cache directory of this
kernel version (mbdsim's own kernels only) with xz and removes any older archive. Several minutes of CPU.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


_WARMUP_PARTS = ("dynamics", "kinematics", "stepping")   # mbdsim._warmup.PARTS


def _env(cache: str) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_") and k != "MBDSIM_CPU"}
    env.update(NUMBA_CACHE_DIR=cache, PYTHONPATH=str(SRC), MBDSIM_NO_PACK="1", MPLBACKEND="Agg")
    return env


def _readme_blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    return [b for b in blocks if "Study(" not in b]   # a study starts a Dask cluster: its kernels are the same


def _run(cmd: list[str], env: dict, cwd: str, check: bool = True) -> None:
    t0 = time.time()
    p = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    print(f"  {time.time() - t0:6.1f} s  rc {p.returncode}  {' '.join(cmd)[:110]}", flush=True)
    if p.returncode != 0 and check:
        sys.stderr.write(p.stdout[-2000:] + p.stderr[-4000:])
        raise SystemExit(f"workload failed: {' '.join(cmd)}")
    if p.returncode != 0:   # a workload whose failures do not matter here: its summary, for the record
        print("\n".join(ln for ln in p.stdout.splitlines() if ln.startswith(("FAILED", "ERROR")))[-3000:], flush=True)


def main() -> None:
    sys.path.insert(0, str(SRC))
    from mbdsim import _jitcache, _kernelpack
    digest = _jitcache._digest()
    name = _kernelpack.pack_name(digest)
    base = tempfile.mkdtemp(prefix="mbdsim-pack-")
    env = _env(base)
    work = tempfile.mkdtemp(prefix="mbdsim-pack-work-")
    py = sys.executable
    print(f"compiling into {base} for {name}", flush=True)
    _run([py, "-m", "mbdsim", "validate", "--out", os.path.join(work, "val")], env, work)
    for i, block in enumerate(_readme_blocks()):
        f = Path(work) / f"readme_{i}.py"
        f.write_text(block)
        _run([py, str(f)], env, work)
    ex = ROOT / "examples"
    for cmd in (["run", ex / "slider_crank.yaml", "--end", "2", "--step", "0.01", "--out", "r.parquet"],
                ["run", ex / "four_bar.yaml", "--end", "1", "--out", "r2.parquet", "--markers"],
                ["kinematics", ex / "four_bar.yaml", "--end", "1", "--out", "kin.csv"],
                ["statics", ex / "spring_mass_chain.yaml"],
                ["modes", ex / "pendulum.yaml", "--out", "modes.csv"]):
        _run([py, "-m", "mbdsim", *map(str, cmd)], env, work)
    for script in sorted(ex.glob("*.py")):
        _run([py, str(script)], env, work)
    _run([py, "-m", "mbdsim._warmup", *_WARMUP_PARTS], env, work)   # what the test suite's controller warms
    # the other analyses, methods and elements, as the test suite uses them, so that a fresh clone's tests
    # compile (almost) nothing (issue 32: the suite cold within 6 min; failures do not matter here, only
    # what they compile)
    _run([py, "-m", "pytest", "-q", "-n", "2", "-p", "no:cacheprovider", str(ROOT / "tests")],
         env, str(ROOT), check=False)

    src_dir = Path(base) / digest
    out_dir = _kernelpack.PACK_DIR
    out_dir.mkdir(exist_ok=True)
    tmp = out_dir / (name + ".part")
    with tarfile.open(tmp, "w:xz", preset=9) as tar:
        files = sorted(f for f in (src_dir / "mbdsim").rglob("*") if f.is_file() and f.suffix in (".nbi", ".nbc"))
        for f in files + sorted(src_dir.glob("nrt-*.pickle")):   # + numba's runtime module (_jitcache._cached_nrt)
            tar.add(f, arcname=str(f.relative_to(src_dir)))
    for old in out_dir.glob("*.tar.xz"):
        if old.name != name:
            old.unlink()
    os.replace(tmp, out_dir / name)
    size = (out_dir / name).stat().st_size
    print(f"wrote {out_dir / name}: {size / 1e6:.1f} MB", flush=True)
    shutil.rmtree(base, ignore_errors=True)
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()

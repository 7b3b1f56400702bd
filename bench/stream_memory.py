"""Peak memory of a long streamed run (issue 10): a double pendulum for END s at 1 ms output written by
simulate(out=...) to a Parquet dataset, in a fresh process (ru_maxrss = peak resident set size).

    python bench/stream_memory.py [END] [--memory]    (default END = 1000 s; --memory: the in-memory run)

Prints: simulated time, outputs, wall time, peak RSS [MB] (the whole process: Python, numpy, scipy, numba,
pandas, pyarrow included) and, for the streamed run, the rows pandas reads back."""
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path


def main():
    end = float(next((a for a in sys.argv[1:] if not a.startswith("--")), 1000.0))
    in_memory = "--memory" in sys.argv
    import mbdsim as mb
    import pandas as pd   # noqa: F401  (loaded before the baseline: the run writes with it)
    import pyarrow.parquet  # noqa: F401
    m = mb.Model("double_pendulum", gravity=(0.0, -9.81, 0.0))
    a = m.add_body("a", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0.0, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.5, 0.0, 0.0))
    m.add_revolute("j1", m.ground, a, (0, 0, 0), (0, 0, 1))
    m.add_revolute("j2", a, b, (1.0, 0, 0), (0, 0, 1))
    mb.simulate(m, 0.01, 0.001)   # kernels loaded from numba's cache before the baseline
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    out = Path(tempfile.mkdtemp()) / "run.parquet"
    t0 = time.perf_counter()
    if in_memory:
        res = mb.simulate(m, end, 0.001)
        rows = len(res.time)
    else:
        res = mb.simulate(m, end, 0.001, out=out)
        rows = res.stats["samples"]
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{'in memory' if in_memory else 'streamed'}: {end:g} s at 1 ms, {rows} outputs, success={res.success}, "
          f"wall {wall:.1f} s, peak RSS {peak:.0f} MB (after imports and a warm-up run: {base:.0f} MB)")
    if not in_memory:
        import pyarrow.parquet as pq
        n = sum(pq.ParquetFile(p).metadata.num_rows for p in out.glob("part-*.parquet"))
        size = sum(p.stat().st_size for p in out.iterdir()) / 2**20
        print(f"dataset {out}: {n} rows in {res.stats['chunks']} parts, {size:.0f} MiB on disk")
    shutil.rmtree(out.parent, ignore_errors=True)


if __name__ == "__main__":
    main()

"""Peak memory of a long streamed run (issue 10): a double pendulum for END s at 1 ms output written by
simulate(out=...) to a Parquet dataset, in a fresh process, as a user would run it:

    import mbdsim as mb; model = ...; mb.simulate(model, 1000, 0.001, out="run.parquet")

    python bench/stream_memory.py [END] [--memory] [--csv]    (default END = 1000 s; --memory: the in-memory
                                                               run; --csv: out="run.csv", one streamed CSV file)

Nothing is loaded or run before the measured call but `import mbdsim` and building the model (no warm-up
run, no pandas: the streamed writer does not use it). Peak RSS is VmHWM of the whole process (Python,
numpy, scipy, numba and its loaded kernels, pyarrow, the run's buffers). Stages (VmRSS [MB] from
/proc/self/status): after building the model, at the run's first progress report (its modules imported, its
integration kernels loaded from numba's cache, before the first part is written), at the end. pandas is imported only
after the peak is taken, to count the rows it reads back. Run it twice after a kernel edit: the first run
compiles (LLVM's compile-time memory is then in the peak)."""
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path


def rss_mb() -> float:
    """Resident set size now [MB] (VmRSS)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def peak_mb() -> float:
    """Peak resident set size of the process so far [MB]: VmHWM, the high-water mark of this process image
    (ru_maxrss, kB on Linux, also counts the parent's pages before exec when started from a big process;
    from a shell both agree)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main():
    end = float(next((a for a in sys.argv[1:] if not a.startswith("--")), 1000.0))
    in_memory = "--memory" in sys.argv
    as_csv = "--csv" in sys.argv
    import mbdsim as mb
    m = mb.Model("double_pendulum", gravity=(0.0, -9.81, 0.0))
    a = m.add_body("a", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0.0, 0.0))
    b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.5, 0.0, 0.0))
    m.add_revolute("j1", m.ground, a, (0, 0, 0), (0, 0, 1))
    m.add_revolute("j2", a, b, (1.0, 0, 0), (0, 0, 1))
    base = rss_mb()
    first = []

    def progress(t):
        if not first:
            first.append(rss_mb())
    out = Path(tempfile.mkdtemp()) / ("run.csv" if as_csv else "run.parquet")
    t0 = time.perf_counter()
    if in_memory:
        res = mb.simulate(m, end, 0.001, progress=progress)
        rows = len(res.time)
    else:
        res = mb.simulate(m, end, 0.001, out=out, progress=progress)
        rows = res.stats["samples"]
    wall = time.perf_counter() - t0
    peak, last = peak_mb(), rss_mb()
    mods = sorted(k for k in sys.modules if k.split(".")[0] in ("pandas", "scipy", "pyarrow"))
    print(f"{'in memory' if in_memory else 'streamed'}: {end:g} s at 1 ms, {rows} outputs, success={res.success}, "
          f"wall {wall:.1f} s, peak RSS {peak:.0f} MB")
    scipy_sub = sorted({k.split(".")[1] for k in mods if k.startswith("scipy.") and not k.split(".")[1][0] == "_"})
    print(f"  RSS [MB]: model built {base:.0f}, first progress report {first[0] if first else float('nan'):.0f}, "
          f"end {last:.0f}; pandas imported: {'pandas' in sys.modules}; scipy subpackages: {scipy_sub}")
    if as_csv and not in_memory:
        with open(out, "rb") as fh:
            n = sum(1 for _ in fh) - 1
        print(f"file {out}: {n} rows, {out.stat().st_size / 2**20:.0f} MiB on disk")
    elif not in_memory:
        import pyarrow.parquet as pq
        n = sum(pq.ParquetFile(p).metadata.num_rows for p in out.glob("part-*.parquet"))
        size = sum(p.stat().st_size for p in out.iterdir()) / 2**20
        import pandas as pd   # after the peak: reading back is the user's next step, not the run's cost
        cols = pd.read_parquet(next(out.glob("part-*.parquet"))).shape[1]
        print(f"dataset {out}: {n} rows x {cols} columns in {res.stats['chunks']} parts, {size:.0f} MiB on disk")
    shutil.rmtree(out.parent, ignore_errors=True)


if __name__ == "__main__":
    main()

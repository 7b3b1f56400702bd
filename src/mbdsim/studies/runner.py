"""Running a study: chunks of variants as dask.distributed tasks (or in this process), rows journaled as
they arrive and written to Parquet (mbdsim.studies.store), finished runs skipped on a re-run, lost tasks
reported instead of crashing."""
from __future__ import annotations

import logging
import math
import os
import sys
from contextlib import contextmanager

import pandas as pd

from .._blas import _limit
from ..errors import ModelError
from .store import STUDY_COLUMN, RowStore, load_rows
from .variant import run_chunk

__all__ = ["execute", "chunks_of", "default_chunk_size"]


def default_chunk_size(n_runs: int, n_workers: int) -> int:
    """About four tasks per worker (load balance) and at most 32 variants per task."""
    return max(1, min(32, math.ceil(n_runs / max(1, 4 * n_workers))))


def chunks_of(design: pd.DataFrame, size: int) -> list[list]:
    """[(run, {parameter: value}), ...] in chunks of `size` runs."""
    records = [(int(run), row) for run, row in zip(design.index, design.to_dict("records"))]
    return [records[k:k + size] for k in range(0, len(records), size)]


def start_method() -> str:
    """How a LocalCluster started by a study makes its worker processes: 'fork' on Linux, so that each
    worker inherits this process's imports and loaded kernels (seconds per worker otherwise, more on
    shared cores), else Dask's setting; the environment variable MBDSIM_STUDY_START_METHOD ('spawn',
    'fork' or 'forkserver') overrides."""
    import dask
    env = os.environ.get("MBDSIM_STUDY_START_METHOD", "").strip()
    if env:
        if env not in ("spawn", "fork", "forkserver"):
            raise ModelError("study", "MBDSIM_STUDY_START_METHOD", f"expected spawn, fork or forkserver, got {env!r}")
        return env
    if sys.platform.startswith("linux"):
        return "fork"
    return dask.config.get("distributed.worker.multiprocessing-method")


def local_cluster_config() -> dict:
    """Dask settings of the LocalCluster a study starts: the start method above, no statistical profiler
    in the workers (it samples the running task's stack every 10 ms; without it a slider-crank variant
    took 69 instead of 85-98 ms of worker CPU under load), and slower housekeeping timers (event-loop
    tick 1 s instead of 20 ms, system monitor 5 s instead of 0.5 s, the nanny's memory monitor 1 s
    instead of 0.1 s): two idle workers then use 1 % of a core instead of 4.7 % (measured), CPU that
    the variants on the same cores get instead."""
    return {"distributed.worker.multiprocessing-method": start_method(),
            "distributed.worker.profile.enabled": False,
            "distributed.admin.tick.interval": "1s",
            "distributed.admin.system-monitor.interval": "5s",
            "distributed.worker.memory.monitor-interval": "1s"}


@contextmanager
def _client(client, workers):
    """A Client: the given one, one connected to an address, or a LocalCluster for this run (closed after)."""
    import dask
    from distributed import Client, LocalCluster
    if client is not None and not isinstance(client, str):
        yield client
        return
    if isinstance(client, str):
        with Client(client, timeout="30s") as c:
            yield c
        return
    n = _local_workers(workers)
    with dask.config.set(local_cluster_config()), \
            LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                         silence_logs=logging.ERROR) as cluster, Client(cluster) as c:
        yield c


def _local_workers(workers) -> int:
    n = 2 if workers is None else int(workers)
    if n < 1:
        raise ModelError("study", "workers", f"expected a positive number of workers (0: no Dask), got {workers!r}")
    return n


class _Sink:
    """Collects rows; stores those of finished runs (not 'lost' ones) through a RowStore."""

    def __init__(self, study, out, previous):
        self.study_id = study.study_id
        self.previous = previous
        self.rows = []          # dicts: one DataFrame at the end, not one per chunk
        self.store = RowStore(out, previous)
        self.executed = 0

    def add(self, rows: list[dict], keep: bool = True):
        rows = [{**row, STUDY_COLUMN: self.study_id} for row in rows]
        self.rows.extend(rows)
        self.executed += len(rows)
        if keep:
            self.store.append(rows)

    def close(self):
        self.store.close()

    def frame(self, study) -> pd.DataFrame:
        cols = ["run", *study.design.columns, *study.plan.outputs, "status", "message", "wall_time", "worker"]
        frames = ([] if self.previous is None else [self.previous]) + ([pd.DataFrame(self.rows)] if self.rows else [])
        frames = frames or [pd.DataFrame(columns=cols)]
        df = pd.concat(frames, ignore_index=True).sort_values("run", kind="stable").reset_index(drop=True)
        df = df[cols]
        df.attrs.update(executed=self.executed, parameters=list(study.design.columns),
                        outputs=list(study.plan.outputs), units=dict(getattr(study, "units", {})))
        return df


def _progress(enabled, total, done):
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
    if enabled is None:
        enabled = sys.stderr.isatty()
    bar = Progress(TextColumn("study"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                   console=Console(stderr=True), disable=not enabled)
    task = bar.add_task("runs", total=total, completed=done)
    return bar, task


def _lost_rows(study, chunk, exc):
    """Rows 'lost' for the runs of a chunk whose task Dask gave up on, the message saying why in words: a
    worker process that died (a variant ending its process: os._exit, a crash in native code, memory)
    takes its task and the data scattered to it with it, and Dask's own words ("FutureCancelledError ...
    already forgotten") name neither."""
    runs = [int(run) for run, _ in chunk]
    span = f"run {runs[0]}" if len(runs) == 1 else f"runs {runs[0]}-{runs[-1]}"
    msg = (f"{span} lost: the Dask worker running it died or its task was dropped (a variant that ends its "
           "process, crashes in native code or exhausts memory does this; it may also take other runs' "
           "tasks with it); run the study again with the same out= file to retry the lost runs, or with "
           f"workers=0 to see a variant's own error ({type(exc).__name__}: {exc})")
    return [{"run": run, **params, **{k: math.nan for k in study.plan.outputs}, "status": "lost",
             "message": msg, "wall_time": math.nan, "worker": ""} for run, params in chunk]


def execute(study, client=None, workers=None, out=None, chunk_size=None, progress=None) -> pd.DataFrame:
    """Study.run (see there)."""
    previous = load_rows(out, study.study_id) if out is not None else None
    done = set() if previous is None else set(previous["run"].astype(int))
    pending = study.design[~study.design.index.isin(done)]
    sink = _Sink(study, out, previous)
    bar, task = _progress(progress, len(study.design), len(study.design) - len(pending))
    serial = workers == 0 and client is None
    try:
        with bar:
            if len(pending) == 0:
                pass
            elif serial:
                with _limit():   # one BLAS limit for the whole loop (run_chunk's own is then a no-op)
                    for chunk in chunks_of(pending, chunk_size or 1):     # every run journaled as it finishes
                        sink.add(run_chunk(study.plan, chunk))
                        bar.advance(task, len(chunk))
            else:
                _run_dask(study, pending, client, workers, chunk_size, sink, lambda n: bar.advance(task, n))
    finally:
        sink.close()       # every finished row into the Parquet file, also after Ctrl-C or an error
    return sink.frame(study)


def _run_dask(study, pending, client, workers, chunk_size, sink, advance):
    from distributed import as_completed
    if client is None and start_method() == "fork":
        _local_workers(workers)
        # the first run here, before the workers are forked: they inherit its imports and loaded kernels
        first = chunks_of(pending.iloc[:1], 1)[0]
        sink.add(run_chunk(study.plan, first))
        advance(1)
        pending = pending.iloc[1:]
        if not len(pending):
            return
    with _client(client, workers) as c:
        n_workers = max(1, len(c.scheduler_info().get("workers", {})) or (workers or 1))
        chunks = chunks_of(pending, chunk_size or default_chunk_size(len(pending), n_workers))
        [plan] = c.scatter([study.plan], broadcast=True, hash=False)
        futures = {c.submit(run_chunk, plan, chunk, pure=False): chunk for chunk in chunks}
        try:
            for fut in as_completed(futures):
                chunk = futures[fut]
                try:
                    sink.add(fut.result())
                except Exception as exc:  # noqa: BLE001 - KilledWorker etc.: rows marked lost, retried on resume
                    sink.add(_lost_rows(study, chunk, exc), keep=False)
                advance(len(chunk))
        finally:
            c.cancel(list(futures))

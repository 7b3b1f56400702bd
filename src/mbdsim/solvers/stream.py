"""Long runs on disk: `simulate(..., out="run.parquet")` streams the results in chunks as they are computed.

Layout: `out` is a Parquet dataset directory (what `pandas.read_parquet(out)` reads as one table):
``part-000000.parquet``, ``part-000001.parquet``, ... one file per chunk of CHUNK_ROWS output times, with
the columns of `Result.to_dataframe()` (joint angles and Euler parameters continuous across chunks;
written with pyarrow alone: pandas is needed to read them, not to write them), and ``_checkpoint.npz``
(ignored by Parquet readers) with everything the compiled integrator carries from one chunk to the next:
time and step size [t, h], the integrator state y and its derivative f, the step statistics and
stiffness counters, the last output row and the last written table row. Each file is written to a
hidden temporary name and renamed (atomic on POSIX), part first, checkpoint second: a run killed at any
moment (SIGKILL included) leaves every completed part readable and a checkpoint that is never ahead of
the parts.

Memory is bounded by one chunk whatever the run's length (bench/stream_memory.py: a 1000 s run at
1 ms output peaks under 300 MB resident, libraries and loaded kernels included; only the kernels the
run calls are loaded: the starting step is computed here around the loaded rhs kernel).

`resume=True` reloads the checkpoint (the run's settings and assembled initial state must match, checked
by a fingerprint, and so must the model's content: a digest of every entity's numbers, expressions and
functions, system.fingerprint.model_digests; a mismatch is a ModelError naming the entities that differ)
and continues with exactly the carried state: the compiled step loop returns to Python
at every chunk boundary in an uninterrupted run too, so a resumed run is bit-identical to an
uninterrupted one.

A ".csv" `out` is streamed the same way into one CSV file: the header, then each part's rows appended
(one write and an fsync per part) as they are computed, so memory stays bounded by a part and a killed
run leaves every completed part's rows (at most the last line of a part cut short by a SIGKILL in the
middle of its write). A CSV run has no checkpoint: resume needs the Parquet dataset.

Streaming needs the compiled DOP853 (method "auto" or "dop853", a model the kernels carry; no stiffness
switch while streaming: a model found stiff in the first part runs in memory with "auto"'s hand-over to
the compiled Radau, joint friction's modes included). Other methods and models run in memory and then
write the same layout (no resume).

Joint friction and expression sensors stream as in memory (issue 29): the kernel locates their events
(`fastdop.run` with its watch), the stick/slip decisions are taken between kernel calls
(`friction_run.FrictionModes.decide`, restart at the event with h = 0), a sensor's stop ends the run
with the state at its time as the last row, and the modes are set again before each part (the previous
part's outputs set those in force at each output). A step, or the run up to an event, that covered
outputs beyond a part's window is redone from the saved state into a larger one, with the kernel's
carried values restored (`stream_events.event_state`: friction switching and sensor values, the event
count, the loop rows in use). The checkpoint carries, besides the state, what a resumed run needs to
continue exactly (`stream_events.events`): those values, the sensor events met, the friction elements'
mode histories, their held groups and the decisions' independent rows.
"""
from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import numpy as np

from ..errors import AnalysisInterrupted, ModelError, SolverError
from ..results import stream as results_stream
from ..results.result import Result

CHUNK_ROWS = 5_000           # output times per part file (a chunk ends at the first step end past them)
STREAM_KEEP = 8 * 2**20    # bytes of output states the returned Result may hold (else: the last part only)
COLUMN_ROWS = 1000          # outputs per block when computing a part's table (bounds its work arrays)
MARGIN = 1024                # extra rows for the outputs of a chunk's last step (grown when a step has more)
CHECKPOINT = "_checkpoint.npz"
META = "_run.json"


# ----------------------------------------------------------------------------- files
def prepare(out, resume: bool) -> Path:
    """The dataset directory for `out` (created; emptied of a previous run unless resuming)."""
    try:
        path = Path(out)
    except TypeError:
        raise ModelError("simulate", "out", f"expected a path, got {out!r}") from None
    if os.path.lexists(path) and not path.is_dir():
        if resume:
            raise ModelError("simulate", "out", f"{str(path)!r} is a file, not a run directory to resume")
        results_stream.check_replaceable(path)   # a results file mbdsim wrote may be replaced, nothing else
        path.unlink()
    if path.is_dir():
        foreign = [p.name for p in path.iterdir() if not _ours(p.name)]
        if foreign:
            raise ModelError("simulate", "out", f"{str(path)!r} holds files not written by mbdsim ({foreign[:3]}); "
                             "choose a new path")
        if not resume:
            for p in path.iterdir():
                p.unlink()
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ModelError("simulate", "out", f"cannot create {str(path)!r}: {exc}") from None
    return path


def _ours(name: str) -> bool:
    """A file a run writes, or the temporary file of one (left behind by a run killed while writing it)."""
    return name in (CHECKPOINT, META, _tmp_name(CHECKPOINT), _tmp_name(META)) or \
        name.startswith(("part-", ".part-", ".ckpt-", "._run"))


def _tmp_name(name: str) -> str:
    """The temporary file `_atomic` writes before renaming it to `name`."""
    return f".{name.lstrip('_')}.tmp"


def _atomic(path: Path, write) -> None:
    tmp = path.parent / _tmp_name(path.name)
    write(tmp)
    with open(tmp, "rb") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, path)


class CsvFile:
    """The `.csv` sink of a streamed run: the header, then each part appended (see the module docstring).
    An existing file is replaced only when mbdsim wrote it (results.stream.check_replaceable)."""

    def __init__(self, out):
        self.path = results_stream.out_file(out)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.path.write_bytes(b"")
        except OSError as exc:
            raise ModelError("simulate", "out", f"cannot write {str(self.path)!r}: {exc}") from None
        self.header = True

    def part(self, cols: dict) -> None:
        """Append the rows of `cols` ({column name: 1-D array}; the header before the first part)."""
        with open(self.path, "ab") as fh:
            results_stream.write_csv(cols, fh, header=self.header)
            fh.flush()
            os.fsync(fh.fileno())
        self.header = False


def write_part(path: Path, index: int, cols: dict) -> None:
    """Chunk `index` of the run as part-<index>.parquet (atomic); `cols`: {column name: 1-D array}, written
    with pyarrow directly (pandas is not needed to write, only to read the dataset back)."""
    _atomic(path / f"part-{index:06d}.parquet", lambda p: results_stream.write_parquet(cols, p))


def fingerprint(sys, rep, times, rtol, atol, max_step, markers=()) -> str:
    """Hash of what makes two runs the same computation (settings, grid, model size, initial state) and
    the same table (the marker columns `markers`: their prefixes)."""
    h = hashlib.sha1()
    for a in (np.asarray([times[0], times[-1], len(times), rtol, atol, max_step or 0.0, sys.nq, sys.nv, sys.nc]),
              np.asarray(times[:2]), np.asarray(rep.q, float), np.asarray(rep.v, float), np.asarray(rep.rows)):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    h.update(",".join(sorted(sys.model.bodies)).encode())
    h.update(",".join(sorted(sys.model.joints)).encode())
    if markers:
        h.update(("markers:" + ",".join(markers)).encode())
    return h.hexdigest()


# ----------------------------------------------------------------------------- tables
def chunk_columns(res, prev_row, markers=False):
    """The `to_dataframe()` columns of a chunk's Result ({name: array}, see results.export.columns); with
    prev_row (the previous chunk's last table row, {name: float}, also the chunk's first sample), angle
    columns continue it (multiples of 2 pi) and Euler parameters keep its sign, and that first row is
    dropped. markers: the marker columns (results.export.marker_targets)."""
    from ..results.export import columns
    cols = columns(res, markers)
    if prev_row is None:
        return cols
    for col, x in cols.items():
        if col.endswith("[rad]"):
            shift = np.round((prev_row[col] - x[0]) / (2 * np.pi)) * 2 * np.pi
            if shift:
                cols[col] = x + shift
    for qw in [c for c in cols if c.endswith(".qw [-]")]:
        stem = qw[:-len("qw [-]")]
        names = [f"{stem}q{c} [-]" for c in "wxyz"]
        if all(c in cols for c in names):
            dot = float(np.dot([prev_row[c] for c in names], [cols[c][0] for c in names]))
            if dot < 0:
                for c in names:
                    cols[c] = -cols[c]
    return {k: v[1:] for k, v in cols.items()}


def part_columns(result_of, n: int, prev_row, markers=False):
    """`chunk_columns` of a part's n outputs, computed in blocks of at most COLUMN_ROWS + 1 outputs joined as
    parts are (a block's first output repeats the previous block's last): the per-sample work arrays
    (frames, accelerations, the Jacobians behind the reactions) stay bounded by a block, not a part.
    result_of(s, e): the Result of the part's outputs s .. e-1."""
    blocks, s = [], 0
    while True:
        e = min(s + COLUMN_ROWS + 1, n)
        res = result_of(s, e)
        blocks.append(chunk_columns(res, prev_row if s == 0 else last_row(blocks[-1]), markers))
        res._fr = None   # break the Result <-> lazy frames cycle: the block's arrays go now, not at a GC
        if e >= n:
            break
        s = e - 1
    if len(blocks) == 1:
        return blocks[0]
    return {k: np.concatenate([b[k] for b in blocks]) for k in blocks[0]}


def last_row(cols: dict) -> dict:
    """The last row of a columns dict as {name: float}."""
    return {k: float(v[-1]) for k, v in cols.items()}


# ----------------------------------------------------------------------------- compiled streaming
def stream_compiled(sys, rep, times, rtol, atol, max_step, progress, out, resume, monitor=True,
                    markers=False, stiff_check=False) -> Result:
    """Compiled DOP853 over `times` in chunks of CHUNK_ROWS outputs written to `out` (see module doc);
    raises NotCompiled when the model needs the reference path, and (stiff_check) when the model turns
    out stiff before the first part is written (the files made are removed: the caller's whole-file
    writer runs "auto" with its implicit hand-over instead). Returns a Result holding the last chunk
    (res.stats["out"] names the dataset, res.stats["samples"] counts every output written)."""
    from . import fastdop, pyloads, stream_events
    from .compiled_run import _MESSAGES, CHUNK, PROGRESS_FAILED, CompiledRun, _full_multipliers, initial_step
    from .fastdyn import FRICTION_FAILED, INTERRUPTED, STIFF
    from ..system.compiled import NotCompiled
    if sys.derived.get("friction not compiled"):   # a held group met by an earlier try (solvers.friction_run)
        raise NotCompiled(sys.derived["friction not compiled"])
    run = CompiledRun(sys, rep.rows, rtol, atol, max_step, stiff_check=False, state=(rep.q, rep.v),
                      friction=len(sys.lock_rows) > 0)
    watch = bool(run.sensors) or run.friction is not None   # events located by the kernel (fastdop.run)
    csv = CsvFile(out) if str(out).lower().endswith(".csv") else None
    path = csv.path if csv is not None else prepare(out, resume)
    a, w = run.cm.arrays(), run.work.arrays()
    y0 = np.concatenate([rep.q, rep.v])
    from ..results.export import marker_targets
    fp = fingerprint(sys, rep, times, rtol, atol, max_step, [p for p, _ in marker_targets(sys.bodies, markers)])
    from ..system.fingerprint import model_digests
    digests = model_digests(sys.model)
    state = _load_checkpoint(path, fp, digests) if resume and csv is None else None
    if state is None:
        for p in () if csv is not None else path.iterdir():
            p.unlink()
        y = run.state_of(y0)
        f = np.zeros(len(y))
        if watch:   # as in memory: the initial modes, then the kernel's own start (h = 0: f, the starting
            if run.friction is not None:   # step and the switching values there)
                run.friction.decide(float(times[0]), y)
            st = np.array([times[0], 0.0])
        else:
            status = fastdop.rhs(a, w, times[0], y, f, True)
            if status != 0:
                raise SolverError(_MESSAGES.get(status, "integration failed") + " at the start",
                                  time=float(times[0]))
            st = np.array([times[0], initial_step(a, w, float(times[0]), y, f, run.rtol, run.atol,
                                                  run.max_step)])
        chunk, i0, ylast, prev_row = 0, 1, y0.copy(), None
        if csv is None:
            _write_meta(path, fp, times, rtol, atol, digests)
    else:
        chunk, i0, st, y, f, stats, ylast, prev_row, events = state
        run.stats[:] = stats
        stream_events.restore(run, events, float(st[0]))
    n, ns = len(y0), len(y)
    K, F, sc = np.zeros((16, ns)), np.zeros((7, ns)), np.zeros((4, ns))
    SY, ST, nsv = np.zeros((0, ns)), np.zeros((0, 2)), np.zeros(1, np.int64)
    t_end, nout = float(times[-1]), len(times)
    from ..results.diagnostics import compact_tail, monitor as run_monitors
    diag = None
    kept = [] if nout * n * 8 <= STREAM_KEEP else None   # a long run keeps nothing but the current part
    status, error, last = 0, None, (np.asarray(times[i0 - 1:i0], float), ylast[None, :], None)
    stopped = None   # the message of a sensor's stop
    while i0 < nout and stopped is None:
        g0 = i0 - 1                                # global index of row 0 (the previous chunk's last output)
        L = min(CHUNK_ROWS + MARGIN + 1, nout - g0)
        Y = np.zeros((L, n))
        Y[0] = ylast
        iout = 1
        t_part = time.monotonic()
        # the kernels' work arrays at the carried state exactly as the step loop leaves them (the output
        # projection reuses the factorisation there): same whether the previous chunk ran in this process
        if run.friction is not None:   # the modes in force (the previous part's outputs set theirs)
            run.friction.set_modes(float(st[0]))
        fastdop.rhs(a, w, st[0], y, np.zeros(ns), True)
        try:
            while status == 0 and iout < min(CHUNK_ROWS + 1, L):
                saved = (st.copy(), y.copy(), f.copy(), run.stats.copy(), stream_events.event_state(run))
                tout = np.asarray(times[g0:g0 + L], float)
                status, got = fastdop.run(a, w, fastdop.COEFFS, st, y, f, t_end, tout, iout, Y, run.rtol, run.atol,
                                          run.max_step, run.max_steps, max(1, min(CHUNK, CHUNK_ROWS + 1 - iout)), 1e-12,
                                          run.stats, K, F, sc, stiff_check and chunk == 0 and state is None, SY,
                                          ST, nsv, watch)
                if status in (0, fastdop.FRICTION_EVENT, fastdop.SENSOR_STOP) and got == L and g0 + L < nout and \
                        times[g0 + L] <= st[0] + 1e-14 * max(1.0, abs(st[0])):
                    # the last step (or the run up to an event) covered outputs beyond the window: redo it from
                    # the saved state into a larger window, so that every step writes all of its outputs
                    # (chunks end at step ends)
                    st[:], y[:], f[:], run.stats[:] = saved[:4]
                    stream_events.set_event_state(run, saved[4])
                    status = 0
                    L = min(2 * L, nout - g0)
                    Y = np.concatenate([Y, np.zeros((L - len(Y), n))])
                    continue
                iout = got
                if status == fastdop.FRICTION_EVENT and st[1] > 0.0:   # decide there, restart (h = 0), as in
                    run.friction.decide(st[0], y)                       # memory (CompiledRun.integrate)
                    st[1], status = 0.0, 0
                elif status == fastdop.EVENTS_FULL:
                    run._take_events()
                    status = 0
                results_stream.notify(progress, st[0])
                if iout > 1 and time.monotonic() - t_part >= results_stream.WRITE_INTERVAL:
                    break   # a part every WRITE_INTERVAL s of wall time too (at a step end, as any part, with
                    # at least one new output: outputs further apart than that are written as they come)
        except KeyboardInterrupt:
            status = INTERRUPTED
        except results_stream.ProgressError as exc:   # the user's callback raised: the run ends, outputs kept
            status, run.run_error = PROGRESS_FAILED, exc
        status, run.run_error = pyloads.settle(run.pyloads, status, run.run_error)
        if status == STIFF and chunk == 0:   # nothing written yet: the in-memory run hands over to the
            _discard(path, csv)               # implicit method (Radau IIA, joint friction's modes included)
            raise NotCompiled("the model is stiff: run in memory with the implicit hand-over")
        run._take_events()
        if status == FRICTION_FAILED:   # name the element whose coupled solve failed
            run.run_error = run.friction.failure(st[0], y)
        if status == fastdop.SENSOR_STOP:   # the state at the sensor's time is the run's last output
            iout, Y, extra = stream_events.sensor_stop(run, st[0], y, Y, iout, g0, times)
            stop = min((e for e in run.sensor_events if e.action == "stop"), key=lambda e: e.time)
            stopped, status = f"stopped by sensor '{stop.name}' at t = {st[0]:.12g} s", 0
        tout = np.asarray(times[g0:g0 + iout], float) if stopped is None or not extra else \
            np.append(np.asarray(times[g0:g0 + iout - 1], float), st[0])
        i1 = g0 + iout
        rows = Y[:iout]

        def accelerations(ts=tout, Yc=rows):
            VD, LAM = run.outputs(ts, Yc)
            return VD, _full_multipliers(sys, rep.rows, ts, Yc, VD, LAM)

        def result_of(s, e, ts=tout, Yc=rows):
            return Result(sys, ts[s:e], Yc[s:e, :sys.nq], Yc[s:e, sys.nq:], None, None,
                          accelerations=lambda: accelerations(ts[s:e], Yc[s:e]))
        cols = part_columns(result_of, len(tout), prev_row, markers)
        cres = Result(sys, tout, rows[:, :sys.nq], rows[:, sys.nq:], None, None, accelerations=accelerations)
        if monitor:   # history kept as one entry per chunk (its extremes): bounded memory
            n_t, n_c = (0, 0) if diag is None else (len(diag.time), len(diag.constraint_time))
            diag = run_monitors(cres, diag, first=prev_row is None)
            compact_tail(diag, n_t, n_c)
        if len(cols["time [s]"]):
            csv.part(cols) if csv is not None else write_part(path, chunk, cols)
        cres._fr = None   # break the Result <-> lazy frames cycle: the chunk's arrays go now, not at a GC
        last = (tout, rows, accelerations)
        if status != 0:
            if kept is not None:
                kept.append((tout[1:] if prev_row is not None else tout, rows[1:] if prev_row is not None else rows))
            cls = AnalysisInterrupted if status == INTERRUPTED else SolverError
            error = run.run_error or cls(_MESSAGES.get(status, "integration failed"), time=float(st[0]))
            break
        if kept is not None:
            kept.append((tout[1:] if prev_row is not None else tout, rows[1:] if prev_row is not None else rows))
        prev_row, ylast = last_row(cols), rows[-1].copy()
        chunk, i0 = chunk + 1, i1
        if csv is None and stopped is None:
            _save_checkpoint(path, fp, digests, chunk, i0, st, y, f, run.stats, ylast, prev_row,
                             stream_events.events(run))
    ts, rows, acc = last
    if kept is not None and state is None and len(kept) > 1:   # every output fits: the Result holds them all
        ts, rows = np.concatenate([k[0] for k in kept]), np.concatenate([k[1] for k in kept])

        def acc(ts=ts, Yc=rows):
            VD, LAM = run.outputs(ts, Yc)
            return VD, _full_multipliers(sys, rep.rows, ts, Yc, VD, LAM)
    written = (i0 - 1 + len(ts)) if error is not None else (i0 if stopped is not None else nout)
    success = error is None
    message = (stopped or "ok") if success else \
        f"{error}; last good output at t = {ts[-1]:.9g} s (written to {path})"
    res = Result(sys, ts, rows[:, :sys.nq], rows[:, sys.nq:], None, None, success=success,
                 status=0 if success else -1, message=message, accelerations=acc,
                 stats={"steps": int(run.stats[0]), "rejected": int(run.stats[1]), "nfev": int(run.stats[2]),
                        "projections": int(run.stats[3]), "method": "DOP853 (compiled, streamed)", "out": str(path),
                        "samples": int(written), "chunks": chunk + (0 if success else 1), "assembly": rep})
    res.error = error
    res.diagnostics = diag
    if run.sensors:
        res.sensor_events = run.sensor_events
    return res


def _discard(path, csv) -> None:
    """Remove what a streamed run made before its first part (the empty CSV file, or the dataset
    directory with its metadata only)."""
    if csv is not None:
        path.unlink(missing_ok=True)
        return
    for p in path.iterdir():
        p.unlink()
    path.rmdir()


def _write_meta(path, fp, times, rtol, atol, digests):
    meta = {"fingerprint": fp, "start_time": float(times[0]), "end_time": float(times[-1]), "outputs": len(times),
            "rtol": rtol, "atol": atol, "chunk_rows": CHUNK_ROWS, "model": digests}
    _atomic(path / META, lambda p: p.write_text(json.dumps(meta, indent=1)))


def _save_checkpoint(path, fp, digests, chunk, i0, st, y, f, stats, ylast, prev_row, events="{}"):
    def write(p):
        with open(p, "wb") as fh:
            np.savez(fh, fingerprint=np.array(fp), model=np.array(json.dumps(digests, sort_keys=True)), chunk=chunk,
                     i0=i0, st=st, y=y, f=f, stats=stats, ylast=ylast,
                     row=np.array(list(prev_row.values()), float), columns=np.array(list(prev_row)),
                     events=np.array(events))
    _atomic(path / CHECKPOINT, write)


def _load_checkpoint(path, fp, digests):
    """The carried state of the last completed chunk, None when there is none; ModelError when it belongs
    to another run (other settings or another model: the entities whose content differs are named)."""
    file = path / CHECKPOINT
    if not file.exists():
        return None
    with np.load(file) as z:
        theirs = json.loads(str(z["model"])) if "model" in z.files else None
        differ = _differences(theirs, digests)
        if differ:
            raise ModelError("simulate", "resume", f"the checkpoint in {str(path)!r} was written by another model "
                             f"({differ}); run without resume to start afresh")
        if str(z["fingerprint"]) != fp:
            raise ModelError("simulate", "resume", f"the checkpoint in {str(path)!r} belongs to another run (times, "
                             "tolerances, initial state or marker columns differ); run without resume to start afresh")
        prev = dict(zip((str(c) for c in z["columns"]), (float(x) for x in z["row"])))
        events = str(z["events"]) if "events" in z.files else None
        return (int(z["chunk"]), int(z["i0"]), z["st"].copy(), z["y"].copy(), z["f"].copy(), z["stats"].copy(),
                z["ylast"].copy(), prev, events)


def _differences(theirs, ours) -> str:
    """What differs between the checkpoint's model digests and this model's, in words ('' when nothing)."""
    if theirs is None:
        return "the checkpoint has no model digest: written by an older mbdsim"
    changed = [k for k in ours if k in theirs and theirs[k] != ours[k]]
    added, missing = [k for k in ours if k not in theirs], [k for k in theirs if k not in ours]
    words = [f"{', '.join(v[:5])}{' ...' if len(v) > 5 else ''} {what}" for v, what in
             ((changed, "differ" if len(changed) > 1 else "differs"), (added, "added"), (missing, "missing")) if v]
    return "; ".join(words)


# ----------------------------------------------------------------------------- in-memory fallback
def write_result(res: Result, out, markers=False) -> Result:
    """Write a Result computed in memory in the same layout (parts of CHUNK_ROWS rows, no checkpoint)."""
    from ..results.export import columns
    path = prepare(out, resume=False)
    cols = columns(res, markers)
    n = len(cols["time [s]"])
    for k, start in enumerate(range(0, max(n, 1), CHUNK_ROWS)):
        write_part(path, k, {c: v[start:start + CHUNK_ROWS] for c, v in cols.items()})
    res.stats["out"], res.stats["samples"] = str(path), n
    return res

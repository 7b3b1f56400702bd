"""Results written to disk while a run goes (`mb.simulate(..., out=path)`, `mb.kinematics(..., out=path)`,
`mbdsim run --out`).

The file holds `res.to_dataframe()` of every output computed so far (.parquet through pyarrow, or .csv).
It is rewritten as a whole, atomically (a temporary file beside it, then `os.replace`), at most every
WRITE_INTERVAL seconds of wall time and never more often than every 4 times the duration of the last
write (so writing costs at most about a fifth of the run), and once more at the end with the complete
Result.  So a long run that is interrupted (Ctrl-C, a failure, a killed process) leaves a valid file
with everything up to the last write, readable with pandas; the column names and values are those of
`to_dataframe()` (continuous angles and quaternion signs need the samples before them, hence rewriting
the whole table instead of appending independent chunks).

An existing `out` file is replaced only when mbdsim wrote it (`ours`): a Parquet file carrying the
"mbdsim" schema metadata key that `write_parquet` sets, or a table (.parquet or .csv) whose header is one
of mbdsim's (first column "time [s]", every column "name [unit]"); any other file, or anything that is
not a regular file, is refused with a ModelError naming `out` before the run starts.

Solvers report through `notify(progress, t, build)`: `progress(t)` for the user's callback, and, when
`progress` is a RunMonitor, `build()` (a Result of the outputs so far) is called only when a write is due.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from ..errors import EvaluationError, ModelError

WRITE_INTERVAL = 2.0          # s of wall time between two writes, at least
SUFFIXES = (".parquet", ".csv")
MARKER = {b"mbdsim": b"results"}   # Parquet schema metadata of every table mbdsim writes


class ProgressError(EvaluationError):
    """The user's progress callback raised: the analysis ends with success=False and this in res.error,
    keeping every output before it."""


def check_progress(progress, entity: str) -> None:
    """ModelError naming `entity`.progress unless progress is None or callable (checked before any work)."""
    if progress is not None and not callable(progress):
        raise ModelError(entity, "progress", f"expected True, False, None or a callable progress(t) of the time "
                         f"reached [s], got {progress!r}")


def notify(progress, t, build=None) -> None:
    """Tell `progress` (None, a callable of t [s], or a RunMonitor) the time reached and, for a RunMonitor,
    offer `build` (a zero-argument callable returning the Result of the outputs so far). An exception
    from the callback is raised as a ProgressError (the solvers end the run with it, outputs kept)."""
    if progress is None:
        return
    try:
        progress(float(t))
    except ProgressError:
        raise
    except Exception as exc:  # noqa: BLE001 - any failure of the user's callback ends the run, named
        raise ProgressError("analysis", "progress", f"the progress callback raised {type(exc).__name__}: {exc}",
                            time=float(t)) from exc
    offer = getattr(progress, "offer", None)
    if offer is not None and build is not None:
        offer(build)


def _arrow_columns(cols: dict) -> list:
    """{column name: 1-D float array} as Arrow float64 arrays over the same buffers (no copy for
    contiguous float arrays; pa.array on numpy would import pandas); ValueError for another shape."""
    import pyarrow as pa
    out = []
    for name, v in cols.items():
        x = np.ascontiguousarray(v, dtype=float)
        if x.ndim != 1:
            raise ValueError(f"column {name!r}: expected a 1-D array, got shape {x.shape}")
        out.append(pa.Array.from_buffers(pa.float64(), len(x), [None, pa.py_buffer(x)]))
    return out


def write_parquet(cols: dict, path) -> None:
    """Write {column name: 1-D float array} as a Parquet file with pyarrow alone: the arrays are wrapped as
    Arrow buffers (pa.array / pa.table on numpy arrays would import pandas, ~75 MB resident, which
    nothing on the writing path needs). pandas.read_parquet reads the file."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    arrays = _arrow_columns(cols)
    # float columns: dictionary pages only cost memory (~4 MB) and space (nearly every value is distinct)
    table = pa.Table.from_arrays(arrays, names=list(cols)).replace_schema_metadata(MARKER)
    pq.write_table(table, path, use_dictionary=False)


def write_csv(cols: dict, fh, header: bool = True) -> None:
    """Write {column name: 1-D float array} as CSV rows to the binary file `fh` (with the header row when
    `header`) through pyarrow (no pandas frame: bounded by the columns given); floats as the shortest text
    that reads back to the same double, integral values with ".0" ("0.0", not "0") so that pandas reads
    every column back as float."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.csv as pcsv
    arrays = []
    for a in _arrow_columns(cols):
        text = pc.cast(a, pa.string())
        integral = pc.and_(pc.equal(pc.floor(a), a), pc.less(pc.abs(a), 1e15))
        arrays.append(pc.if_else(integral, pc.binary_join_element_wise(text, ".0", ""), text))
    table = pa.Table.from_arrays(arrays, names=list(cols))
    pcsv.write_csv(table, fh, write_options=pcsv.WriteOptions(include_header=header, quoting_style="none",
                                                              batch_size=4096))


def _mbdsim_header(names) -> bool:
    """Column names of an mbdsim table: "time [s]" first, every one "name [unit]"."""
    names = list(names)
    return bool(names) and names[0] == "time [s]" and all(" [" in n and n.endswith("]") for n in names)


def ours(path: Path) -> bool:
    """Whether the regular file `path` is a results table mbdsim wrote (see the module docstring)."""
    try:
        if path.suffix.lower() == ".parquet":
            import pyarrow.parquet as pq
            schema = pq.read_schema(path)
            return (schema.metadata or {}).get(b"mbdsim") == MARKER[b"mbdsim"] or _mbdsim_header(schema.names)
        if path.suffix.lower() == ".csv":
            with open(path, encoding="utf-8", errors="replace", newline="") as fh:
                import csv
                header = next(csv.reader([fh.readline(65536)]), [])
            return _mbdsim_header(header)
    except Exception:  # noqa: BLE001 - unreadable or not a table: not ours
        return False
    return False


def check_replaceable(path: Path, entity: str = "simulate") -> None:
    """ModelError when `path` exists and is not a results file mbdsim wrote (a foreign file, a directory
    that is not a run's, a FIFO or device): nothing the user made is overwritten."""
    if not os.path.lexists(path) or path.is_dir():
        return
    if path.is_symlink() or not path.is_file():
        raise ModelError(entity, "out", f"{str(path)!r} exists and is not a regular file; choose a new path")
    if not ours(path):
        raise ModelError(entity, "out", f"{str(path)!r} exists and was not written by mbdsim (not one of its "
                         "results tables); choose a new path or remove the file")


def out_file(path, entity: str = "simulate") -> Path:
    """`path` as the results file of an analysis: a .parquet or .csv path that is not a directory and
    that mbdsim may replace (check_replaceable); ModelError naming entity.out otherwise."""
    try:
        out = Path(os.fspath(path))
    except TypeError:
        raise ModelError(entity, "out", f"expected a file path, got {path!r}") from None
    if out.suffix.lower() not in SUFFIXES:
        raise ModelError(entity, "out", f"{str(out)!r}: expected a .parquet or .csv file")
    if out.is_dir():
        raise ModelError(entity, "out", f"{str(out)!r} is a directory")
    check_replaceable(out, entity)
    return out


class ResultFile:
    """The results table of one run, rewritten on disk as the run goes (see the module docstring)."""

    def __init__(self, path, entity="simulate", markers=False):
        self.markers = markers     # marker columns: results.export.marker_targets
        self.path = out_file(path, entity)
        self.last, self.cost, self.build, self.writes = time.monotonic(), 0.0, None, 0

    def offer(self, build) -> None:
        """Remember the latest builder; write its Result when a write is due."""
        self.build = build
        if time.monotonic() - self.last >= max(WRITE_INTERVAL, 4.0 * self.cost):
            self.write(build())

    def write(self, res) -> None:
        """Write the table of `res.to_dataframe()` atomically (OSError when the file cannot be written)."""
        t0 = time.monotonic()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        tmp = self.path.with_name(f".{self.path.name}.partial")
        if self.path.suffix.lower() == ".parquet":   # pyarrow directly: no pandas import to write
            from .export import columns
            write_parquet(columns(res, self.markers), tmp)
        else:   # pyarrow's CSV writer from the columns: no pandas frame beside them
            from .export import columns
            if len(res.time) == 0:
                res.to_dataframe()   # the ModelError of an empty result
            with open(tmp, "wb") as fh:
                write_csv(columns(res, self.markers), fh)
        os.replace(tmp, self.path)
        self.writes += 1
        self.last = time.monotonic()
        self.cost = self.last - t0

    def salvage(self) -> None:
        """After an exception ended the run: write the outputs offered last, if any (best effort)."""
        if self.build is not None:
            try:
                self.write(self.build())
            except Exception:  # noqa: BLE001 - the original exception is what the caller sees
                pass


class RunMonitor:
    """What solvers receive as `progress` when a run writes its results as it goes: calls the user's
    progress(t) and hands the outputs so far to a ResultFile."""

    def __init__(self, progress, file: ResultFile, entity="simulate"):
        check_progress(progress, entity)
        self.progress, self.file = progress, file

    def __call__(self, t) -> None:
        if self.progress is not None:
            self.progress(t)

    def offer(self, build) -> None:
        self.file.offer(build)


def run_writing(run, progress, out, entity, markers=False):
    """`run(progress)` (an analysis taking a progress argument) with its results written to `out` as it goes
    (None: just run it), with the marker columns `markers` selects (results.export.marker_targets). The
    final file is the complete Result's table, also when the run stopped early."""
    check_progress(progress, entity)
    if out is None:
        return run(progress)
    file = ResultFile(out, entity, markers)
    monitor = RunMonitor(progress, file, entity)
    try:
        res = run(monitor)
    except BaseException:
        file.salvage()
        raise
    try:
        file.write(res)
    except OSError as exc:
        raise ModelError(entity, "out", f"cannot write {str(file.path)!r}: {exc}") from None
    return res

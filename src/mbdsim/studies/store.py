"""Results of a study on disk: every row is appended to a journal as it arrives, and the Parquet file is
rewritten from all rows now and then (atomically) and when the study ends.

A Parquet file cannot be appended to, and rewriting it after every run costs more than a slider-crank
variant (15-20 ms per write on this machine), so each batch of rows is first appended to the journal
`.NAME.journal` beside the file (JSON lines, flushed: a few microseconds), and the Parquet file is
rewritten at most every FLUSH_INTERVAL seconds, then once more at the end (also after an error or
Ctrl-C), which removes the journal.  A study killed outright leaves the Parquet file plus the journal;
`load_rows` reads both, so a re-run with the same file skips every run that finished: nothing is lost.
"""
from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

import pandas as pd

from ..errors import ModelError

__all__ = ["load_rows", "write_rows", "journal_path", "RowStore", "STUDY_COLUMN", "FLUSH_INTERVAL"]

STUDY_COLUMN = "study_id"
FLUSH_INTERVAL = 2.0      # seconds between two rewrites of the Parquet file while a study runs


def journal_path(out) -> Path:
    """The journal of the results file `out`: '.NAME.journal' in the same folder."""
    path = Path(out)
    return path.with_name(f".{path.name}.journal")


def _read_journal(path: Path) -> pd.DataFrame | None:
    """Rows of a journal (a line cut short by a kill is skipped); None when there is none."""
    if not path.exists():
        return None
    rows = []
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            try:
                rows.append(json.loads(line))
            except json.JSONDecodeError:
                continue        # the last line of a killed study, half written
    return pd.DataFrame(rows) if rows else None


def load_rows(out, study_id: str) -> pd.DataFrame | None:
    """Rows already stored for this study in `out` and its journal (None when there are none).

    Raises ModelError when the file holds another study's results (other model, parameters, analysis or
    outputs), so that a changed study never mixes with old rows."""
    path = Path(out)
    frames = []
    if path.exists():
        try:
            frames.append(pd.read_parquet(path))
        except Exception as exc:  # noqa: BLE001 - pyarrow's errors vary: name the file
            raise ModelError("study", "out", f"cannot read {str(path)!r} as Parquet: {exc}") from None
    journal = _read_journal(journal_path(path))
    if journal is not None:
        frames.append(journal)
    if not frames:
        return None
    for df in frames:
        if STUDY_COLUMN not in df.columns or "run" not in df.columns:
            raise ModelError("study", "out", f"{str(path)!r} is not a study result file (no {STUDY_COLUMN!r} column)")
        if set(df[STUDY_COLUMN].unique()) - {study_id}:
            raise ModelError("study", "out", f"{str(path)!r} holds results of another study (the model, parameters, "
                             "analysis or outputs differ); remove it or choose another file")
    df = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    return df.drop_duplicates("run", keep="first").reset_index(drop=True)


def write_rows(out, df: pd.DataFrame) -> None:
    """Write all rows to `out` (a temporary file renamed over it: never a half-written file)."""
    path = Path(out)
    if path.parent and not path.parent.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    df.to_parquet(tmp, index=False)
    os.replace(tmp, path)


def _jsonable(value):
    if isinstance(value, float) and not math.isfinite(value):
        return value            # json writes NaN / Infinity and reads them back
    if hasattr(value, "item"):
        return value.item()     # numpy scalars
    return value


class RowStore:
    """The rows of one study run going to `out` (None: kept in memory only).

    `append(rows)` journals the rows (a DataFrame or a list of dicts) and rewrites the Parquet file when
    FLUSH_INTERVAL has passed; `close()` writes the Parquet file with every row and removes the journal.
    Rows given as dicts stay dicts until a Parquet write (no DataFrame per batch: a study in this process
    journals every run as it finishes)."""

    def __init__(self, out, previous: pd.DataFrame | None, interval: float = FLUSH_INTERVAL):
        self.out = None if out is None else Path(out)
        self.frames = [] if previous is None else [previous]
        self.rows = []
        self.interval = interval
        self._last = time.monotonic()
        self._dirty = False
        self._journal = None
        if self.out is not None:
            if self.out.parent and not self.out.parent.exists():
                self.out.parent.mkdir(parents=True, exist_ok=True)
            self._journal = open(journal_path(self.out), "a", encoding="utf-8")
            if self._journal.tell() > 0:     # a killed run's journal (read into `previous`): fold it in now
                self._dirty = previous is not None
                self.flush()
                self._journal.truncate(0)

    def append(self, rows) -> None:
        if isinstance(rows, pd.DataFrame):
            self.frames.append(rows)
            rows = rows.to_dict("records") if self._journal is not None else []
        else:
            self.rows.extend(rows)
        if self._journal is None:
            return
        lines = "".join(json.dumps({k: _jsonable(v) for k, v in row.items()}) + "\n" for row in rows)
        self._journal.write(lines)
        self._journal.flush()
        self._dirty = True
        if time.monotonic() - self._last >= self.interval:
            self.flush()

    def flush(self) -> None:
        """Rewrite the Parquet file with every row; the journal starts afresh."""
        if self.out is None or not self._dirty:
            return
        write_rows(self.out, pd.concat(self.frames + ([pd.DataFrame(self.rows)] if self.rows else []),
                                       ignore_index=True))
        self._journal.seek(0)
        self._journal.truncate()
        self._last, self._dirty = time.monotonic(), False

    def close(self) -> None:
        if self._journal is None:
            return
        try:
            self.flush()
        finally:
            self._journal.close()
            self._journal = None
            path = journal_path(self.out)
            if path.exists() and path.stat().st_size == 0:
                path.unlink()

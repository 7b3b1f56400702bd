"""Results of a study on disk: a Parquet file rewritten atomically as rows arrive, so a killed study
leaves every finished row readable and a re-run with the same file skips them."""
from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from ..errors import ModelError

__all__ = ["load_rows", "write_rows", "STUDY_COLUMN"]

STUDY_COLUMN = "study_id"


def load_rows(out, study_id: str) -> pd.DataFrame | None:
    """Rows already stored in `out` for this study (None when the file does not exist).

    Raises ModelError when the file holds another study's results (other model, parameters, analysis or
    outputs), so that a changed study never mixes with old rows."""
    path = Path(out)
    if not path.exists():
        return None
    try:
        df = pd.read_parquet(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow's errors vary: name the file
        raise ModelError("study", "out", f"cannot read {str(path)!r} as Parquet: {exc}") from None
    if STUDY_COLUMN not in df.columns or "run" not in df.columns:
        raise ModelError("study", "out", f"{str(path)!r} is not a study result file (no {STUDY_COLUMN!r} column)")
    others = set(df[STUDY_COLUMN].unique()) - {study_id}
    if others:
        raise ModelError("study", "out", f"{str(path)!r} holds results of another study (the model, parameters, "
                         "analysis or outputs differ); remove it or choose another file")
    return df


def write_rows(out, df: pd.DataFrame) -> None:
    """Write all rows to `out` (a temporary file renamed over it: never a half-written file)."""
    path = Path(out)
    if path.parent and not path.parent.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    df.to_parquet(tmp, index=False)
    os.replace(tmp, path)

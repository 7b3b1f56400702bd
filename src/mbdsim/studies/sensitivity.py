"""Sensitivity of a study's outputs to its parameters, from the runs themselves (no extra runs).

- "src": standardised regression coefficients of a linear least-squares fit, SRC_j = b_j std(x_j)/std(y),
  with the fit's R^2 (SRC^2 sums to R^2 for independent parameters; trust them when R^2 is near 1).
- "sobol": first-order Sobol indices S_j = Var(E[y | x_j]) / Var(y), E[y | x_j] estimated by the mean of
  y within groups of x_j (its distinct values on a grid, else quantile bins); valid for any design with
  independent parameters (grid, Latin hypercube, Sobol or Monte Carlo samples).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import ModelError

__all__ = ["sensitivity", "study_columns"]


def study_columns(df: pd.DataFrame, parameters=None, outputs=None) -> tuple[list, list]:
    """(parameters, outputs) of a study DataFrame: the given ones, else from df.attrs (set by Study.run)."""
    params = list(parameters) if parameters is not None else list(df.attrs.get("parameters", []))
    outs = list(outputs) if outputs is not None else list(df.attrs.get("outputs", []))
    if not params or not outs:
        raise ModelError("sensitivity", "parameters" if not params else "outputs",
                         "name the parameter and output columns (this DataFrame does not record them)")
    missing = [c for c in params + outs if c not in df.columns]
    if missing:
        raise ModelError("sensitivity", "columns", f"{missing[0]!r} is not a column; columns: {', '.join(df.columns)}")
    return params, outs


def _numeric(df, cols):
    return [c for c in cols if pd.api.types.is_numeric_dtype(df[c]) and df[c].nunique() > 1]


def _src(X: np.ndarray, y: np.ndarray):
    xs, ys = X.std(axis=0), y.std()
    A = np.column_stack([np.ones(len(y)), X])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    fit = A @ coef
    r2 = 1.0 - np.sum((y - fit) ** 2) / np.sum((y - y.mean()) ** 2) if ys > 0 else np.nan
    return (coef[1:] * xs / ys if ys > 0 else np.full(X.shape[1], np.nan)), r2


def first_order_index(x: np.ndarray, y: np.ndarray, bins: int | None = None) -> float:
    """Var(E[y|x]) / Var(y) with E[y|x] the mean of y over groups of x (distinct values or quantile bins)."""
    var = y.var()
    if not var > 0:
        return np.nan
    levels = np.unique(x)
    if len(levels) <= 20 and bins is None:
        groups = np.searchsorted(levels, x)
    else:
        nb = bins or int(np.clip(np.sqrt(len(x)) / 2, 2, 20))
        edges = np.quantile(x, np.linspace(0, 1, nb + 1)[1:-1])
        groups = np.searchsorted(edges, x, side="right")
    counts = np.bincount(groups)
    means = np.bincount(groups, weights=y) / np.where(counts > 0, counts, 1)
    ok = counts > 0
    return float(np.sum(counts[ok] * (means[ok] - y.mean()) ** 2) / len(y) / var)


def sensitivity(df: pd.DataFrame, parameters=None, outputs=None, method: str = "src") -> pd.DataFrame:
    """Sensitivity table: one row per (output, parameter), from the runs with status 'ok'.

    method "src": columns src (standardised regression coefficient, signed) and r2 (of the output's
    linear fit); "sobol": column S1 (first-order Sobol index, 0..1).  Parameters that are not numeric or
    do not vary are left out.  Raises ModelError for unknown columns or methods."""
    if method not in ("src", "sobol"):
        raise ModelError("sensitivity", "method", f"unknown method {method!r}; choose 'src' or 'sobol'")
    params, outs = study_columns(df, parameters, outputs)
    ok = df[df["status"] == "ok"] if "status" in df.columns else df
    params = _numeric(ok, params)
    rows = []
    for out in outs:
        sub = ok[params + [out]].dropna()
        if len(sub) < len(params) + 2 or not params:
            continue
        X, y = sub[params].to_numpy(float), sub[out].to_numpy(float)
        if method == "src":
            src, r2 = _src(X, y)
            rows += [{"output": out, "parameter": p, "src": float(s), "r2": float(r2)} for p, s in zip(params, src)]
        else:
            rows += [{"output": out, "parameter": p, "S1": first_order_index(X[:, k], y)} for k, p in enumerate(params)]
    cols = ["output", "parameter"] + (["src", "r2"] if method == "src" else ["S1"])
    return pd.DataFrame(rows, columns=cols).set_index(["output", "parameter"])

"""Plots of study results: main effects, a scatter matrix, and a response surface over two parameters.
Each returns a matplotlib Figure (not shown; save it with fig.savefig)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import ModelError
from .sensitivity import study_columns

__all__ = ["plot_study"]

KINDS = ("main_effects", "scatter_matrix", "surface")


def _ok(df):
    return df[df["status"] == "ok"] if "status" in df.columns else df


def _binned_mean(x, y, nb=10):
    levels = np.unique(x)
    if len(levels) <= nb:
        return levels, np.array([y[x == v].mean() for v in levels])
    edges = np.quantile(x, np.linspace(0, 1, nb + 1))
    idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, nb - 1)
    keep = [k for k in range(nb) if np.any(idx == k)]
    return (np.array([x[idx == k].mean() for k in keep]), np.array([y[idx == k].mean() for k in keep]))


def _main_effects(df, params, outs):
    from matplotlib.figure import Figure
    fig = Figure(figsize=(3.2 * len(params), 2.6 * len(outs)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(outs), len(params), squeeze=False))
    for i, out in enumerate(outs):
        for j, p in enumerate(params):
            ax = axes[i, j]
            x, y = df[p].to_numpy(float), df[out].to_numpy(float)
            ax.plot(x, y, ".", color="0.7", ms=3)
            bx, by = _binned_mean(x, y)
            ax.plot(bx, by, "o-", color="C0")
            ax.set_xlabel(p) if i == len(outs) - 1 else None
            ax.set_ylabel(out) if j == 0 else None
    fig.suptitle("main effects (mean of each output over the other parameters)")
    return fig


def _scatter_matrix(df, cols):
    from matplotlib.figure import Figure
    n = len(cols)
    fig = Figure(figsize=(2.2 * n, 2.2 * n), layout="constrained")
    axes = fig.subplots(n, n, squeeze=False)
    pd.plotting.scatter_matrix(df[cols].astype(float), ax=axes, diagonal="hist", s=8)
    return fig


def _surface(df, x, y, out):
    from matplotlib.figure import Figure
    from matplotlib.tri import Triangulation
    fig = Figure(figsize=(5.5, 4.5), layout="constrained")
    ax = fig.subplots()
    px, py, z = (df[c].to_numpy(float) for c in (x, y, out))
    if len(np.unique(np.column_stack([px, py]), axis=0)) >= 3:
        cs = ax.tricontourf(Triangulation(px, py), z, levels=14, cmap="viridis")
        fig.colorbar(cs, ax=ax, label=out)
    ax.scatter(px, py, c="k", s=6)
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_title(f"{out} over {x} and {y}")
    return fig


def plot_study(df: pd.DataFrame, kind: str = "main_effects", parameters=None, outputs=None,
               x: str | None = None, y: str | None = None, output: str | None = None):
    """A Figure of study results (runs with status 'ok'):

    kind "main_effects": each output against each parameter, runs as dots and the mean per value (or
    quantile bin) as a line; "scatter_matrix": pairwise scatter of parameters and outputs; "surface": a
    response surface (filled contours over the runs) of `output` over parameters `x` and `y` (default:
    the first output over the first two parameters).  parameters/outputs default to those recorded by
    Study.run in df.attrs."""
    if kind not in KINDS:
        raise ModelError("plot_study", "kind", f"unknown kind {kind!r}; choose from {', '.join(KINDS)}")
    params, outs = study_columns(df, parameters, outputs)
    data = _ok(df)
    if data.empty:
        raise ModelError("plot_study", "df", "no run with status 'ok' to plot")
    numeric = [p for p in params if pd.api.types.is_numeric_dtype(data[p])]
    if kind == "main_effects":
        return _main_effects(data, numeric, outs)
    if kind == "scatter_matrix":
        return _scatter_matrix(data, numeric + outs)
    x, y = x or numeric[0], y or (numeric[1] if len(numeric) > 1 else None)
    if y is None:
        raise ModelError("plot_study", "y", "a response surface needs two numeric parameters")
    for name, col in (("x", x), ("y", y), ("output", output or outs[0])):
        if col not in data.columns:
            raise ModelError("plot_study", name, f"{col!r} is not a column")
    return _surface(data, x, y, output or outs[0])

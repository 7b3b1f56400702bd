"""Plots of study results: main effects, a scatter matrix, and a response surface over two parameters.
Each returns a matplotlib Figure (not shown; save it with fig.savefig).  Axes are labelled with the
columns' SI units when known (df.attrs['units'], set by Study.run, or the `units` argument)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import ModelError
from .sensitivity import first_order_index, study_columns
from .units import pretty

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


def _label(col, units) -> str:
    u = units.get(col, "")
    return f"{col} [{pretty(u)}]" if u else col


def _main_effects(df, params, outs, units):
    import textwrap

    from matplotlib.figure import Figure
    width = max(3.2 * len(params), 4.0)
    fig = Figure(figsize=(width, 2.6 * len(outs) + 0.4), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(outs), len(params), squeeze=False))
    for i, out in enumerate(outs):
        for j, p in enumerate(params):
            ax = axes[i, j]
            x, y = df[p].to_numpy(float), df[out].to_numpy(float)
            ax.plot(x, y, ".", color="0.7", ms=3)
            bx, by = _binned_mean(x, y)
            ax.plot(bx, by, "o-", color="C0")
            ax.set_xlabel(_label(p, units)) if i == len(outs) - 1 else None
            ax.set_ylabel(_label(out, units)) if j == 0 else None
    title = "main effects (mean of each output over the other parameters)"
    fig.suptitle(textwrap.fill(title, int(width * 9)), fontsize="medium")   # ~9 characters per inch
    return fig


def _scatter_matrix(df, cols, units):
    from matplotlib.figure import Figure
    n = len(cols)
    fig = Figure(figsize=(2.2 * n, 2.2 * n), layout="constrained")
    axes = fig.subplots(n, n, squeeze=False)
    pd.plotting.scatter_matrix(df[cols].astype(float), ax=axes, diagonal="hist", s=8)
    for j, col in enumerate(cols):
        axes[-1, j].set_xlabel(_label(col, units))
        axes[j, 0].set_ylabel(_label(col, units))
    return fig


def _surface(df, x, y, out, units):
    from matplotlib.figure import Figure
    from matplotlib.tri import Triangulation
    fig = Figure(figsize=(5.5, 4.5), layout="constrained")
    ax = fig.subplots()
    px, py, z = (df[c].to_numpy(float) for c in (x, y, out))
    if len(np.unique(np.column_stack([px, py]), axis=0)) >= 3:
        cs = ax.tricontourf(Triangulation(px, py), z, levels=14, cmap="viridis")
        fig.colorbar(cs, ax=ax, label=_label(out, units))
    ax.scatter(px, py, c="k", s=6)
    ax.set_xlabel(_label(x, units))
    ax.set_ylabel(_label(y, units))
    ax.set_title(f"{out} over {x} and {y}")
    return fig


def dominant_parameters(df: pd.DataFrame, params: list, output: str, n: int = 2) -> list:
    """The `n` parameters with the largest main effect on `output`: the first-order index
    Var(E[output | p]) / Var(output) (variance of the per-level or per-bin means); ties keep the given order."""
    y = df[output].to_numpy(float)
    ok = np.isfinite(y)
    effect = []
    for p in params:
        x = df[p].to_numpy(float)
        keep = ok & np.isfinite(x)
        s = first_order_index(x[keep], y[keep]) if keep.sum() > 2 and np.unique(x[keep]).size > 1 else np.nan
        effect.append(-1.0 if not np.isfinite(s) else s)
    order = sorted(range(len(params)), key=lambda k: (-effect[k], k))
    return [params[k] for k in order[:n]]


def plot_study(df: pd.DataFrame, kind: str = "main_effects", parameters=None, outputs=None,
               x: str | None = None, y: str | None = None, output: str | None = None, units: dict | None = None):
    """A Figure of study results (runs with status 'ok'):

    kind "main_effects": each output against each parameter, runs as dots and the mean per value (or
    quantile bin) as a line; "scatter_matrix": pairwise scatter of parameters and outputs; "surface": a
    response surface (filled contours over the runs) of `output` (default: the first output) over
    parameters `x` and `y`; by default the two with the largest main effect on `output`
    (dominant_parameters), or, given only `x`, `x` and the most influential other one.
    parameters/outputs default to those recorded by Study.run in df.attrs.  units: column -> SI unit
    for the axis labels ("m", "N"), added to df.attrs['units'] (recorded by Study.run)."""
    if kind not in KINDS:
        raise ModelError("plot_study", "kind", f"unknown kind {kind!r}; choose from {', '.join(KINDS)}")
    params, outs = study_columns(df, parameters, outputs)
    data = _ok(df)
    if data.empty:
        raise ModelError("plot_study", "df", "no run with status 'ok' to plot")
    numeric = [p for p in params if pd.api.types.is_numeric_dtype(data[p])]
    units = {**df.attrs.get("units", {}), **(units or {})}
    if kind == "main_effects":
        return _main_effects(data, numeric, outs, units)
    if kind == "scatter_matrix":
        return _scatter_matrix(data, numeric + outs, units)
    output = output or outs[0]
    for name, col in (("x", x), ("y", y), ("output", output)):
        if col is not None and col not in data.columns:
            raise ModelError("plot_study", name, f"{col!r} is not a column")
    if x is None or y is None:
        ranked = dominant_parameters(data, [p for p in numeric if p not in (x, y)], output, 2)
        if x is None and ranked:
            x = ranked.pop(0)
        if y is None and ranked:
            y = ranked.pop(0)
    if x is None or y is None:
        raise ModelError("plot_study", "y", "a response surface needs two numeric parameters")
    return _surface(data, x, y, output, units)

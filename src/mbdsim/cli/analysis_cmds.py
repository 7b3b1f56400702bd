"""``mbdsim kinematics``, ``mbdsim statics`` and ``mbdsim modes``: the other analyses of a model file.

Commands::

    mbdsim kinematics MODEL --end T [--step DT] [--out results.parquet|.csv] [--markers | --marker NAME] [--debug]
    mbdsim statics MODEL [--end T [--step DT]] [--out results.parquet|.csv] [--debug]
    mbdsim modes MODEL [--at equilibrium|initial] [--out modes.csv|.parquet] [--debug]

``kinematics`` is `mb.kinematics` (every degree of freedom driven); ``statics`` is `mb.equilibrium`
(static equilibrium at t = 0), or with ``--end`` `mb.quasi_static` (the equilibrium at every output time
while the motions move the mechanism); ``modes`` linearizes (`mb.linearize`) about the static equilibrium
(default) or the assembled initial state and prints the natural frequencies [Hz] and damping ratios
(`Linearization.modes()`). ``--out`` writes the results table (`res.to_dataframe()`, as ``mbdsim run``)
or, for ``modes``, the modes table. Exit status as ``mbdsim run``: 0 success; 1 the analysis failed or a
file could not be written; 2 bad input; 130 interrupted. Only typer is imported here.
"""
from __future__ import annotations

import math
import os
import time
import warnings
from pathlib import Path
from typing import List, Optional

import typer

from .run_cmds import (ALL_MARKERS_OPT, DEBUG_OPT, EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, MARKER_OPT,
                       MODEL_ARG, OUT_SUFFIXES, _bar, _console, _fail, _guard, _load, _markers, _note_cold,
                       _note_markers, _print_table, _rank_dof, _writable)

MODES_COLUMNS = ("mode", "frequency [Hz]", "damped frequency [Hz]", "damping ratio [-]", "eigenvalue.real [rad/s]",
                 "eigenvalue.imag [rad/s]")


def _check_out(out: Optional[Path]) -> None:
    if out is not None and out.suffix.lower() not in OUT_SUFFIXES:
        _fail(f"--out {str(out)!r}: expected a .parquet or .csv file", EXIT_BAD_INPUT)


def _check_span(end: Optional[float], step: Optional[float]) -> None:
    if end is not None and not end > 0:
        _fail(f"--end must be > 0, got {end!r}", EXIT_BAD_INPUT)
    if step is not None and not step > 0:
        _fail(f"--step must be > 0, got {step!r}", EXIT_BAD_INPUT)


def _finish(res, rows, title, out, then=None) -> None:
    """Print the summary table (and then(), when given); exit 130 for an interrupted run, 1 for a failed one."""
    from mbdsim.errors import AnalysisInterrupted
    _print_table(title, rows)
    if then is not None:
        then()
    if out is not None:
        _console().print(f"results: {out} ({len(res.time)} rows)")
    if isinstance(getattr(res, "error", None), AnalysisInterrupted) or "KeyboardInterrupt" in str(
            getattr(res, "error", "")):
        raise typer.Exit(EXIT_INTERRUPTED)
    if not res.success:
        raise typer.Exit(EXIT_FAILED)


# ----------------------------------------------------------------------------- kinematics
def kinematics_cmd(
    model: Path = MODEL_ARG,
    end: float = typer.Option(..., "--end", "-e", metavar="T", help="End time in s."),
    step: Optional[float] = typer.Option(None, "--step", "-s", metavar="DT",
                                         help="Output step in s (default: end/500)."),
    out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="FILE",
                                       help="Write the results table (res.to_dataframe()) to .parquet or .csv "
                                       "as the run goes."),
    every_marker: bool = ALL_MARKERS_OPT,
    marker: Optional[List[str]] = MARKER_OPT,
    debug: bool = DEBUG_OPT,
) -> None:
    """Kinematic analysis of a fully driven model file (zero degrees of freedom): positions, velocities,
    accelerations, reactions and driver efforts at every output time.

    Example: mbdsim kinematics examples/slider_crank.yaml --end 1 --step 0.01 --out kin.parquet

    Exit status: 0 ok, 1 analysis failed, 2 bad input or model file (also: free degrees of freedom), 130
    interrupted."""
    _check_out(out)
    _check_span(end, step)
    markers = _markers(every_marker, marker)
    if markers is not False and out is None:
        _fail("--markers / --marker add columns to the results table: give --out FILE", EXIT_BAD_INPUT)
    _guard(lambda: _kinematics(model, end, step, out, markers), debug)


def _kinematics(path, end, step, out, markers):
    import mbdsim as mb
    m = _load(path)
    _note_cold()
    _note_markers(m, markers)
    dof, n_redundant, redundant = _rank_dof(m)
    t0 = time.perf_counter()
    with warnings.catch_warnings(), _bar(f"kinematics of {m.name}", end) as bar:
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.kinematics(m, end_time=end, output_step=step, progress=bar, out=_writable(out),
                            markers=markers)
    wall = time.perf_counter() - t0
    stats = res.stats or {}
    singular = stats.get("singular") or []
    rows = [("model", f"{m.name} ({path})"), ("DOF (rank)", str(dof)),
            ("redundant constraints", f"{n_redundant} among {', '.join(redundant)}" if redundant else "0"),
            ("method", str(stats.get("method", "kinematic"))),
            ("solved", f"{res.time[0]:.6g} .. {res.time[-1]:.6g} s, {len(res.time)} samples"),
            ("singular samples", str(len(singular))),
            ("wall time", f"{wall:.3f} s"), ("success", f"{res.success} ({res.message})")]
    _finish(res, rows, f"mbdsim kinematics: {m.name}", out)


# ----------------------------------------------------------------------------- statics
def statics_cmd(
    model: Path = MODEL_ARG,
    end: Optional[float] = typer.Option(None, "--end", "-e", metavar="T",
                                        help="Quasi-static analysis from 0 to T s (default: one equilibrium at "
                                        "t = 0)."),
    step: Optional[float] = typer.Option(None, "--step", "-s", metavar="DT",
                                         help="Output step in s of the quasi-static analysis (default: end/500)."),
    out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="FILE",
                                       help="Write the results table (res.to_dataframe()) to .parquet or .csv."),
    debug: bool = DEBUG_OPT,
) -> None:
    """Static equilibrium of a model file (loads balanced by the joints, velocities zero); with --end, the
    quasi-static equilibrium at every output time while the motions move the mechanism.

    Example: mbdsim statics examples/spring_mass_chain.yaml --out eq.csv

    Exit status: 0 ok (an equilibrium found at every time; the table says whether it is stable), 1 analysis
    failed (no equilibrium), 2 bad input or model file, 130 interrupted."""
    _check_out(out)
    _check_span(end, step)
    if step is not None and end is None:
        _fail("--step needs --end (the quasi-static analysis)", EXIT_BAD_INPUT)
    _guard(lambda: _statics(model, end, step, out), debug)


def _statics(path, end, step, out):
    import mbdsim as mb
    from mbdsim.results.stream import ResultFile
    m = _load(path)
    file = None if out is None else ResultFile(_writable(out), "statics")   # refuses a foreign file before the work
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        warnings.simplefilter("ignore", mb.UnstableEquilibriumWarning)     # reported in the table
        if end is None:
            res = mb.equilibrium(m)
        else:
            with _bar(f"quasi-static {m.name}", end) as bar:
                res = mb.quasi_static(m, end_time=end, output_step=step, progress=bar)
    wall = time.perf_counter() - t0
    st = res.stats or {}
    stable = st.get("stable")
    if end is None:
        rows = [("model", f"{m.name} ({path})"), ("analysis", "static equilibrium at t = 0 s"),
                ("method", str(st.get("method", "?"))), ("iterations", str(st.get("iterations", "?"))),
                ("stable", "yes" if stable else "no: " + "; ".join(map(str, st.get("unstable_directions") or [])))]
        if st.get("neutral_directions"):
            rows.append(("neutral directions", "; ".join(map(str, st["neutral_directions"]))))
    else:
        n_stable = int(sum(bool(s) for s in (stable if stable is not None else [])))
        rows = [("model", f"{m.name} ({path})"), ("analysis", "quasi-static"),
                ("solved", f"{res.time[0]:.6g} .. {res.time[-1]:.6g} s, {len(res.time)} samples"),
                ("stable samples", f"{n_stable} of {len(res.time)}")]
    rows += [("wall time", f"{wall:.3f} s"), ("success", f"{res.success} ({res.message})")]
    if file is not None:
        try:
            file.write(res)
        except OSError as exc:
            _fail(f"cannot write {str(out)!r}: {exc}", EXIT_FAILED)
    _finish(res, rows, f"mbdsim statics: {m.name}", out, (lambda: _print_positions(res)) if end is None else None)


def _print_positions(res) -> None:
    """The equilibrium configuration: each body's centre of mass [m] in ground axes."""
    import numpy as np
    rows = []
    pos = {b.name: np.asarray(res.position(b)[0], float) for b in res.system.bodies}
    tiny = 1e-12 * max([1.0] + [float(np.max(np.abs(p))) for p in pos.values()])   # round-off shown as 0
    for name, p in pos.items():
        rows.append((name, *(f"{0.0 if abs(v) < tiny else v:.6g}" for v in p)))
    _print_table("equilibrium: centres of mass", rows, ("body", "x [m]", "y [m]", "z [m]"))


# ----------------------------------------------------------------------------- modes
def modes_cmd(
    model: Path = MODEL_ARG,
    at: str = typer.Option("equilibrium", "--at", metavar="POINT",
                           help="Operating point: 'equilibrium' (static equilibrium at t = 0, mb.equilibrium) "
                           "or 'initial' (the assembled initial state, velocities included)."),
    out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="FILE",
                                       help="Write the modes table to .csv or .parquet."),
    debug: bool = DEBUG_OPT,
) -> None:
    """Natural frequencies [Hz] and damping ratios of a model file, linearized about its static
    equilibrium (or its initial state); rigid-body modes are listed at 0 Hz.

    Example: mbdsim modes examples/pendulum.yaml --out modes.csv

    Exit status: 0 ok, 1 analysis failed (no equilibrium), 2 bad input or model file."""
    _check_out(out)
    if at not in ("equilibrium", "initial"):
        _fail(f"--at: expected 'equilibrium' or 'initial', got {at!r}", EXIT_BAD_INPUT)
    _guard(lambda: _modes(model, at, out), debug)


def modes_frame(lin):
    """The modes of a Linearization as a table of real columns (MODES_COLUMNS): frequency [Hz] (undamped
    natural |lambda| / 2 pi), damped frequency [Hz], damping ratio [-] (NaN for rigid-body modes),
    eigenvalue real and imaginary parts [rad/s]."""
    import pandas as pd
    df = lin.modes()
    lam = [complex(x) for x in df["eigenvalue"]]
    return pd.DataFrame({MODES_COLUMNS[0]: range(len(df)), MODES_COLUMNS[1]: df["frequency [Hz]"].to_numpy(float),
                         MODES_COLUMNS[2]: df["damped frequency [Hz]"].to_numpy(float),
                         MODES_COLUMNS[3]: df["damping ratio"].to_numpy(float),
                         MODES_COLUMNS[4]: [x.real for x in lam], MODES_COLUMNS[5]: [x.imag for x in lam]})


def _modes(path, at, out):
    import mbdsim as mb
    m = _load(path)
    if out is not None:
        _check_modes_file(out)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        warnings.simplefilter("ignore", mb.UnstableEquilibriumWarning)   # an unstable mode says it (zeta < 0)
        lin = mb.linearize(m, at="equilibrium" if at == "equilibrium" else None)
    df = modes_frame(lin)
    point = "static equilibrium" if at == "equilibrium" else "initial state"
    rows = [(str(r[0]), f"{r[1]:.6g}", f"{r[2]:.6g}", "rigid" if math.isnan(r[3]) else f"{r[3]:.4g}",
             _eig(r[4], r[5])) for r in df.itertuples(index=False)]
    if lin.dof == 0:
        _console().print(f"{m.name}: no free coordinates (every degree of freedom is driven): no modes")
    else:
        _print_table(f"modes of {m.name} ({point}, t = {lin.t:g} s, {lin.dof} coordinates)",
                     rows, ("mode", "frequency [Hz]", "damped [Hz]", "damping ratio", "eigenvalue [rad/s]"))
    if out is not None:
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            df.to_csv(out, index=False) if out.suffix.lower() == ".csv" else df.to_parquet(out, index=False)
        except OSError as exc:
            _fail(f"cannot write {str(out)!r}: {exc}", EXIT_FAILED)
        _console().print(f"modes: {out} ({len(df)} rows)")


def _eig(re_: float, im: float) -> str:
    """'a + bj' [rad/s], a real part at round-off level (1e-12 of the magnitude) shown as 0."""
    re_ = 0.0 if abs(re_) <= 1e-12 * math.hypot(re_, im) else re_
    return f"{re_:.6g}" if im == 0 else f"{re_:.6g} {'+' if im > 0 else '-'} {abs(im):.6g}j"


def _check_modes_file(out: Path) -> None:
    """An existing --out is replaced only when it is a modes table (its first columns MODES_COLUMNS)."""
    if not os.path.lexists(out):
        return
    try:
        if out.suffix.lower() == ".csv":
            with open(out, encoding="utf-8") as fh:
                head = fh.readline().strip().split(",")
        else:
            import pyarrow.parquet as pq
            head = list(pq.read_schema(out).names)
    except Exception:  # noqa: BLE001 - unreadable: not ours
        head = []
    if list(head[:2]) != list(MODES_COLUMNS[:2]) or not out.is_file() or out.is_symlink():
        _fail(f"--out {str(out)!r} exists and is not a modes table mbdsim wrote; choose a new path or remove it",
              EXIT_BAD_INPUT)


def register(app: typer.Typer) -> None:
    """Add kinematics, statics and modes to the mbdsim Typer app."""
    app.command("kinematics")(kinematics_cmd)
    app.command("statics")(statics_cmd)
    app.command("modes")(modes_cmd)

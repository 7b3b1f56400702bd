"""``mbdsim run``, ``mbdsim info`` and ``mbdsim schema``: model files from the shell.

Commands::

    mbdsim run MODEL --end T [--step DT] [--method M] [--rtol R] [--out results.parquet|.csv] [--resume]
               [--markers | --marker NAME...] [--debug]

``--out`` is written while the run goes, so an interrupted or killed run leaves a readable file with what it
computed: a .parquet output of the compiled core is a Parquet dataset streamed in parts with checkpoints
(bounded memory; ``--resume`` continues it bit-identically, see mbdsim.solvers.stream), otherwise the file
is rewritten every few seconds, atomically (mbdsim.results.stream). ``--markers`` (every marker) or
``--marker NAME`` add marker columns to it ("<body>.<marker>.x [m]" ..., results.export.marker_targets).
    mbdsim info MODEL [--debug]
    mbdsim schema [--out schema.json]

Exit status: 0 success; 1 the analysis failed (assembly, lock-up, solver) or an output file could not be
written; 2 bad input (arguments, unreadable or invalid model file); 130 interrupted (Ctrl-C).  Errors
are one line on stderr; ``--debug`` shows the traceback.  Only typer is imported here: the engine,
rich, pydantic and pandas load when a command runs, so ``mbdsim --help`` stays fast.
"""
from __future__ import annotations

import os
import sys
import time
import warnings
from pathlib import Path
from typing import List, Optional

import typer

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130
OUT_SUFFIXES = (".parquet", ".csv")

MODEL_ARG = typer.Argument(..., metavar="MODEL", help="Model file (.yaml, .yml, .json, or imported: .urdf, .xml/.mjcf, .adm).")
DEBUG_OPT = typer.Option(False, "--debug", help="Show the Python traceback of an error.")
ALL_MARKERS_OPT = typer.Option(False, "--markers", help="Add every marker's columns to --out: "
                               "<body>.<marker>.x [m] .y .z, orientation, velocity, acceleration.")
MARKER_OPT = typer.Option(None, "--marker", metavar="NAME", show_default=False,
                          help="Add this marker's columns to --out (name, or body.marker); repeat it or give "
                          "a list: --marker tip,coupler.B.")


def _markers(every: bool, names):
    """The `markers` argument of the analyses from --markers / --marker (exit 2 without --out)."""
    picked = [n for raw in names or () for n in str(raw).replace(" ", "").split(",") if n]
    return True if every else (picked or False)


def _note_markers(model, markers) -> None:
    """Say so when --markers finds no marker in the model (the table then has none)."""
    if markers is True and not any(b.markers for b in model.bodies.values()):
        _console().print(f"note: --markers: model {model.name!r} has no markers (add them under a body's "
                         "'markers:' in the model file)")


def _console():
    from rich.console import Console
    return Console(stderr=True, highlight=False, width=None if sys.stderr.isatty() else 120)


def _fail(message: str, code: int) -> None:
    from rich.markup import escape
    _console().print(f"[bold red]error:[/] {escape(message)}")
    raise typer.Exit(code)


def _guard(fn, debug: bool):
    """Run fn() mapping errors to exit codes: bad input 2, analysis failure 1, Ctrl-C 130."""
    from mbdsim.errors import AssemblyError, ModelError, SolverError
    try:
        return fn()
    except typer.Exit:
        raise
    except KeyboardInterrupt:
        if debug:
            raise
        _fail("interrupted", EXIT_INTERRUPTED)
    except ModelError as exc:
        if debug:
            raise
        _fail(str(exc), EXIT_BAD_INPUT)
    except (AssemblyError, SolverError) as exc:
        if debug:
            raise
        _fail(f"analysis failed: {exc}", EXIT_FAILED)
    except Exception as exc:  # noqa: BLE001 - one line instead of a bare traceback
        if debug:
            raise
        _fail(f"{type(exc).__name__}: {exc} (run with --debug for the traceback)", EXIT_FAILED)


def _load(path: Path):
    import mbdsim as mb
    if not os.path.lexists(path):   # anything else (a FIFO, a device, too large) is refused by load_model
        _fail(f"model file {str(path)!r} does not exist", EXIT_BAD_INPUT)
    from ..importers import load_any   # .yaml/.yml/.json, or an imported format (.urdf, .xml/.mjcf, ...)
    return load_any(path)


def _rank_dof(model, with_report=False):
    """(DOF by the rank of the constraint Jacobian, independent rows dropped, joints in redundant rows)
    [+ the reaction determinacy report of redundant sets at the assembled state]."""
    import mbdsim as mb
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        rep = mb.assemble(model)
    out = (rep.dof, rep.system.nc - len(rep.rows), list(rep.redundant))
    if not with_report:
        return out
    report = []
    if out[2]:   # redundant joints (not a planar model's out-of-plane equations, dependent by design)
        from mbdsim.system.determinacy import determinacy_report
        report = determinacy_report(rep.system, rep.q, rep.t if hasattr(rep, "t") else 0.0)
    return out + (report,)


def _mobility(summary, dof, n_redundant, redundant):
    """Rows of the mobility table: Gruebler's count (and the planar count of a model flagged planar), the
    DOF from the rank of the constraint Jacobian, the redundant equations (a planar model's dependent
    out-of-plane equations are dropped by design and said so, not counted as redundant)."""
    g = str(summary.gruebler_dof) + ("" if summary.planar_dof is None else f" (planar count: {summary.planar_dof})")
    if redundant:
        red = f"{n_redundant} among {', '.join(redundant)}"
    elif n_redundant:
        red = f"0 ({n_redundant} out-of-plane equations dependent by design: planar model)"
    else:
        red = "0"
    return [("DOF (Gruebler)", g), ("DOF (rank)", str(dof)), ("redundant constraints", red)]


def run_cmd(
    model: Path = MODEL_ARG,
    end: float = typer.Option(..., "--end", "-e", metavar="T", help="End time in s."),
    step: Optional[float] = typer.Option(None, "--step", "-s", metavar="DT", help="Output step in s (default: end/500)."),
    method: Optional[str] = typer.Option(None, "--method", "-m", metavar="M",
                                         help="auto (default), dop853, hht, rk45, radau or bdf."),
    rtol: Optional[float] = typer.Option(None, "--rtol", metavar="R",
                                         help="Relative tolerance (default 1e-7 with --method auto, the "
                                         "method's own otherwise)."),
    out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="FILE",
                                       help="Write the results table (res.to_dataframe()) to .parquet or .csv "
                                       "as the run goes (.parquet: a Parquet dataset streamed in parts)."),
    resume: bool = typer.Option(False, "--resume", help="Continue the run streamed to --out (.parquet) from its "
                                                        "last checkpoint (bit-identical to an uninterrupted run)."),
    every_marker: bool = ALL_MARKERS_OPT,
    marker: Optional[List[str]] = MARKER_OPT,
    debug: bool = DEBUG_OPT,
) -> None:
    """Simulate a model file and print a summary; optionally write the results table.

    Example: mbdsim run examples/slider_crank.yaml --end 2 --step 0.01 --out results.parquet

    With --markers (or --marker NAME) the table has marker columns, e.g. rod.tip.y [m] for mbdsim plot.

    Exit status: 0 ok, 1 analysis failed, 2 bad input or model file, 130 interrupted."""
    if out is not None and out.suffix.lower() not in OUT_SUFFIXES:
        _fail(f"--out {str(out)!r}: expected a .parquet or .csv file", EXIT_BAD_INPUT)
    if not end > 0:
        _fail(f"--end must be > 0, got {end!r}", EXIT_BAD_INPUT)
    stream = out is not None and out.suffix.lower() == ".parquet"
    if resume and not stream:
        _fail("--resume needs --out FILE.parquet (the streamed run to continue)", EXIT_BAD_INPUT)
    markers = _markers(every_marker, marker)
    if markers is not False and out is None:
        _fail("--markers / --marker add columns to the results table: give --out FILE", EXIT_BAD_INPUT)
    _guard(lambda: _run(model, end, step, method, rtol, out, stream, resume, markers), debug)


def _run(path, end, step, method, rtol, out, stream=False, resume=False, markers=False):
    import mbdsim as mb

    from mbdsim.errors import AnalysisInterrupted
    from mbdsim.io.summary import summarize
    m = _load(path)
    _note_cold()
    _note_markers(m, markers)
    summary = summarize(m)
    dof, n_redundant, redundant = _rank_dof(m)
    t0 = time.perf_counter()
    with warnings.catch_warnings(), _bar(f"simulating {m.name}", end) as bar:
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)   # reported in the summary
        res = mb.simulate(m, end_time=end, output_step=step, method=method, rtol=rtol, out=_writable(out),
                          progress=bar, resume=resume, markers=markers)
    wall = time.perf_counter() - t0
    stats = res.stats or {}
    rows = [("model", f"{m.name} ({path})"), *_mobility(summary, dof, n_redundant, redundant),
            ("method", str(stats.get("method", method or "auto"))), ("steps", str(stats.get("steps", "?"))),
            ("simulated", f"{res.time[0]:.6g} .. {res.time[-1]:.6g} s, {stats.get('samples', len(res.time))} samples"),
            ("wall time", f"{wall:.3f} s"), ("success", f"{res.success} ({res.message})")]
    _print_table(f"mbdsim run: {m.name}", rows)
    if out is not None:
        _console().print(f"results: {out} ({stats.get('samples', len(res.time))} rows; written as the run went)")
    if isinstance(getattr(res, "error", None), AnalysisInterrupted):
        raise typer.Exit(EXIT_INTERRUPTED)
    if not res.success:
        interrupted = "KeyboardInterrupt" in str(getattr(res, "error", ""))
        raise typer.Exit(EXIT_INTERRUPTED if interrupted else EXIT_FAILED)


def _bar(label: str, end: float):
    """The progress bar of a run from 0 to end [s] on stderr (mbdsim._progress; nothing outside a terminal)."""
    from mbdsim._progress import ProgressBar
    return ProgressBar(label, 0.0, end, console=_console())


def _note_cold() -> None:
    if _kernels_cold():
        _console().print("note: first run of this mbdsim version: compiling its numba kernels (once, cached "
                         "on disk; a few minutes on a slow machine)")


def _kernels_cold() -> bool:
    """True when the on-disk cache of this version's compiled kernels is empty (mbdsim._jitcache)."""
    try:
        from mbdsim import _jitcache
        return not any(Path(_jitcache.CACHE_DIR).rglob("*.nbi"))
    except Exception:  # noqa: BLE001 - only a notice
        return False


def _writable(out: Optional[Path]) -> Optional[Path]:
    """`out` after checking that it can be written (exit 1 otherwise); the run writes it as it goes
    (mbdsim.results.stream): an interrupted run leaves every output computed before the last write."""
    if out is None:
        return None
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        probe = out.with_name(f".{out.name}.probe")
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        _fail(f"cannot write {str(out)!r}: {exc}", EXIT_FAILED)
    return out


def _print_table(title, rows, headers=("", "")):
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table
    t = Table(title=escape(title), show_header=any(headers), header_style="bold")
    for h in headers:                 # plain text: "x [m]" is not rich markup
        t.add_column(escape(h))
    for r in rows:
        t.add_row(*(escape(str(c)) for c in r))
    Console(highlight=False, width=None if sys.stdout.isatty() else 120).print(t)


def info_cmd(model: Path = MODEL_ARG, debug: bool = DEBUG_OPT) -> None:
    """Describe a model file: bodies, joints, degrees of freedom, drivers and force elements.

    Example: mbdsim info examples/four_bar.yaml

    Exit status: 0 ok, 1 the model does not assemble, 2 bad input or model file."""
    _guard(lambda: _info(model), debug)


def _info(path):
    from mbdsim.io.summary import summarize
    m = _load(path)
    s = summarize(m)
    _print_table(f"{m.name}: bodies", [(n, k, f"{mass:.6g} kg") for n, k, mass in s.bodies], ("name", "kind", "mass"))
    _print_table("joints", [(n, k, f"{bi} -> {bj}", str(nc)) for n, k, bi, bj, nc in s.joints],
                 ("name", "type", "bodies", "constraints"))
    if s.drivers:
        _print_table("drivers", [(n, j, k, d) for n, j, k, d in s.drivers], ("name", "joint", "kind", "function"))
    if s.elements:
        _print_table("force elements", s.elements, ("name", "kind"))
    dof, n_redundant, redundant, report = _rank_dof(m, True)   # assembles: may fail after the tables are out
    _print_table("mobility", _mobility(s, dof, n_redundant, redundant))
    if report:   # Wojtyra-Fraczek: which reaction components the rigid model determines (ground axes, on body_j)
        _print_table("reaction determinacy (redundant constraints; ground axes, on body_j, at assembly)",
                     [(n, " ".join(d) or "-", " ".join(i) or "-") for n, d, i in report],
                     ("joint", "determinate", "indeterminate (minimum-norm split reported)"))


def schema_cmd(out: Optional[Path] = typer.Option(None, "--out", "-o", metavar="FILE",
                                                  help="Write the schema to FILE instead of printing it.")) -> None:
    """Print the JSON Schema of model files (for editors and validators).

    Example: mbdsim schema --out mbdsim-model.schema.json"""
    import json

    from mbdsim.io import json_schema
    text = json.dumps(json_schema(), indent=2)
    if out is None:
        typer.echo(text)
        return
    try:
        out.write_text(text + "\n", encoding="utf-8")
    except OSError as exc:
        _fail(f"cannot write {str(out)!r}: {exc}", EXIT_FAILED)


def register(app: typer.Typer) -> None:
    """Add run, info, schema and export-fmu to the mbdsim Typer app."""
    app.command("run")(run_cmd)
    app.command("info")(info_cmd)
    app.command("schema")(schema_cmd)
    app.command("export-fmu")(export_fmu_cmd)


def export_fmu_cmd(model: Path = typer.Argument(..., metavar="MODEL", help="Model file (.yaml, .yml or .json)."),
                   out: Path = typer.Argument(..., metavar="OUT", help="FMU file to write (.fmu)."),
                   rtol: Optional[float] = typer.Option(None, "--rtol", help="Simulator tolerance inside the FMU."),
                   step: float = typer.Option(1e-3, "--step", help="Default communication step [s]."),
                   debug: bool = DEBUG_OPT) -> None:
    """Write an FMI 2.0 co-simulation FMU of a model file (inputs, outputs, numeric fields as parameters).

    The importing tool needs a Python with mbdsim installed (the FMU runs it through pythonfmu)."""
    def go():
        import mbdsim as mb
        path = mb.export_fmu(_load(model), out, rtol=rtol, step_size=step)
        _console().print(f"FMU written: {path}")
    _guard(go, debug)

"""``mbdsim plot`` and ``mbdsim animate``: figures and 3D pages from results files and model files.

Commands::

    mbdsim plot RESULTS SIGNAL... [--x SIGNAL] -o fig.png|svg|pdf
    mbdsim plot RESULTS --list
    mbdsim animate MODEL|RESULTS -o anim.html [--end T] [--signal SIGNAL] [--contact-forces]

RESULTS is a .csv or .parquet file written from ``res.to_dataframe()``; SIGNAL a column name, matched
leniently (exactly, then case-insensitively ignoring the unit suffix, then by a unique prefix).  A
MODEL file is read with ``mbdsim.load_model`` and simulated over ``--end`` seconds.  Exit status 0 on
success, 1 when the run or a file operation fails, 2 for bad arguments (unknown column, bad file).
Only typer is imported here; pandas, matplotlib and the engine load when a command runs.
"""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

RESULT_SUFFIXES = (".csv", ".parquet", ".pq")
FIGURE_SUFFIXES = (".png", ".svg", ".pdf")


def _fail(message: str, code: int = 2) -> None:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code)


def read_results(path: Path):
    """The DataFrame of a results file (.csv or .parquet written from `res.to_dataframe()`, or the Parquet
    dataset directory a long run streams its parts into)."""
    import pandas as pd

    suffix = path.suffix.lower()
    dataset = path.is_dir() and suffix in (".parquet", ".pq")   # a run streamed in parts (`run --out x.parquet`)
    if not (path.is_file() or dataset):
        _fail(f"results file {str(path)!r} does not exist")
    if suffix not in RESULT_SUFFIXES:
        _fail(f"results file {str(path)!r}: expected .csv or .parquet, got {suffix or 'no suffix'!r}")
    try:
        return pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure: one clear line, no traceback
        _fail(f"cannot read results file {str(path)!r}: {type(exc).__name__}: {exc}")


def plot_cmd(
    results: Path = typer.Argument(..., metavar="RESULTS", help="Results file (.csv or .parquet from res.to_dataframe())."),
    signals: Optional[List[str]] = typer.Argument(None, metavar="SIGNAL...", show_default=False,
                                                  help="Column names to plot (lenient match)."),
    x: Optional[str] = typer.Option(None, "--x", metavar="SIGNAL", help="Plot against this column instead of time."),
    out: Path = typer.Option(Path("fig.png"), "--out", "-o", metavar="FILE", help="Figure file: .png, .svg or .pdf."),
    list_columns: bool = typer.Option(False, "--list", "-l", help="Print the file's columns and exit."),
) -> None:
    """Plot columns of a results file against time (or against --x) into a PNG/SVG/PDF figure; signals
    of different units get separate y axes (stacked), each labelled with its unit.

    Example: mbdsim plot r.parquet slider.x --x crank_pin.angle -o x.png

    Exit status: 0 ok, 1 the figure could not be written, 2 bad input (unknown column, unreadable file)."""
    if out.suffix.lower() not in FIGURE_SUFFIXES:
        _fail(f"--out {str(out)!r}: expected a .png, .svg or .pdf file")
    df = read_results(results)
    if list_columns:
        typer.echo("\n".join(str(c) for c in df.columns))
        return
    if not signals:
        _fail(f"give the columns to plot (mbdsim plot {results} --list shows them)")
    from mbdsim.errors import ModelError
    from mbdsim.plotting import plot

    try:
        ax = plot(df, list(signals), x=x)
    except ModelError as exc:
        hint = f"; list them all: mbdsim plot {results} --list" if "matches no column" in str(exc) else ""
        _fail(str(exc).replace(" (all: the table's .columns)", "") + hint)
    ax.set_title(results.name)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        ax.figure.savefig(out, dpi=150)
    except OSError as exc:
        _fail(f"cannot write {str(out)!r}: {exc}", 1)
    finally:
        import matplotlib.pyplot as plt
        plt.close(ax.figure)
    typer.echo(f"figure: {out}")


def load_model_file(path: Path):
    """A Model from a model file (mbdsim.importers.load_any: .yaml/.yml/.json or an imported format)."""
    import mbdsim
    from mbdsim.importers import load_any
    try:
        return load_any(path)
    except mbdsim.MbdsimError as exc:
        _fail(f"model file {str(path)!r}: {exc}")


def animate_cmd(
    source: Path = typer.Argument(..., metavar="MODEL|RESULTS", help="Model file, or results file (.csv/.parquet)."),
    out: Path = typer.Option(Path("anim.html"), "--out", "-o", metavar="FILE", help="HTML page to write."),
    end: Optional[float] = typer.Option(None, "--end", metavar="T", help="End time [s] (model: simulated span, "
                                        "default 2 s; results: cut there)."),
    signal: Optional[str] = typer.Option(None, "--signal", metavar="SIGNAL",
                                         help="Column shown beside the 3D view (default: first joint coordinate)."),
    contact_forces: bool = typer.Option(False, "--contact-forces",
                                        help="Draw shape-contact forces as arrows at the touching points."),
) -> None:
    """Write a self-contained HTML page (three.js inlined, no network) playing a model's motion.

    Example: mbdsim animate examples/slider_crank.yaml --end 2 --signal slider.x -o a.html

    Exit status: 0 ok, 1 the run or the file failed, 2 bad input."""
    if out.suffix.lower() not in (".html", ".htm"):
        _fail(f"--out {str(out)!r}: expected an .html file")
    if not (source.is_file() or (source.is_dir() and source.suffix.lower() in (".parquet", ".pq"))):
        _fail(f"{str(source)!r} does not exist")
    from mbdsim.errors import MbdsimError
    from mbdsim.viewer import animate

    if source.suffix.lower() in RESULT_SUFFIXES:
        what = read_results(source)
        title = source.stem
    else:
        what = load_model_file(source)
        title = None
    try:
        page = animate(what, out, signal=signal or "auto", end_time=end, title=title, contact_forces=contact_forces)
    except MbdsimError as exc:
        _fail(str(exc), 2 if isinstance(exc, ValueError) else 1)
    except OSError as exc:
        _fail(f"cannot write {str(out)!r}: {exc}", 1)
    typer.echo(f"animation: {page}")


def register(app: typer.Typer) -> None:
    """Add ``plot`` and ``animate`` to the ``mbdsim`` command line."""
    app.command("plot")(plot_cmd)
    app.command("animate")(animate_cmd)

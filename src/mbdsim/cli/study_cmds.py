"""``mbdsim study``: run a parameter study file on Dask.

    mbdsim study STUDY.yaml [--workers N] [--scheduler tcp://host:8786] [--out results.parquet]
                            [--chunk N] [--plots DIR] [--debug]

Runs every variant (a LocalCluster of N worker processes, default 2; --workers 0 runs in this process;
--scheduler uses a running Dask scheduler), journals the rows as they arrive and writes the Parquet file (default
STUDY_results.parquet; a re-run with the same file does only the missing runs), then prints the status
counts, each output's range and the sensitivity table (standardised regression coefficients).
Exit status: 0 at least one run succeeded, 1 none did, 2 bad study or model file, 130 interrupted.
"""
from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Optional

import typer

from .run_cmds import DEBUG_OPT, EXIT_BAD_INPUT, EXIT_FAILED, _console, _fail, _guard


def _summary(df, study, seconds: float) -> None:
    import pandas as pd
    from rich.table import Table
    con = _console()
    counts = df["status"].value_counts()
    executed = df.attrs.get("executed", len(df))
    rate = 60.0 * executed / seconds if seconds > 0 else float("nan")
    con.print(f"study {study.name!r}: {len(df)} runs ({executed} now, {len(df) - executed} from the file), "
              + ", ".join(f"{k} {v}" for k, v in counts.items()) + f"; {seconds:.1f} s, {rate:.0f} variants/min")
    for _, row in df[df["status"] != "ok"].head(5).iterrows():
        con.print(f"  run {row['run']}: {row['status']}: {row['message']}", highlight=False)
    ok = df[df["status"] == "ok"]
    table = Table(title="outputs (runs with status ok)")
    for col in ("output", "min", "mean", "max"):
        table.add_column(col, justify="left" if col == "output" else "right")
    for name in study.plan.outputs:
        s = pd.to_numeric(ok[name], errors="coerce")
        table.add_row(name, *(f"{v:.6g}" for v in (s.min(), s.mean(), s.max())))
    con.print(table)
    if len(ok) >= len(study.parameters) + 3:
        sens = study.sensitivity(df, "src")
        st = Table(title="sensitivity: standardised regression coefficients (R^2 of the linear fit)")
        st.add_column("output")
        params = list(dict.fromkeys(sens.index.get_level_values("parameter")))
        for p in params:
            st.add_column(p, justify="right")
        st.add_column("R^2", justify="right")
        for out in dict.fromkeys(sens.index.get_level_values("output")):
            sub = sens.loc[out]
            st.add_row(out, *(f"{sub.loc[p, 'src']:+.3f}" for p in params), f"{sub['r2'].iloc[0]:.3f}")
        con.print(st)


def _plots(df, directory: Path) -> None:
    import mbdsim as mb
    directory.mkdir(parents=True, exist_ok=True)
    numeric = [p for p in df.attrs.get("parameters", []) if p in df and df[p].dtype.kind in "fiu"]
    kinds = ("main_effects", "scatter_matrix") + (("surface",) if len(numeric) >= 2 else ())
    for kind in kinds:   # a surface needs two numeric parameters
        mb.plot_study(df, kind=kind).savefig(directory / f"{kind}.png", dpi=90, bbox_inches="tight")
    _console().print(f"plots: {directory}/" + ", ".join(f"{k}.png" for k in kinds))


def study_cmd(
    study_file: Path = typer.Argument(..., metavar="STUDY", help="Study file (.yaml, .yml or .json)."),
    workers: Optional[int] = typer.Option(None, "--workers", "-w", min=0,
                                          help="Local worker processes (default 2; 0: run in this process)."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Address of a running Dask scheduler."),
    out: Optional[Path] = typer.Option(None, "--out", "-o", help="Parquet file of the results (resumable)."),
    chunk: Optional[int] = typer.Option(None, "--chunk", min=1, help="Variants per Dask task."),
    plots: Optional[Path] = typer.Option(None, "--plots", help="Directory for main-effect, scatter and surface PNGs."),
    debug: bool = DEBUG_OPT,
) -> None:
    """Run a parameter study: variants of a model file on Dask, one row per run in a Parquet file.

    Example: mbdsim study examples/slider_crank_study.yaml --workers 2 --out s.parquet --plots plots

    Exit status: 0 at least one run succeeded, 1 none did, 2 bad study or model file, 130 interrupted."""
    def go():
        import mbdsim as mb
        if not os.path.lexists(study_file):   # anything else (a FIFO, too large) is refused by load_study
            _fail(f"study file {str(study_file)!r} does not exist", EXIT_BAD_INPUT)
        if scheduler is not None and workers is not None:
            _fail("give --workers (a local cluster) or --scheduler (a running one), not both", EXIT_BAD_INPUT)
        if out is not None and out.suffix != ".parquet":
            _fail(f"--out must be a .parquet file, got {str(out)!r}", EXIT_BAD_INPUT)
        study = mb.load_study(study_file)
        target = out or Path(f"{study_file.stem}_results.parquet")
        t0 = time.perf_counter()
        df = study.run(client=scheduler, workers=workers, out=target, chunk_size=chunk)
        seconds = time.perf_counter() - t0
        _console().print(f"results: {target}")
        _summary(df, study, seconds)
        if plots is not None and (df["status"] == "ok").any():
            _plots(df, plots)
        if not (df["status"] == "ok").any():
            raise typer.Exit(EXIT_FAILED)
    _guard(go, debug)


def register(app: typer.Typer) -> None:
    """Add `study` to the mbdsim Typer app."""
    app.command("study")(study_cmd)

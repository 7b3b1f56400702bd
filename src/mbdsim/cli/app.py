"""The ``mbdsim`` command line.

Commands::

    mbdsim validate [CASES]... [--case N]... [--out DIR] [--json FILE] [--no-report]
    mbdsim version          (or: mbdsim --version)
    mbdsim cache info | clear [--stale]   (the compiled kernels' on-disk cache)

``mbdsim validate`` runs the validation cases (all 30 by default) with a progress bar,
prints the comparison table, writes the Markdown + self-contained HTML report to DIR
(default ``validation-report/``) and, with ``--json FILE``, one JSON record per compared
quantity.  Exit status: 0 when every quantity of every case passes, 1 when a quantity
fails or a case raised, 2 for bad arguments (e.g. an unknown case number).

Case numbers may be given as ``--case 3 --case 7``, ``--case 3,7``, ranges ``--case 1-5``
or positionally: ``mbdsim validate 3 7``.  The validation cases, matplotlib and the report
writer are imported only when ``validate`` runs.
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path
from typing import Any, List, Optional

import typer

app = typer.Typer(
    name="mbdsim",
    help="mbdsim: multibody dynamics simulator.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,   # plain help: typer's rich help formatter alone takes 0.16 s to import (issue 32)
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _version() -> str:
    from mbdsim import __version__
    return __version__


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"mbdsim {_version()}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Optional[bool] = typer.Option(
        None, "--version", "-V", help="Show the version and exit.",
        callback=_version_callback, is_eager=True,
    ),
) -> None:
    """mbdsim: multibody dynamics simulator."""


@app.command("version")
def version_cmd() -> None:
    """Print the mbdsim version.

    Example: mbdsim version"""
    typer.echo(f"mbdsim {_version()}")


def parse_case_numbers(values: List[str]) -> list[int]:
    """``["3", "1,2", "5-7"]`` -> ``[1, 2, 3, 5, 6, 7]``; raises ``typer.BadParameter``."""
    out: set[int] = set()
    for raw in values:
        for tok in str(raw).replace(" ", "").split(","):
            if not tok:
                continue
            m = re.fullmatch(r"(\d+)(?:-(\d+))?", tok)
            if m is None or (m.group(2) is not None and int(m.group(2)) < int(m.group(1))):
                raise typer.BadParameter(
                    f"{raw!r} is not a case number, a list (3,7) or a range (1-5)",
                    param_hint="'--case'",
                )
            lo = int(m.group(1))
            hi = int(m.group(2)) if m.group(2) is not None else lo
            out.update(range(lo, hi + 1))
    return sorted(out)


@app.command("validate")
def validate(
    cases_pos: Optional[List[str]] = typer.Argument(
        None, metavar="CASES", show_default=False,
        help="Case numbers to run (same syntax as --case).",
    ),
    case: Optional[List[str]] = typer.Option(
        None, "--case", "-c", metavar="N", show_default=False,
        help="Case number to run; repeat it, or give a list (3,7) or a range (1-5). Default: all.",
    ),
    out: Path = typer.Option(
        Path("validation-report"), "--out", "-o", metavar="DIR",
        help="Directory for report.md, report.html and figures/.",
    ),
    json_file: Optional[Path] = typer.Option(
        None, "--json", metavar="FILE", help="Write one JSON record per compared quantity.",
    ),
    no_report: bool = typer.Option(False, "--no-report", help="Do not write the report."),
) -> None:
    """Run the validation cases, print the comparison table and write the report.

    Example: mbdsim validate --case 1-5 --out validation-report --json results.json

    Exit status: 0 every quantity passes, 1 a quantity fails or a case raised, 2 bad arguments."""
    from rich.console import Console
    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, SpinnerColumn,
                               TextColumn, TimeElapsedColumn)

    err = Console(stderr=True, width=None if sys.stderr.isatty() else 120)
    console = Console(width=None if sys.stdout.isatty() else 200)

    numbers = parse_case_numbers(list(case or []) + list(cases_pos or []))
    if json_file is not None and json_file.exists() and json_file.is_dir():
        raise typer.BadParameter(f"{str(json_file)!r} is a directory", param_hint="'--json'")
    if out.exists() and not out.is_dir():
        raise typer.BadParameter(f"{str(out)!r} exists and is not a directory", param_hint="'--out'")

    try:
        from mbdsim.validation import registry
    except Exception as exc:  # noqa: BLE001 - engine import broken: clear message, no traceback
        err.print(f"[bold red]error:[/] cannot load the validation suite: {type(exc).__name__}: {exc}")
        raise typer.Exit(1) from None

    try:
        modules = registry.case_modules(numbers or None)
    except registry.UnknownCaseError as exc:
        raise typer.BadParameter(str(exc), param_hint="'--case'") from None
    except Exception as exc:  # noqa: BLE001
        err.print(f"[bold red]error:[/] cannot discover the validation cases: {type(exc).__name__}: {exc}")
        raise typer.Exit(1) from None
    modules = sorted(modules, key=lambda m: registry.case_info(m).number)
    if not modules:
        err.print("[bold red]error:[/] no validation cases found in mbdsim.validation.cases")
        raise typer.Exit(1)

    outcomes = []
    with Progress(SpinnerColumn(), TextColumn("[progress.description]{task.description}"),
                  BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  console=err, transient=False) as progress:
        task = progress.add_task("validating", total=len(modules))
        for m in modules:
            info = registry.case_info(m)
            progress.update(task, description=f"case {info.number:02d} {info.slug}")
            o = registry.run_case(m)
            outcomes.append(o)
            status = _status(registry, o)
            style = {"PASS": "green", "FAIL": "red", "ERROR": "bold red"}[status]
            qs = o.quantities
            npass = sum(1 for q in qs if _q_passed(q))
            extra = ""
            if status == "ERROR":
                msg = str(registry.outcome_error(o)).splitlines()[0] if registry.outcome_error(o) else ""
                extra = "  " + (msg if len(msg) <= 100 else msg[:97] + "...")
            progress.console.print(
                f"  case {info.number:02d} {info.title[:60]:<60} [{style}]{status:<5}[/] "
                f"{npass}/{len(qs)}  {getattr(o, 'elapsed_s', 0.0):6.2f} s{extra}",
                markup=True, highlight=False,
            )
            progress.advance(task)
        progress.update(task, description="done")

    from mbdsim.validation.report import COLUMNS, fmt_pct, fmt_value, quantity_records

    console.print(_table(outcomes, registry, COLUMNS, fmt_value, fmt_pct))

    n_cases = len(outcomes)
    n_ok = sum(1 for o in outcomes if registry.outcome_ok(o))
    n_err = sum(1 for o in outcomes if _status(registry, o) == "ERROR")
    n_q = sum(len(o.quantities) for o in outcomes)
    n_qok = sum(1 for o in outcomes for q in o.quantities if _q_passed(q))
    all_ok = n_ok == n_cases

    if json_file is not None:
        records = quantity_records(outcomes)
        try:
            json_file.parent.mkdir(parents=True, exist_ok=True)
            json_file.write_text(json.dumps(records, indent=2, allow_nan=False) + "\n", encoding="utf-8")
            err.print(f"JSON: {json_file} ({len(records)} records)")
        except OSError as exc:
            err.print(f"[bold red]error:[/] cannot write {json_file}: {exc}")
            raise typer.Exit(1) from None

    if not no_report:
        from mbdsim.validation.report import write_report

        try:
            md_path, html_path = write_report(outcomes, out)
            err.print(f"report: {md_path}  {html_path}")
        except Exception as exc:  # noqa: BLE001
            err.print(f"[bold red]error:[/] cannot write the report to {out}: {type(exc).__name__}: {exc}")
            raise typer.Exit(1) from None

    style = "bold green" if all_ok else "bold red"
    msg = (f"{n_ok}/{n_cases} cases passed, {n_qok}/{n_q} quantities passed"
           + (f", {n_err} case(s) raised an error" if n_err else ""))
    console.print(f"[{style}]{'PASS' if all_ok else 'FAIL'}[/]: {msg}", highlight=False)
    if not all_ok:
        raise typer.Exit(1)


def _q_passed(q: Any) -> bool:
    try:
        return bool(q.passed)
    except Exception:  # noqa: BLE001
        return False


def _status(registry, o) -> str:
    if registry.outcome_error(o) is not None:
        return "ERROR"
    return "PASS" if registry.outcome_ok(o) else "FAIL"


def _table(outcomes, registry, columns, fmt_value, fmt_pct):
    from rich.table import Table

    t = Table(title="mbdsim validation", show_lines=False, header_style="bold")
    numeric = {3, 4, 5, 6, 7, 8}
    for i, c in enumerate(columns):
        t.add_column(c.replace(" (recomputed)", ""), justify="right" if i in numeric or i == 0 else "left",
                     no_wrap=i in numeric)
    for o in outcomes:
        n = f"{int(o.info.number):02d}"
        err = registry.outcome_error(o)
        if err is not None and not o.quantities:
            t.add_row(n, "[bold red]ERROR[/]", "", "", "", "", "", "", "", "[bold red]FAIL[/]")
            t.add_row("", f"[red]{_escape(err)}[/]", *[""] * (len(columns) - 2))
            continue
        for q in o.quantities:
            ok = _q_passed(q)
            ep = _safe(lambda q=q: q.error_pct)
            cp = _safe(lambda q=q: q.commercial_error_pct)
            t.add_row(n, _escape(str(q.name)), _escape(str(q.unit)), fmt_value(q.theory),
                      fmt_value(q.manual_theory), fmt_value(q.manual_commercial), fmt_value(q.mbdsim),
                      fmt_pct(ep), fmt_pct(cp),
                      "[green]PASS[/]" if ok else "[bold red]FAIL[/]")
    return t


def _safe(fn):
    try:
        return fn()
    except Exception:  # noqa: BLE001
        return None


def _escape(s: str) -> str:
    from rich.markup import escape

    return escape(s)


from mbdsim.cli import view_cmds as _view_cmds  # noqa: E402 - plot, animate

_view_cmds.register(app)

from mbdsim.cli import run_cmds as _run_cmds  # noqa: E402 - run, info, schema (model files)

_run_cmds.register(app)

from mbdsim.cli import analysis_cmds as _analysis_cmds  # noqa: E402 - kinematics, statics, modes (model files)

_analysis_cmds.register(app)

from mbdsim.cli import study_cmds as _study_cmds  # noqa: E402 - study (parameter studies on Dask)

_study_cmds.register(app)

from mbdsim.cli import cache_cmds as _cache_cmds  # noqa: E402 - cache info, cache clear (compiled kernels)

_cache_cmds.register(app)


def show_warning(message, category, filename, lineno, file=None, line=None, _seen=set()) -> None:  # noqa: B006
    """Warnings at the command line: one line "warning: <Category>: <message>" on stderr, each text once
    (no source path or code line; ``--debug`` does not change this)."""
    text = f"warning: {category.__name__}: {message}"
    if text in _seen:
        return
    _seen.add(text)
    print(text, file=sys.stderr if file is None else file)


def main(argv: Optional[List[str]] = None) -> None:
    """Console-script entry point (``mbdsim = "mbdsim.cli.app:main"``)."""
    import gc
    import warnings
    warnings.showwarning = show_warning
    try:
        app(args=argv, prog_name="mbdsim")
    finally:   # the command is done and its files closed: the interpreter's exit need not traverse the
        gc.freeze()   # ~10^5 objects of numba's and the kernels' loading again (0.1 s of every call; issue 32)


if __name__ == "__main__":  # pragma: no cover
    main()

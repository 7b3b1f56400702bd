"""The validation report: Markdown + one self-contained HTML page + figure PNGs.

:func:`write_report` takes the :class:`~mbdsim.validation.framework.CaseOutcome` list
produced by the validation runner and writes, into ``out_dir``::

    report.md            Markdown (figures referenced as figures/*.png)
    report.html          one self-contained page: inline CSS, figures as base64 data URIs
    figures/*.png        the mechanism at t=0 of every case and the manual's plots

The mechanism figure is drawn from the model itself (x-y projection of the bodies,
markers, joints and spring-dampers at t=0).  Figure drawing is defensive: if anything
is missing or fails, the report carries a note instead of the figure and goes on.

matplotlib is imported lazily (Agg canvas, no pyplot state), so importing this module
is cheap; :func:`quantity_records` and the formatting helpers need neither matplotlib
nor the engine.
"""
from __future__ import annotations

import datetime as _dt
from pathlib import Path
from typing import Sequence

from mbdsim.validation.framework import CaseOutcome
from ._vr_markdown import _CaseDoc, _markdown  # noqa: F401
from ._vr_html import _html  # noqa: F401
from ._vr_figures import _render_figures  # noqa: F401
from ._vr_format import COLUMNS, case_status, fmt_pct, fmt_value, quantity_records  # noqa: F401

__all__ = [
    "write_report",
    "quantity_records",
    "fmt_value",
    "fmt_pct",
    "case_status",
    "COLUMNS",
]


def write_report(outcomes: Sequence[CaseOutcome], out_dir: str | Path) -> tuple[Path, Path]:
    """Write ``report.md``, ``report.html`` and ``figures/*.png`` into ``out_dir``.

    Returns ``(markdown_path, html_path)``.  Cases are ordered by number.  A figure that
    cannot be drawn is replaced by a note; the report itself is always written.
    """
    out = Path(out_dir)
    figdir = out / "figures"
    figdir.mkdir(parents=True, exist_ok=True)
    for stale in figdir.glob("case*.png"):  # figures of a previous run
        try:
            stale.unlink()
        except OSError:
            pass

    docs: list[_CaseDoc] = []
    for o in sorted(outcomes, key=lambda o: int(getattr(o.info, "number", 0))):
        d = _CaseDoc(o, case_status(o))
        d.figures = _render_figures(o)
        for f in d.figures:
            if f.png is not None and f.filename:
                (figdir / f.filename).write_bytes(f.png)
        docs.append(d)

    generated = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    md_path = out / "report.md"
    html_path = out / "report.html"
    md_path.write_text(_markdown(docs, generated), encoding="utf-8")
    html_path.write_text(_html(docs, generated), encoding="utf-8")
    return md_path, html_path

"""Builds the validation report: :func:`write_report` (Markdown, HTML page, figure PNGs).

The rest of the report lives beside it: ``format`` (values and quantity records),
``markdown``, ``html`` and ``figures``.
"""
from __future__ import annotations

import datetime as _dt
from pathlib import Path
from typing import Sequence

from mbdsim.validation.framework import CaseOutcome
from .figures import _render_figures
from .format import case_status
from .html import _html
from .markdown import _CaseDoc, _markdown

__all__ = ["write_report"]


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

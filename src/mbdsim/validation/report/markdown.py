"""Markdown of the validation report: case documents, summary table, per-case sections."""
from __future__ import annotations

import html
import platform
import re
import sys
from dataclasses import dataclass, field
from typing import Any, Iterable, Sequence

from mbdsim import __version__ as _mbdsim_version
from mbdsim.validation.registry import is_finite, outcome_error
from mbdsim.validation.framework import FLOOR, REL_TOL, CaseOutcome
from .format import COLUMNS, MANUAL, _row_cells, _safe, fmt_pct
from .figures import _Figure


_MATH_RE = re.compile(r"\$\$(.+?)\$\$|(?<![\\$])\$(?!\s)([^$\n]+?)(?<!\s)\$", re.S)


def _md_renderer():
    try:
        from markdown_it import MarkdownIt
    except ImportError:  # pragma: no cover - markdown-it-py ships with rich
        return None
    return MarkdownIt("commonmark", {"html": False}).enable("table")


_MD = None


def _md_html(text: str, inline: bool = False) -> str:
    """Markdown to HTML (raw HTML escaped); TeX math kept verbatim in .math spans."""
    global _MD
    if not text:
        return ""
    maths: list[tuple[str, bool]] = []

    def stash(m: re.Match) -> str:
        if m.group(1) is not None:
            maths.append((m.group(1).strip(), True))
        else:
            maths.append((m.group(2), False))
        return f"MBDSIMMATHTOKEN{len(maths) - 1}X"

    protected = _MATH_RE.sub(stash, text)
    if _MD is None:
        _MD = _md_renderer() or False
    if _MD:
        out = _MD.renderInline(protected) if inline else _MD.render(protected)
    else:  # pragma: no cover
        out = html.escape(protected).replace("\n\n", "</p><p>")
        out = out if inline else f"<p>{out}</p>"

    def unstash(m: re.Match) -> str:
        expr, display = maths[int(m.group(1))]
        cls = "math display" if display else "math"
        return f'<span class="{cls}">{html.escape(expr)}</span>'

    return re.sub(r"MBDSIMMATHTOKEN(\d+)X", unstash, out)


# --------------------------------------------------------------------------- document model


@dataclass
class _CaseDoc:
    outcome: CaseOutcome
    status: str
    figures: list[_Figure] = field(default_factory=list)

    @property
    def number(self) -> int:
        return int(self.outcome.info.number)

    @property
    def anchor(self) -> str:
        return f"case-{self.number:02d}"


def _counts(docs: Sequence[_CaseDoc]) -> dict[str, int]:
    nq = sum(len(d.outcome.quantities) for d in docs)
    nq_pass = sum(1 for d in docs for q in d.outcome.quantities if _safe(lambda q=q: q.passed, False))
    return {
        "cases": len(docs),
        "cases_passed": sum(1 for d in docs if d.status == "PASS"),
        "cases_error": sum(1 for d in docs if d.status == "ERROR"),
        "quantities": nq,
        "quantities_passed": nq_pass,
    }


def _max_or_none(values: Iterable[Any]) -> float | None:
    vals = [float(v) for v in values if v is not None and is_finite(v)]
    return max(vals) if vals else None


def _environment() -> str:
    import numpy

    parts = [f"mbdsim {_mbdsim_version}", f"Python {platform.python_version()}",
             f"NumPy {numpy.__version__}"]
    scipy = sys.modules.get("scipy")
    if scipy is not None:
        parts.append(f"SciPy {getattr(scipy, '__version__', '?')}")
    parts.append(platform.platform(terse=True))
    return ", ".join(parts)


CRITERION = (
    "For every compared quantity, e = |mbdsim − theory| / |theory| (theory recomputed from the "
    "manual's formulas in full precision) and e_c is the commercial code's error against the same "
    f"recomputed theory. A quantity passes when e ≤ {REL_TOL:g} ({REL_TOL * 100:g} %) and "
    f"(e ≤ e_c or e ≤ {FLOOR:g}): never worse than the commercial code, except below one part per "
    "million."
)


# --------------------------------------------------------------------------- markdown


def _md_cell(s: str) -> str:
    return str(s).replace("|", "\\|").replace("\n", " ")


def _md_table(header: Sequence[str], rows: Sequence[Sequence[str]], right: Sequence[int] = ()) -> str:
    lines = ["| " + " | ".join(_md_cell(h) for h in header) + " |"]
    lines.append("|" + "|".join("---:" if i in right else "---" for i in range(len(header))) + "|")
    for r in rows:
        lines.append("| " + " | ".join(_md_cell(c) for c in r) + " |")
    return "\n".join(lines)


_NUM_COLS = (3, 4, 5, 6, 7, 8)


def _summary_rows(docs: Sequence[_CaseDoc], link) -> list[list[str]]:
    rows = []
    for d in docs:
        o = d.outcome
        qs = o.quantities
        npass = sum(1 for q in qs if _safe(lambda q=q: q.passed, False))
        elapsed = getattr(o, "elapsed_s", None)
        rows.append([
            link(d),
            str(o.info.title),
            str(o.info.reference),
            f"{npass}/{len(qs)}",
            fmt_pct(_max_or_none(_safe(lambda q=q: q.error_pct) for q in qs)),
            fmt_pct(_max_or_none(_safe(lambda q=q: q.commercial_error_pct) for q in qs)),
            str(len(o.info.discrepancies or [])),
            d.status,
            "—" if elapsed is None else f"{float(elapsed):.2f}",
        ])
    return rows


_SUMMARY_HEADER = ("case", "title", "reference", "quantities passed", "max mbdsim error %",
                   "max commercial error %", "discrepancies", "status", "time [s]")


def _markdown(docs: Sequence[_CaseDoc], generated: str) -> str:
    c = _counts(docs)
    out: list[str] = []
    out.append("# mbdsim validation report\n")
    out.append(f"Generated {generated} with {_environment()}.\n")
    out.append(f"Reference problems: {MANUAL} (the 30 problems of the validation manual).\n")
    verdict = "ALL PASS" if c["cases_passed"] == c["cases"] and c["cases"] else "FAILURES"
    out.append(f"**{verdict}: {c['cases_passed']}/{c['cases']} cases passed, "
               f"{c['quantities_passed']}/{c['quantities']} quantities passed"
               + (f", {c['cases_error']} case(s) raised an error" if c["cases_error"] else "")
               + ".**\n")
    out.append(f"Pass criterion: {CRITERION}\n")

    out.append("## Summary\n")
    out.append(_md_table(_SUMMARY_HEADER,
                         _summary_rows(docs, lambda d: f"[{d.number:02d}](#{d.anchor})"),
                         right=(4, 5, 6, 8)) + "\n")

    out.append("## Manual discrepancies found\n")
    any_disc = False
    for d in docs:
        disc = list(d.outcome.info.discrepancies or [])
        if not disc:
            continue
        any_disc = True
        out.append(f"### Case {d.number:02d}: {d.outcome.info.title}\n")
        out.extend(f"- {_one_line(s)}" for s in disc)
        out.append("")
    if not any_disc:
        out.append("None found in the cases run.\n")

    out.append("## All compared quantities\n")
    rows = [_row_cells(d.number, q) for d in docs for q in d.outcome.quantities]
    out.append(_md_table(COLUMNS, rows, right=_NUM_COLS) + "\n" if rows else "No quantities.\n")

    out.append("## Cases\n")
    for d in docs:
        out.append(_md_case(d))
    return "\n".join(out).rstrip() + "\n"


def _one_line(s: str) -> str:
    return str(s).strip().replace("\n", "\n  ")


def _md_case(d: _CaseDoc) -> str:
    o, info = d.outcome, d.outcome.info
    out: list[str] = []
    out.append(f'<a id="{d.anchor}"></a>\n')
    out.append(f"### Case {d.number:02d}: {info.title} [{d.status}]\n")
    meta = [f"**Reference:** {info.reference}" if info.reference else "",
            f"**Analysis:** {info.analysis}" if info.analysis else "",
            f"**Module:** `{info.slug}`" if info.slug else ""]
    elapsed = getattr(o, "elapsed_s", None)
    if elapsed is not None:
        meta.append(f"**Run time:** {float(elapsed):.2f} s")
    out.append(" · ".join(m for m in meta if m) + "\n")
    err = outcome_error(o)
    if err:
        out.append(f"> **ERROR:** {_md_cell(err)}\n")
        tb = getattr(o, "traceback", "")
        if tb:
            out.append("<details><summary>Traceback</summary>\n\n```text\n" + tb.rstrip()
                       + "\n```\n\n</details>\n")
    if info.statement:
        out.append("#### Problem statement\n")
        out.append(str(info.statement).strip() + "\n")
    if info.reconstruction:
        out.append("#### Reconstruction\n")
        out.append(str(info.reconstruction).strip() + "\n")
    for f in d.figures:
        if f.kind == "mechanism":
            out.append(_md_figure(f))
    plots = [f for f in d.figures if f.kind == "plot"]
    if plots:
        out.append("#### Plots\n")
        out.extend(_md_figure(f) for f in plots)
    if o.quantities:
        out.append("#### Comparison\n")
        out.append(_md_table(COLUMNS, [_row_cells(d.number, q) for q in o.quantities],
                             right=_NUM_COLS) + "\n")
        qnotes = [(q.name, q.note) for q in o.quantities if q.note]
        if qnotes:
            out.extend(f"- **{n}:** {_one_line(t)}" for n, t in qnotes)
            out.append("")
    for heading, items in (("Notes", info.notes), ("Full-physics variants", o.variants),
                           ("Manual discrepancies", info.discrepancies)):
        items = list(items or [])
        if items:
            out.append(f"#### {heading}\n")
            out.extend(f"- {_one_line(s)}" for s in items)
            out.append("")
    return "\n".join(out) + "\n"


def _md_figure(f: _Figure) -> str:
    if f.png is not None and f.filename:
        return f"![{_md_cell(f.title)}](figures/{f.filename})\n\n*{f.title}*\n"
    return f"> *{f.note}*\n"


# --------------------------------------------------------------------------- html

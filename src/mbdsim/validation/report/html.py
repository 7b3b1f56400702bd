"""The self-contained HTML page of the validation report (inline CSS, figures as data URIs)."""
from __future__ import annotations

import base64
import html
from typing import Any, Iterable, Sequence

from mbdsim.validation.framework import Quantity
from mbdsim.validation.registry import outcome_error
from .format import COLUMNS, MANUAL, _row_cells, _safe
from .markdown import CRITERION, _CaseDoc, _NUM_COLS, _SUMMARY_HEADER, _counts, _environment, _md_html, _summary_rows
from .figures import _Figure


_CSS = """
:root { --ok:#1e7d32; --okbg:#e8f5e9; --bad:#b71c1c; --badbg:#ffebee; --err:#8a4b00; --errbg:#fff3e0;
        --line:#d0d7de; --muted:#57606a; }
* { box-sizing: border-box; }
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 0; color:#1f2328;
       line-height: 1.5; background:#fff; }
main { max-width: 1280px; margin: 0 auto; padding: 24px 32px 64px; }
h1 { font-size: 1.9em; border-bottom: 2px solid var(--line); padding-bottom: .3em; }
h2 { font-size: 1.45em; border-bottom: 1px solid var(--line); padding-bottom: .25em; margin-top: 2em; }
h3 { font-size: 1.2em; margin-top: 1.6em; }
h4 { font-size: 1.02em; margin: 1.3em 0 .4em; color:#24292f; }
section.case { border: 1px solid var(--line); border-radius: 8px; padding: 8px 22px 18px; margin: 26px 0;
               background: #fff; }
section.case > h3 { margin-top: .6em; }
.meta { color: var(--muted); font-size: .92em; }
.verdict { font-size: 1.15em; font-weight: 600; padding: 10px 14px; border-radius: 6px; display: inline-block; }
.verdict.ok { background: var(--okbg); color: var(--ok); }
.verdict.bad { background: var(--badbg); color: var(--bad); }
.criterion { color: var(--muted); font-size: .92em; max-width: 960px; }
.tablewrap { overflow-x: auto; margin: 8px 0 12px; }
table { border-collapse: collapse; font-size: .88em; }
th, td { border: 1px solid var(--line); padding: 4px 8px; vertical-align: top; }
th { background: #f6f8fa; text-align: left; white-space: nowrap; }
td.num { text-align: right; font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace;
         white-space: nowrap; }
tr.fail td { background: var(--badbg); }
tr.error td { background: var(--errbg); }
.badge { display: inline-block; padding: 1px 8px; border-radius: 10px; font-size: .8em; font-weight: 700;
         letter-spacing: .03em; }
.badge.PASS { background: var(--okbg); color: var(--ok); }
.badge.FAIL { background: var(--badbg); color: var(--bad); }
.badge.ERROR { background: var(--errbg); color: var(--err); }
figure { margin: 10px 0 14px; display: inline-block; vertical-align: top; max-width: 100%; }
figure img { max-width: 100%; height: auto; border: 1px solid #eaeef2; border-radius: 4px; }
figcaption { color: var(--muted); font-size: .85em; text-align: center; }
.note { color: var(--muted); font-style: italic; border-left: 3px solid var(--line); padding-left: 10px; }
.error { background: var(--errbg); border-left: 4px solid var(--err); padding: 8px 12px; border-radius: 4px; }
pre { background: #f6f8fa; padding: 10px; overflow-x: auto; font-size: .85em; border-radius: 4px; }
code { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, monospace; font-size: .92em; }
.math { font-family: "Cambria Math", "STIX Two Math", "Latin Modern Math", Georgia, serif; color:#0a3069;
        background: #f3f6fb; padding: 0 3px; border-radius: 3px; white-space: pre-wrap; }
.math.display { display: block; margin: 6px 0; padding: 6px 10px; overflow-x: auto; }
.disc-case { margin: .6em 0 .2em; font-weight: 600; }
nav.toc { font-size: .9em; color: var(--muted); }
nav.toc a { margin-right: .6em; }
a { color: #0969da; text-decoration: none; }
a:hover { text-decoration: underline; }
"""


def _e(s: Any) -> str:
    return html.escape(str(s), quote=True)


def _html_table(header: Sequence[str], rows: Sequence[Sequence[str]], num_cols: Sequence[int] = (),
                row_classes: Sequence[str] | None = None, raw_cols: Sequence[int] = ()) -> str:
    h = "".join(f"<th>{_e(c)}</th>" for c in header)
    body = []
    for i, r in enumerate(rows):
        cls = f' class="{row_classes[i]}"' if row_classes and row_classes[i] else ""
        cells = []
        for j, c in enumerate(r):
            content = c if j in raw_cols else _e(c)
            cells.append(f'<td class="num">{content}</td>' if j in num_cols else f"<td>{content}</td>")
        body.append(f"<tr{cls}>" + "".join(cells) + "</tr>")
    return (f'<div class="tablewrap"><table><thead><tr>{h}</tr></thead><tbody>'
            + "\n".join(body) + "</tbody></table></div>")


def _badge(status: str) -> str:
    return f'<span class="badge {_e(status)}">{_e(status)}</span>'


def _html_quantity_table(rows_src: Sequence[tuple[int, Quantity]]) -> str:
    rows, classes = [], []
    for number, q in rows_src:
        cells = _row_cells(number, q)
        cells = [_e(c) for c in cells]
        cells[-1] = _badge("PASS" if cells[-1] == "PASS" else "FAIL")
        rows.append(cells)
        classes.append("" if _safe(lambda q=q: q.passed, False) else "fail")
    return _html_table(COLUMNS, rows, num_cols=_NUM_COLS, row_classes=classes,
                       raw_cols=tuple(range(len(COLUMNS))))


def _html_figure(f: _Figure) -> str:
    if f.png is not None:
        data = base64.b64encode(f.png).decode("ascii")
        return (f'<figure><img alt="{_e(f.title)}" src="data:image/png;base64,{data}">'
                f"<figcaption>{_e(f.title)}</figcaption></figure>")
    return f'<p class="note">{_e(f.note)}</p>'


def _html_list(items: Iterable[str]) -> str:
    return "<ul>" + "".join(f"<li>{_md_html(str(s).strip(), inline=True)}</li>" for s in items) + "</ul>"


def _html(docs: Sequence[_CaseDoc], generated: str) -> str:
    c = _counts(docs)
    ok = c["cases_passed"] == c["cases"] and c["cases"] > 0
    parts: list[str] = []
    parts.append("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                 "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                 "<title>mbdsim validation report</title>\n"
                 f"<style>{_CSS}</style>\n</head>\n<body>\n<main>\n")
    parts.append("<h1>mbdsim validation report</h1>")
    parts.append(f'<p class="meta">Generated {_e(generated)} with {_e(_environment())}.<br>'
                 f"Reference problems: {_md_html(MANUAL, inline=True)} "
                 "(the 30 problems of the validation manual).</p>")
    verdict = (f"{'ALL PASS' if ok else 'FAILURES'}: {c['cases_passed']}/{c['cases']} cases passed, "
               f"{c['quantities_passed']}/{c['quantities']} quantities passed")
    if c["cases_error"]:
        verdict += f", {c['cases_error']} case(s) raised an error"
    parts.append(f'<p><span class="verdict {"ok" if ok else "bad"}">{_e(verdict)}</span></p>')
    parts.append(f'<p class="criterion">{_e(CRITERION)}</p>')
    parts.append('<nav class="toc">Jump to: <a href="#summary">summary</a> '
                 '<a href="#discrepancies">manual discrepancies</a> '
                 '<a href="#quantities">all quantities</a> <a href="#cases">cases</a></nav>')

    # summary
    parts.append('<h2 id="summary">Summary</h2>')
    rows = _summary_rows(docs, lambda d: f'<a href="#{d.anchor}">{d.number:02d}</a>')
    esc_rows, classes = [], []
    for d, r in zip(docs, rows):
        cells = [r[0]] + [_e(x) for x in r[1:]]
        cells[7] = _badge(d.status)
        esc_rows.append(cells)
        classes.append({"PASS": "", "FAIL": "fail", "ERROR": "error"}[d.status])
    parts.append(_html_table(_SUMMARY_HEADER, esc_rows, num_cols=(3, 4, 5, 6, 8), row_classes=classes,
                             raw_cols=tuple(range(len(_SUMMARY_HEADER)))))

    # discrepancies
    parts.append('<h2 id="discrepancies">Manual discrepancies found</h2>')
    any_disc = False
    for d in docs:
        disc = list(d.outcome.info.discrepancies or [])
        if not disc:
            continue
        any_disc = True
        parts.append(f'<p class="disc-case"><a href="#{d.anchor}">Case {d.number:02d}</a>: '
                     f"{_e(d.outcome.info.title)}</p>")
        parts.append(_html_list(disc))
    if not any_disc:
        parts.append("<p>None found in the cases run.</p>")

    # all quantities
    parts.append('<h2 id="quantities">All compared quantities</h2>')
    allq = [(d.number, q) for d in docs for q in d.outcome.quantities]
    parts.append(_html_quantity_table(allq) if allq else "<p>No quantities.</p>")

    # cases
    parts.append('<h2 id="cases">Cases</h2>')
    for d in docs:
        parts.append(_html_case(d))
    parts.append("</main>\n</body>\n</html>\n")
    return "\n".join(parts)


def _html_case(d: _CaseDoc) -> str:
    o, info = d.outcome, d.outcome.info
    p: list[str] = [f'<section class="case" id="{d.anchor}">']
    p.append(f"<h3>Case {d.number:02d}: {_e(info.title)} {_badge(d.status)}</h3>")
    meta = []
    if info.reference:
        meta.append(f"<b>Reference:</b> {_e(info.reference)}")
    if info.analysis:
        meta.append(f"<b>Analysis:</b> {_e(info.analysis)}")
    if info.slug:
        meta.append(f"<b>Module:</b> <code>{_e(info.slug)}</code>")
    elapsed = getattr(o, "elapsed_s", None)
    if elapsed is not None:
        meta.append(f"<b>Run time:</b> {float(elapsed):.2f} s")
    if meta:
        p.append(f'<p class="meta">{" · ".join(meta)}</p>')
    err = outcome_error(o)
    if err:
        p.append(f'<div class="error"><b>ERROR:</b> {_e(err)}</div>')
        tb = getattr(o, "traceback", "")
        if tb:
            p.append(f"<details><summary>Traceback</summary><pre>{_e(tb)}</pre></details>")
    if info.statement:
        p.append("<h4>Problem statement</h4>")
        p.append(_md_html(str(info.statement)))
    if info.reconstruction:
        p.append("<h4>Reconstruction</h4>")
        p.append(_md_html(str(info.reconstruction)))
    for f in d.figures:
        if f.kind == "mechanism":
            p.append(_html_figure(f))
    plots = [f for f in d.figures if f.kind == "plot"]
    if plots:
        p.append("<h4>Plots</h4>")
        p.append("<div>" + "".join(_html_figure(f) for f in plots) + "</div>")
    if o.quantities:
        p.append("<h4>Comparison</h4>")
        p.append(_html_quantity_table([(d.number, q) for q in o.quantities]))
        qnotes = [(q.name, q.note) for q in o.quantities if q.note]
        if qnotes:
            p.append("<ul>" + "".join(f"<li><b>{_e(n)}:</b> {_md_html(str(t).strip(), inline=True)}</li>"
                                      for n, t in qnotes) + "</ul>")
    for heading, items in (("Notes", info.notes), ("Full-physics variants", o.variants),
                           ("Manual discrepancies", info.discrepancies)):
        items = list(items or [])
        if items:
            p.append(f"<h4>{_e(heading)}</h4>")
            p.append(_html_list(items))
    p.append("</section>")
    return "\n".join(p)


# --------------------------------------------------------------------------- entry point

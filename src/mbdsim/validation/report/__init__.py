"""The validation report: Markdown + one self-contained HTML page + figure PNGs.

:func:`write_report` takes the :class:`~mbdsim.validation.framework.CaseOutcome` list
produced by the validation runner and writes, into ``out_dir``::

    report.md            Markdown (figures referenced as figures/*.png)
    report.html          one self-contained page: inline CSS, figures as base64 data URIs
    figures/*.png        the mechanism at t=0 of every case and the manual's plots

The mechanism figure is drawn from the model itself (x-y projection of the bodies,
markers, joints and spring-dampers at t=0).  Figure drawing is defensive: if anything
is missing or fails, the report carries a note instead of the figure and goes on.

matplotlib is imported lazily (Agg canvas, no pyplot state), so importing this package
is cheap; :func:`quantity_records` and the formatting helpers need neither matplotlib
nor the engine.

The report knows the cases (it reads :mod:`mbdsim.validation.framework` and
:mod:`mbdsim.validation.registry`); nothing in the cases or the framework imports it.
"""
from __future__ import annotations

from .builder import write_report
from .format import COLUMNS, case_status, fmt_pct, fmt_value, quantity_records

__all__ = [
    "write_report",
    "quantity_records",
    "fmt_value",
    "fmt_pct",
    "case_status",
    "COLUMNS",
]

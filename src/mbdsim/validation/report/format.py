"""Formatting of values and the quantity records of the validation report (no matplotlib)."""
from __future__ import annotations

import math
from typing import Any, Iterable

from mbdsim.validation.framework import CaseOutcome, Quantity
from mbdsim.validation.registry import outcome_error


MANUAL = "J. L. Meriam and L. G. Kraige, *Engineering Mechanics: Dynamics*, 7th ed."

#: comparison table columns (shared with the CLI's table)
COLUMNS = (
    "case",
    "quantity",
    "unit",
    "recomputed theory",
    "manual theory",
    "manual commercial",
    "mbdsim",
    "mbdsim error %",
    "commercial error % (recomputed)",
    "pass",
)

# --------------------------------------------------------------------------- formatting


def fmt_value(x: Any) -> str:
    """Nine significant digits: enough to show 1e-7 relative differences."""
    if x is None:
        return "—"
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(v):
        return str(v)
    return f"{v:.9g}"


def fmt_pct(p: Any) -> str:
    """An error in percent: scientific notation with 3 significant digits when small."""
    if p is None:
        return "—"
    try:
        v = float(p)
    except (TypeError, ValueError):
        return str(p)
    if not math.isfinite(v):
        return str(v)
    if v == 0.0:
        return "0"
    if abs(v) < 0.01:
        return f"{v:.2e}"
    return f"{v:.3g}"


def _safe(fn, default=None):
    try:
        return fn()
    except Exception:  # noqa: BLE001
        return default


def case_status(outcome: CaseOutcome) -> str:
    """``"PASS"``, ``"FAIL"`` (some quantity fails) or ``"ERROR"`` (the case did not run)."""
    if outcome_error(outcome) is not None:
        return "ERROR"
    ok = _safe(lambda: all(q.passed for q in outcome.quantities), False)
    return "PASS" if ok else "FAIL"


def _json_num(x: Any) -> float | None:
    if x is None:
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def quantity_records(outcomes: Iterable[CaseOutcome]) -> list[dict[str, Any]]:
    """One JSON-ready record per compared quantity.

    Keys: ``case`` (int), ``quantity``, ``unit``, ``theory``, ``manual_theory``,
    ``manual_commercial``, ``mbdsim``, ``error_pct``, ``commercial_error_pct``, ``pass``.
    A case that raised contributes one record with ``quantity`` ``"<case error>"``,
    null values, ``pass`` false and an extra ``error`` key holding the message.
    Non-finite numbers are written as null.
    """
    records: list[dict[str, Any]] = []
    for o in outcomes:
        number = int(getattr(o.info, "number", 0))
        err = getattr(o, "error", None)
        if err or not o.quantities:
            records.append({
                "case": number, "quantity": "<case error>", "unit": "",
                "theory": None, "manual_theory": None, "manual_commercial": None,
                "mbdsim": None, "error_pct": None, "commercial_error_pct": None,
                "pass": False, "error": str(err or "the case produced no compared quantities"),
            })
            continue
        for q in o.quantities:
            records.append({
                "case": number,
                "quantity": str(q.name),
                "unit": str(q.unit),
                "theory": _json_num(q.theory),
                "manual_theory": _json_num(q.manual_theory),
                "manual_commercial": _json_num(q.manual_commercial),
                "mbdsim": _json_num(q.mbdsim),
                "error_pct": _json_num(_safe(lambda q=q: q.error_pct)),
                "commercial_error_pct": _json_num(_safe(lambda q=q: q.commercial_error_pct)),
                "pass": bool(_safe(lambda q=q: q.passed, False)),
            })
    return records


def _row_cells(number: int, q: Quantity) -> list[str]:
    passed = bool(_safe(lambda: q.passed, False))
    return [
        f"{number:02d}",
        str(q.name),
        str(q.unit),
        fmt_value(q.theory),
        fmt_value(q.manual_theory),
        fmt_value(q.manual_commercial),
        fmt_value(q.mbdsim),
        fmt_pct(_safe(lambda: q.error_pct)),
        fmt_pct(_safe(lambda: q.commercial_error_pct)),
        "PASS" if passed else "FAIL",
    ]


# --------------------------------------------------------------------------- figures

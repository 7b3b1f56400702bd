"""Data types shared by the validation cases, the runner and the report.

Every case module under ``mbdsim.validation.cases`` exposes a module-level ``CASE``
(a :class:`CaseInfo`) and a function ``run() -> CaseOutcome`` that builds its model with
the public API, runs the analysis and measures the compared quantities.
Values in a :class:`Quantity` are expressed in the manual's table unit (``unit``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

REL_TOL = 1e-4  # pass bound on |mbdsim - theory| / |theory|
FLOOR = 1e-6    # below this relative error a case passes even if the commercial code was closer


@dataclass
class Quantity:
    """One compared quantity of a case, all values in ``unit`` (the manual's table unit)."""

    name: str                 # e.g. "v_B" or "theta at a_A = 0"
    unit: str                 # the manual's table unit, e.g. "m/s", "mm", "deg"
    theory: float             # recomputed from the formulas in full precision
    manual_theory: float | None       # printed in the manual's comparison table
    manual_commercial: float | None   # the commercial code's printed result
    mbdsim: float             # measured from our Result
    note: str = ""            # e.g. "manual row mislabelled: this is r_dot, not r"

    @property
    def error_pct(self) -> float:
        """|mbdsim - theory| / |theory| in percent."""
        return _rel(self.mbdsim, self.theory) * 100.0

    @property
    def commercial_error_pct(self) -> float | None:
        """Commercial code's error against the same recomputed theory, percent."""
        if self.manual_commercial is None:
            return None
        return _rel(self.manual_commercial, self.theory) * 100.0

    @property
    def passed(self) -> bool:
        """e <= 1e-4 and (e <= e_c or e <= 1e-6)."""
        e = _rel(self.mbdsim, self.theory)
        ec = None if self.manual_commercial is None else _rel(self.manual_commercial, self.theory)
        if not e <= REL_TOL:
            return False
        return e <= FLOOR or ec is None or e <= ec


def _rel(value: float, ref: float) -> float:
    scale = abs(ref) if ref != 0 else 1.0
    return abs(value - ref) / scale


@dataclass
class Plot:
    """A plot the manual shows: y against x, with an optional marked (x, y) point."""

    title: str
    x: Any                    # (N,) array
    y: Any                    # (N,) array or dict label -> (N,) array
    xlabel: str
    ylabel: str
    mark: tuple[float, float] | None = None
    mark_label: str = ""


@dataclass
class CaseInfo:
    """Static description of a case: what the manual says and how we rebuilt it."""

    number: int
    slug: str                 # e.g. "vertical_launch"
    title: str
    reference: str            # "Meriam & Kraige 7th ed., p.31, P2.13"
    analysis: str             # "dynamics", "kinematics", ...
    statement: str            # the problem in words (Markdown)
    reconstruction: str       # every reconstructed dimension and the consistency check (Markdown)
    discrepancies: list[str] = field(default_factory=list)  # manual slips found, each with the correct figure
    notes: list[str] = field(default_factory=list)          # derivation vs full-physics notes


@dataclass
class CaseOutcome:
    """What running a case produced."""

    info: CaseInfo
    quantities: list[Quantity]
    model: Any = None          # the mbdsim.Model (for the t=0 figure)
    result: Any = None         # the main mbdsim Result
    plots: list[Plot] = field(default_factory=list)
    variants: list[str] = field(default_factory=list)  # full-physics variant findings (Markdown lines)

    @property
    def passed(self) -> bool:
        return all(q.passed for q in self.quantities)


CaseRunner = Callable[[], CaseOutcome]

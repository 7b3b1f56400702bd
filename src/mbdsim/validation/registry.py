"""Discovery and fault-tolerant execution of the validation cases.

Case modules live in :mod:`mbdsim.validation.cases` and are named ``caseNN_slug.py``.
Each exposes ``CASE`` (a :class:`~mbdsim.validation.framework.CaseInfo`) and
``run() -> CaseOutcome``.

* :func:`discover` lists ``(number, module name)`` pairs without importing the cases.
* :func:`case_modules` imports them (all, or the requested numbers), sorted by number.
  A case module that fails to *import* is replaced by a stand-in whose ``run()``
  re-raises the import error, so that it is reported as a failed case instead of
  aborting the whole validation run.
* :func:`run_case` runs one case and never raises: any exception becomes a
  :class:`FailedOutcome` carrying the error message and traceback.
"""
from __future__ import annotations

import importlib
import math
import pkgutil
import re
import time
import warnings
import traceback
from dataclasses import dataclass
from types import ModuleType, SimpleNamespace
from typing import Any, Iterable, Sequence

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Quantity

CASES_PACKAGE = "mbdsim.validation.cases"
_CASE_RE = re.compile(r"^case(\d+)(?:_(.*))?$")


class UnknownCaseError(ValueError):
    """Raised by :func:`case_modules` for case numbers that do not exist."""

    def __init__(self, unknown: Sequence[int], available: Sequence[int]):
        self.unknown = list(unknown)
        self.available = list(available)
        super().__init__(
            f"unknown case number(s): {', '.join(str(n) for n in self.unknown)}; "
            f"available: {format_numbers(self.available) or 'none'}"
        )


@dataclass
class FailedOutcome(CaseOutcome):
    """A case that raised (or returned something unusable) instead of producing results."""

    error: str = ""
    traceback: str = ""

    @property
    def passed(self) -> bool:  # a failed case never passes
        return False


# --------------------------------------------------------------------------- discovery

def _cases_package() -> ModuleType:
    return importlib.import_module(CASES_PACKAGE)


def discover() -> list[tuple[int, str]]:
    """``(number, fully qualified module name)`` for every case module, sorted by number."""
    pkg = _cases_package()
    found: list[tuple[int, str]] = []
    for info in pkgutil.iter_modules(list(getattr(pkg, "__path__", []))):
        m = _CASE_RE.match(info.name)
        if m is None:
            continue
        found.append((int(m.group(1)), f"{CASES_PACKAGE}.{info.name}"))
    found.sort(key=lambda item: (item[0], item[1]))
    return found


def available_numbers() -> list[int]:
    """Sorted case numbers present in the cases package."""
    return sorted({n for n, _ in discover()})


def format_numbers(numbers: Iterable[int]) -> str:
    """Compact representation such as ``1-5, 7, 9-30``."""
    nums = sorted(set(numbers))
    parts: list[str] = []
    i = 0
    while i < len(nums):
        j = i
        while j + 1 < len(nums) and nums[j + 1] == nums[j] + 1:
            j += 1
        parts.append(str(nums[i]) if i == j else f"{nums[i]}-{nums[j]}")
        i = j + 1
    return ", ".join(parts)


def _broken_module(number: int, module_name: str, exc: BaseException) -> SimpleNamespace:
    """Stand-in for a case module that could not be imported."""
    short = module_name.rsplit(".", 1)[-1]
    m = _CASE_RE.match(short)
    slug = (m.group(2) if m and m.group(2) else short) or short
    tb = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    info = CaseInfo(
        number=number,
        slug=slug,
        title=f"{short} (module failed to import)",
        reference="",
        analysis="",
        statement="",
        reconstruction="",
    )

    def run() -> CaseOutcome:
        raise ImportError(f"case module {module_name} failed to import: "
                          f"{type(exc).__name__}: {exc}")

    return SimpleNamespace(__name__=module_name, CASE=info, run=run, import_traceback=tb)


def case_modules(numbers: Iterable[int] | None = None) -> list[Any]:
    """Import the case modules, sorted by number.

    ``numbers`` selects cases by number (duplicates ignored); ``None`` means all.
    Raises :class:`UnknownCaseError` for numbers that do not exist.
    """
    found = discover()
    if numbers is not None:
        wanted = sorted({int(n) for n in numbers})
        have = {n for n, _ in found}
        unknown = [n for n in wanted if n not in have]
        if unknown:
            raise UnknownCaseError(unknown, sorted(have))
        found = [(n, name) for n, name in found if n in set(wanted)]
    modules: list[Any] = []
    for number, name in found:
        try:
            modules.append(importlib.import_module(name))
        except Exception as exc:  # keep going: report it as a failed case
            modules.append(_broken_module(number, name, exc))
    return modules


# --------------------------------------------------------------------------- running

def case_info(module: Any) -> CaseInfo:
    """The module's ``CASE``, or a placeholder built from its name when unusable."""
    info = getattr(module, "CASE", None)
    if isinstance(info, CaseInfo):
        return info
    name = str(getattr(module, "__name__", "case?")).rsplit(".", 1)[-1]
    m = _CASE_RE.match(name)
    number = int(m.group(1)) if m else 0
    slug = (m.group(2) if m and m.group(2) else name) or name
    return CaseInfo(number=number, slug=slug, title=name, reference="", analysis="",
                    statement="", reconstruction="")


def _check_quantity(q: Any) -> None:
    if not isinstance(q, Quantity):
        raise TypeError(f"expected a Quantity, got {type(q).__name__}")
    for attr in ("theory", "mbdsim"):
        v = getattr(q, attr)
        try:
            float(v)
        except (TypeError, ValueError):
            raise TypeError(f"quantity {q.name!r}: {attr} is not a number ({v!r})") from None
    # exercise the derived values so that a broken quantity fails here, not in the report
    q.error_pct, q.commercial_error_pct, q.passed  # noqa: B018


def failed_outcome(info: CaseInfo, exc: BaseException | str, tb: str = "") -> FailedOutcome:
    """Build a :class:`FailedOutcome` from an exception (or a message)."""
    if isinstance(exc, BaseException):
        msg = f"{type(exc).__name__}: {exc}"
        if not tb:
            tb = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    else:
        msg = str(exc)
    return FailedOutcome(info=info, quantities=[], error=msg, traceback=tb)


def run_case(module: Any) -> CaseOutcome:
    """Run one case; never raises (except KeyboardInterrupt).

    The returned outcome carries ``elapsed_s`` (wall time in seconds) as an attribute.
    Exceptions, a return value that is not a :class:`CaseOutcome`, or malformed
    quantities produce a :class:`FailedOutcome` with the error message.
    """
    info = case_info(module)
    t0 = time.perf_counter()
    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            outcome = module.run()
        if not isinstance(outcome, CaseOutcome):
            raise TypeError(f"run() returned {type(outcome).__name__}, expected CaseOutcome")
        for q in outcome.quantities:
            _check_quantity(q)
    except Exception as exc:  # noqa: BLE001 - the run must go on
        outcome = failed_outcome(info, exc)
    except SystemExit as exc:  # a case calling sys.exit() must not end the run
        outcome = failed_outcome(info, f"SystemExit: {exc.code}")
    elapsed = time.perf_counter() - t0
    seen = []
    for w in caught:  # solver warnings (e.g. redundant constraints) go into the report, once each
        text = f"Solver warning ({w.category.__name__}): {w.message}"
        if text not in seen:
            seen.append(text)
    if seen and isinstance(outcome, CaseOutcome):
        outcome.variants = list(outcome.variants) + seen
    try:
        outcome.elapsed_s = elapsed  # type: ignore[attr-defined]
    except Exception:  # pragma: no cover - frozen/slotted outcome
        pass
    return outcome


def run_cases(modules: Iterable[Any]) -> list[CaseOutcome]:
    """Run every module with :func:`run_case`."""
    return [run_case(m) for m in modules]


# --------------------------------------------------------------------------- status helpers

def outcome_error(outcome: CaseOutcome) -> str | None:
    """Error message of a failed case, or a reason why a case without quantities fails."""
    err = getattr(outcome, "error", None)
    if err:
        return str(err)
    if not outcome.quantities:
        return "the case produced no compared quantities"
    return None


def outcome_ok(outcome: CaseOutcome) -> bool:
    """True when the case ran, compared at least one quantity and every quantity passes."""
    if outcome_error(outcome) is not None:
        return False
    try:
        return bool(outcome.passed)
    except Exception:  # noqa: BLE001
        return False


def is_finite(x: Any) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False

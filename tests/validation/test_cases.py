"""Every validation case of the manual: each compared quantity meets the issue's pass criterion.

Pass: e = |mbdsim - theory| / |theory| <= 1e-4 and (e <= e_commercial or e <= 1e-6), with the theory
recomputed from the formulas in each case module (never a printed number).
"""
import pytest

from mbdsim.validation.registry import available_numbers, case_modules, outcome_error, run_case


@pytest.mark.parametrize("number", available_numbers())
def test_case(number):
    (module,) = case_modules([number])
    outcome = run_case(module)
    err = outcome_error(outcome)
    assert err is None, err
    assert outcome.quantities, "the case compares no quantity"
    failed = [f"{q.name}: mbdsim {q.mbdsim!r} vs theory {q.theory!r} (e = {q.error_pct:.3g} %, "
              f"commercial {q.commercial_error_pct})" for q in outcome.quantities if not q.passed]
    assert not failed, "; ".join(failed)
    assert outcome.info.reconstruction.strip(), "the reconstruction of the missing figure is not written down"


def test_all_thirty_cases_present():
    assert available_numbers() == list(range(1, 31))

"""Force element evaluators: one module per element type, registered by the spec class.

An evaluator provides `generalized(sys, fr, elem, t, state) -> Q (nv,)` [N, N m] and optionally
`potential(sys, fr, elem) -> (N,)` [J] and `dissipation(sys, fr, elem, t) -> (N,)` [W].
"""
from __future__ import annotations

EVALUATORS: dict = {}


def register(spec_cls):
    """Class decorator / function registering an evaluator module-like object for spec_cls."""
    def deco(ev):
        EVALUATORS[spec_cls] = ev
        return ev
    return deco


def evaluator(elem):
    """Evaluator of a force element spec (walks the class hierarchy)."""
    for cls in type(elem).__mro__:
        if cls in EVALUATORS:
            return EVALUATORS[cls]
    # an element may carry its own evaluator methods
    if hasattr(elem, "generalized"):
        return elem
    raise TypeError(f"no evaluator for force element {elem!r}")


from . import bushing, contact, exprloads, shape_contact, stop, torsion  # noqa: E402,F401  (evaluators register themselves)

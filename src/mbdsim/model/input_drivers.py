"""Motion drivers that read model inputs (issue 33): `add_motion(..., velocity="w_cmd")`.

A driver expression may name the model's inputs (Model.add_input) besides t [s]. The Simulator holds
each input constant over a step, so within a step the driver is an ordinary function of time; between
steps, when an input changes at t_k:

* a displacement driver x = f(t, u) jumps to f(t_k, u_new): the Simulator projects the positions and
  velocities onto the constraints at t_k before the next step (an event: the driven coordinate moves
  instantly, the rest of the mechanism follows by the mass-weighted minimum-norm correction);
* a velocity driver v = g(t, u) keeps its displacement continuous: x(t) = c0 + G(t, u) with G a closed-form
  antiderivative in t (inputs constant), the anchor c0 re-set at t_k so that x(t_k) is unchanged; the
  velocity jumps to g(t_k, u_new) (velocities projected at t_k);
* an acceleration driver a = h(t, u) keeps displacement and velocity continuous: x = c0 + c1 t + H2(t, u),
  v = c1 + H1(t, u), both anchors re-set at t_k.

`simulate` (and a new Simulator) uses the inputs' declared values: the driver is then the plain driver
with those constants (the anchors from initial_displacement / initial_velocity at t = 0). The anchors are
constants of the compiled driver programs, named ANCHOR_X / ANCHOR_V. Units: the driven coordinate's SI
unit (rad or m) and its rates; t in s.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from .._exprtree import Bin, Call, Const, Fn, Neg, Var, _depends, _eval, add, mul

ANCHOR_X, ANCHOR_V = "$x0", "$v0"   # not identifiers: no input or variable can take these names


@dataclass(frozen=True)
class InputDriver:
    """The symbolic driver of a motion reading inputs: value, d1, d2 trees of t, the inputs and the anchors;
    `constants` {input or anchor name: value at t = 0}; `kind` as given ("displacement", ...)."""

    kind: str
    value: object
    d1: object
    d2: object
    constants: dict
    inputs: tuple
    text: str = ""

    def evaluate(self, node, t: float, constants: dict) -> float:
        """A tree of this driver at time t [s] with the `constants` given."""
        return float(_eval(node, {"t": float(t), **constants}))

    def rebase(self, t: float, constants: dict, new_inputs: dict) -> dict:
        """The constants after the inputs change to `new_inputs` {name: value} at t [s]: the anchors moved so
        that a velocity driver's displacement, an acceleration driver's displacement and velocity, stay
        continuous at t (a displacement driver jumps: its constants are the new inputs only)."""
        new = {**constants, **new_inputs}
        if self.kind == "displacement":
            return new
        if self.kind == "acceleration":
            v_old, v_new = self.evaluate(self.d1, t, constants), self.evaluate(self.d1, t, new)
            new[ANCHOR_V] = constants[ANCHOR_V] + (v_old - v_new)
        x_old, x_new = self.evaluate(self.value, t, constants), self.evaluate(self.value, t, new)
        new[ANCHOR_X] = constants[ANCHOR_X] + (x_old - x_new)
        return new


def reads_inputs(text, inputs) -> bool:
    """True when driver text `text` is a string naming one of `inputs` (names)."""
    if not isinstance(text, str) or not inputs:
        return False
    from ..expressions import parse
    try:
        e = parse(text, ("t",) + tuple(inputs))
    except Exception:  # noqa: BLE001 - not parseable with the inputs either: the ordinary path reports it
        return False
    return any(_depends(e.node, n) for n in inputs)


def _bind(node, values: dict):
    """`node` with the variables named in `values` replaced by constants."""
    if isinstance(node, Var):
        return Const(float(values[node.name])) if node.name in values else node
    if isinstance(node, Bin):
        return Bin(node.op, _bind(node.a, values), _bind(node.b, values))
    if isinstance(node, Neg):
        return Neg(_bind(node.a, values))
    if isinstance(node, (Fn, Call)):
        return dataclasses.replace(node, args=tuple(_bind(a, values) for a in node.args))
    return node


def input_driver(kind: str, text: str, inputs: dict, x0: float, v0: float):
    """(TimeFunction with the inputs' declared values, InputDriver) of a `kind` driver given as `text`, an
    expression of t and the model inputs `inputs` {name: declared value}; ValueError when a velocity or
    acceleration expression has no closed-form antiderivative in t (mbdsim._exprint)."""
    from .._exprint import _antiderivative, _lower
    from ..expressions import Expr, parse
    from ..timefunctions import TimeFunction
    names = ("t",) + tuple(inputs)
    e = parse(text, names)
    used = tuple(n for n in inputs if _depends(e.node, n))
    consts = {n: float(inputs[n]) for n in used}
    g, dg = e.node, e.derivative("t").node
    if kind == "displacement":
        value, d1, d2 = g, dg, Expr(dg, names).derivative("t").node
    else:
        G1 = _antiderivative(g, "t")
        G2 = None if G1 is None or kind == "velocity" else _antiderivative(G1, "t")
        if G1 is None or (kind == "acceleration" and G2 is None):
            raise ValueError(f"a {kind} driver that reads inputs needs an expression with a closed-form "
                             f"antiderivative in t (polynomials, sin/cos/exp of a t + b, STEP ...): {text!r}")
        G1 = _lower(G1, "t")
        if kind == "velocity":
            value, d1, d2 = add(Var(ANCHOR_X), G1), g, dg
            consts[ANCHOR_X] = float(x0) - float(_eval(G1, {"t": 0.0, **consts}))
        else:
            G2 = _lower(G2, "t")
            value = add(add(Var(ANCHOR_X), mul(Var(ANCHOR_V), Var("t"))), G2)
            d1, d2 = add(Var(ANCHOR_V), G1), g
            consts[ANCHOR_V] = float(v0) - float(_eval(G1, {"t": 0.0, **consts}))
            consts[ANCHOR_X] = float(x0) - float(_eval(G2, {"t": 0.0, **consts}))
    sym = InputDriver(kind, value, d1, d2, consts, used, text)
    bound = [Expr(_bind(n, consts), ("t",)) for n in (value, d1, d2)]
    tf = TimeFunction(bound[0], bound[1], bound[2], f"{kind} {text!r} reading inputs {', '.join(used)}", bound[0],
                      symbolic=sym)
    return tf, sym

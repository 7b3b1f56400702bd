"""Expression trees of mbdsim.expressions: nodes, simplifying constructors, evaluation, d/dx, text.

Private to mbdsim.expressions (the public API is Expr/parse there). Nodes are frozen
dataclasses compared structurally; build them only through the simplifying constructors
(add, sub, mul, div, neg, pw, fn, call), which fold constants and drop 0/1 terms so that
repeated derivatives stay small.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import functions as _lib
from .errors import MbdsimError


class ExpressionError(MbdsimError, ValueError):
    """An expression that cannot be parsed, or a derivative that cannot be formed."""

    def __init__(self, message: str, text: str | None = None, token: str | None = None, position: int | None = None):
        self.text, self.token, self.position = text, token, position
        if text is not None:
            where = f" at position {position}" if position is not None else ""
            shown = text if len(text) <= 200 else text[:197] + "..."
            message = f"{message}{where} in expression {shown!r}"
        super().__init__(message)


# ----------------------------------------------------------------------------- tree nodes
@dataclass(frozen=True)
class Const:
    value: float


@dataclass(frozen=True)
class Var:
    name: str


@dataclass(frozen=True)
class Bin:
    op: str          # one of + - * / **
    a: object
    b: object


@dataclass(frozen=True)
class Neg:
    a: object


@dataclass(frozen=True)
class Fn:
    name: str        # key of FUNCTIONS
    args: tuple


@dataclass(frozen=True)
class Call:
    name: str        # upper-case library name or table name
    args: tuple
    order: int = 0   # derivative order with respect to args[0]
    table: object = None


_C0, _C1 = Const(0.0), Const(1.0)
_NP = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
       "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "exp": np.exp,
       "log": np.log, "sqrt": np.sqrt, "abs": np.abs, "sign": np.sign, "atan2": np.arctan2}
FUNCTIONS = tuple(_NP)
LIBRARY_FUNCTIONS = tuple(_lib.LIBRARY) + tuple(n.lower() for n in _lib.LIBRARY)


def _const(v) -> Const | None:
    """Fold a computed constant; None (do not fold) when it is not finite."""
    v = float(v)
    return Const(v) if np.isfinite(v) else None


def neg(a):
    if isinstance(a, Const):
        return Const(-a.value)
    if isinstance(a, Neg):
        return a.a
    if isinstance(a, Bin) and a.op == "-":
        return sub(a.b, a.a)
    if isinstance(a, Bin) and a.op in "*/" and isinstance(a.a, Const):
        return Bin(a.op, Const(-a.a.value), a.b)
    return Neg(a)


def add(a, b):
    if a == _C0:
        return b
    if b == _C0:
        return a
    if isinstance(a, Const) and isinstance(b, Const):
        return _const(a.value + b.value) or Bin("+", a, b)
    if isinstance(b, Neg):
        return sub(a, b.a)
    if isinstance(b, Const) and b.value < 0:
        return sub(a, Const(-b.value))
    if isinstance(a, Neg):
        return sub(b, a.a)
    return Bin("+", a, b)


def sub(a, b):
    if b == _C0:
        return a
    if a == _C0:
        return neg(b)
    if a == b:
        return _C0
    if isinstance(a, Const) and isinstance(b, Const):
        return _const(a.value - b.value) or Bin("-", a, b)
    if isinstance(b, Neg):
        return add(a, b.a)
    if isinstance(b, Const) and b.value < 0:
        return add(a, Const(-b.value))
    return Bin("-", a, b)


def mul(a, b):
    if a == _C0 or b == _C0:
        return _C0
    if isinstance(b, Const) and not isinstance(a, Const):
        a, b = b, a                                  # constants to the left
    if a == _C1:
        return b
    if a == Const(-1.0):
        return neg(b)
    if isinstance(a, Neg) and isinstance(b, Neg):
        return mul(a.a, b.a)
    if isinstance(a, Neg):
        return neg(mul(a.a, b))
    if isinstance(b, Neg):
        return neg(mul(a, b.a))
    if isinstance(a, Const):
        if isinstance(b, Const):
            return _const(a.value * b.value) or Bin("*", a, b)
        if isinstance(b, Bin) and b.op in "*/" and isinstance(b.a, Const):   # c1*(c2*x) -> (c1 c2)*x
            c = _const(a.value * b.a.value)
            if c is not None:
                return mul(c, b.b) if b.op == "*" else div(c, b.b)
    return Bin("*", a, b)


def div(a, b):
    if a == _C0:
        return _C0
    if b == _C1:
        return a
    if isinstance(a, Const) and isinstance(b, Const) and b.value != 0:
        return _const(a.value / b.value) or Bin("/", a, b)
    if isinstance(a, Neg):
        return neg(div(a.a, b))
    if isinstance(b, Neg):
        return neg(div(a, b.a))
    if isinstance(b, Const) and isinstance(a, Bin) and a.op in "*/" and isinstance(a.a, Const):
        c = _const(a.a.value / b.value) if b.value != 0 else None     # (c1 x)/c2 -> (c1/c2) x
        if c is not None:
            return mul(c, a.b) if a.op == "*" else div(c, a.b)
    return Bin("/", a, b)


def pw(a, b):
    if b == _C0:
        return _C1
    if b == _C1:
        return a
    if isinstance(a, Const) and isinstance(b, Const):
        with np.errstate(all="ignore"):
            return _const(np.power(a.value, b.value)) or Bin("**", a, b)
    return Bin("**", a, b)


def fn(name, *args):
    if all(isinstance(x, Const) for x in args):
        with np.errstate(all="ignore"):
            c = _const(_NP[name](*(x.value for x in args)))
        if c is not None:
            return c
    return Fn(name, args)


_MAX_ORDER = {"STEP": 3, "STEP5": 5}


def call(name, args, order=0, table=None):
    if table is None:
        top = _MAX_ORDER.get(name, len(args) - 3 if name == "POLY" else None)
        if top is not None and order > top:
            return _C0
    if all(isinstance(x, Const) for x in args):
        c = _const(_eval(Call(name, args, order, table), {}))
        if c is not None:
            return c
    return Call(name, tuple(args), order, table)


# ----------------------------------------------------------------------------- evaluation
_UFUNC = {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.true_divide, "**": np.power}


def _eval(n, env):
    if isinstance(n, Const):
        return n.value
    if isinstance(n, Var):
        return env[n.name]
    if isinstance(n, Bin):
        a, b = _eval(n.a, env), _eval(n.b, env)
        return _UFUNC[n.op](a, b)
    if isinstance(n, Neg):
        return np.negative(_eval(n.a, env))
    if isinstance(n, Fn):
        return _NP[n.name](*(_eval(x, env) for x in n.args))
    args = [_eval(x, env) for x in n.args]
    if getattr(n.table, "nargs", None) is not None:   # a user function (mbdsim.userfunctions)
        return n.table(*args)
    if n.table is not None:
        return n.table(args[0], order=n.order)
    return _lib.LIBRARY[n.name].fn(*args, order=n.order)


def _depends(n, var) -> bool:
    if isinstance(n, Var):
        return n.name == var
    if isinstance(n, Bin):
        return _depends(n.a, var) or _depends(n.b, var)
    if isinstance(n, Neg):
        return _depends(n.a, var)
    if isinstance(n, (Fn, Call)):
        return any(_depends(x, var) for x in n.args)
    return False


# ----------------------------------------------------------------------------- derivatives
_DERIV = {   # d f(u) / du as a node in u
    "sin": lambda u: fn("cos", u), "cos": lambda u: neg(fn("sin", u)),
    "tan": lambda u: div(_C1, pw(fn("cos", u), Const(2.0))),
    "asin": lambda u: div(_C1, fn("sqrt", sub(_C1, pw(u, Const(2.0))))),
    "acos": lambda u: neg(div(_C1, fn("sqrt", sub(_C1, pw(u, Const(2.0)))))),
    "atan": lambda u: div(_C1, add(_C1, pw(u, Const(2.0)))),
    "sinh": lambda u: fn("cosh", u), "cosh": lambda u: fn("sinh", u),
    "tanh": lambda u: div(_C1, pw(fn("cosh", u), Const(2.0))),
    "exp": lambda u: fn("exp", u), "log": lambda u: div(_C1, u),
    "sqrt": lambda u: div(Const(0.5), fn("sqrt", u)), "abs": lambda u: fn("sign", u),
    "sign": lambda u: _C0,
}


def _diff(n, var):
    if isinstance(n, Const):
        return _C0
    if isinstance(n, Var):
        return _C1 if n.name == var else _C0
    if isinstance(n, Neg):
        return neg(_diff(n.a, var))
    if isinstance(n, Bin):
        a, b, da, db = n.a, n.b, _diff(n.a, var), _diff(n.b, var)
        if n.op == "+":
            return add(da, db)
        if n.op == "-":
            return sub(da, db)
        if n.op == "*":
            return add(mul(da, b), mul(a, db))
        if n.op == "/":
            return sub(div(da, b), div(mul(a, db), pw(b, Const(2.0)))) if db != _C0 else div(da, b)
        if db == _C0:                                  # u**c
            return mul(mul(b, pw(a, sub(b, _C1))), da)
        if da == _C0:                                  # c**v
            return mul(mul(n, fn("log", a)), db)
        return mul(n, add(mul(db, fn("log", a)), div(mul(b, da), a)))
    if isinstance(n, Fn):
        if n.name == "atan2":                          # d atan2(y, x) = (x dy - y dx)/(x^2 + y^2)
            y, x = n.args
            num = sub(mul(x, _diff(y, var)), mul(y, _diff(x, var)))
            return div(num, add(pw(x, Const(2.0)), pw(y, Const(2.0))))
        return mul(_DERIV[n.name](n.args[0]), _diff(n.args[0], var))
    if getattr(n.table, "nargs", None) is not None:
        raise ExpressionError(f"cannot differentiate the user function {n.name}(...) (mbdsim.userfunctions): "
                              "it has no derivatives")
    for k, x in enumerate(n.args[1:], start=2):        # Call: only the first argument may vary
        if _depends(x, var):
            raise ExpressionError(f"cannot differentiate {n.name}(...) with respect to {var!r}: argument {k} "
                                  f"({_text(x)}) depends on it; only the first argument may")
    return mul(call(n.name, n.args, n.order + 1, n.table), _diff(n.args[0], var))


# ----------------------------------------------------------------------------- printing
def _num(v: float) -> str:
    return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)


def _prec(n) -> int:
    if isinstance(n, Bin):
        return {"+": 1, "-": 1, "*": 2, "/": 2, "**": 4}[n.op]
    if isinstance(n, Neg) or (isinstance(n, Const) and (n.value < 0 or str(n.value)[0] == "-")):
        return 3
    return 5


def _text(n) -> str:
    def wrap(x, paren):
        s = _text(x)
        return f"({s})" if paren else s
    if isinstance(n, Const):
        return _num(n.value)
    if isinstance(n, Var):
        return n.name
    if isinstance(n, Neg):
        return "-" + wrap(n.a, _prec(n.a) < 4)
    if isinstance(n, Bin):
        p = _prec(n)
        if n.op == "**":
            return f"{wrap(n.a, _prec(n.a) <= 4)}**{wrap(n.b, _prec(n.b) < 5)}"
        return f"{wrap(n.a, _prec(n.a) < p)} {n.op} {wrap(n.b, _prec(n.b) <= p)}"
    args = ", ".join(_text(x) for x in n.args)
    order = f", order={n.order}" if isinstance(n, Call) and n.order else ""
    return f"{n.name}({args}{order})"

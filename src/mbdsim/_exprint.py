"""Closed-form antiderivatives of expression trees (private to mbdsim.timefunctions).

Velocity and acceleration drivers are integrated once, when the model is built, into a displacement
expression that the compiled core evaluates like any other driver (system.exprvm): exact, no quadrature
at run time. `antiderivative(node, "t")` returns a tree F with dF/dt = node, or None when the
expression has no closed form here; the caller then keeps the quadrature path.

Covered: sums and constant multiples of
- polynomials in t (any integer powers, products, POLY(t, ...));
- (a t + b)**c (c != -1), 1/(a t + b), sqrt(a t + b);
- a polynomial times sin, cos, exp, sinh or cosh of a t + b (integration by parts), SHF;
- the Adams smooth steps STEP, STEP5, HAVSIN of a t + b (any number of times: the n-th antiderivative is a
  clamped polynomial, written with abs() so that one formula holds on both sides of the step),
  and their derivatives (order=k).
Everything else (tables, products of two transcendental factors, nested non-linear arguments) gives None.
"""
from __future__ import annotations

from math import factorial

import numpy as np
from numpy.polynomial import polynomial as P

from ._exprtree import Bin, Call, Const, Fn, Neg, Var, _depends, _eval, add, call, div, fn, mul, neg, pw, sub

_C0, _C1 = Const(0.0), Const(1.0)
_MAX_POW = 40          # largest integer power expanded as a polynomial
_ANTI = {"sin": (-1.0, "cos"), "cos": (1.0, "sin"), "exp": (1.0, "exp"), "sinh": (1.0, "cosh"),
         "cosh": (1.0, "sinh")}
_STEPS = ("STEP", "STEP5", "HAVSIN")
_NEG = "ANTI"          # marker: Call(_NEG, (step call, n)) is the n-th antiderivative of a step, lowered at the end


# ----------------------------------------------------------------------------- polynomials
def _poly(n, var):
    """Ascending coefficients when `n` is a polynomial in var, else None."""
    if isinstance(n, Const):
        return np.array([n.value])
    if isinstance(n, Var):
        return np.array([0.0, 1.0]) if n.name == var else None
    if isinstance(n, Neg):
        a = _poly(n.a, var)
        return None if a is None else -a
    if isinstance(n, Bin):
        a = _poly(n.a, var)
        if a is None:
            return None
        if n.op == "**":
            e = n.b.value if isinstance(n.b, Const) else None
            if e is None or e != int(e) or not 0 <= e <= _MAX_POW:
                return None
            return P.polypow(a, int(e))
        b = _poly(n.b, var)
        if b is None:
            return None
        if n.op == "+":
            return P.polyadd(a, b)
        if n.op == "-":
            return P.polysub(a, b)
        if n.op == "*":
            return P.polymul(a, b)
        if n.op == "/" and len(np.trim_zeros(b, "b")) == 1:
            return a / b[0]
        return None
    if isinstance(n, Call) and n.name == "POLY" and n.table is None and n.order == 0:
        x, rest = _poly(n.args[0], var), [_poly(a, var) for a in n.args[1:]]
        if x is None or any(r is None or len(np.trim_zeros(r, "b")) > 1 for r in rest):
            return None
        c = [float(r[0]) if len(r) else 0.0 for r in rest]
        u = P.polysub(x, [c[0]])
        out = np.zeros(1)
        for a in reversed(c[1:]):          # Horner in u
            out = P.polyadd(P.polymul(out, u), [a])
        return out
    return None


def _poly_node(c, var):
    out = _C0
    for k, ck in enumerate(c):
        if ck != 0.0:
            out = add(out, mul(Const(float(ck)), pw(Var(var), Const(float(k)))))
    return out


def _linear(n, var):
    """(a, b) when n = a var + b with a != 0, else None."""
    c = _poly(n, var)
    if c is None:
        return None
    c = np.trim_zeros(c, "b")
    return (float(c[1]), float(c[0])) if len(c) == 2 else None


# ----------------------------------------------------------------------------- products
def _factors(n, var):
    """(constant, polynomial coefficients, other factors) of a product/quotient tree, or None."""
    if isinstance(n, Neg):
        f = _factors(n.a, var)
        return None if f is None else (-f[0], f[1], f[2])
    if isinstance(n, Bin) and n.op == "*":
        a, b = _factors(n.a, var), _factors(n.b, var)
        if a is None or b is None:
            return None
        return a[0] * b[0], P.polymul(a[1], b[1]), a[2] + b[2]
    if isinstance(n, Bin) and n.op == "/" and not _depends(n.b, var):
        a = _factors(n.a, var)
        d = _eval(n.b, {})
        return None if a is None or not np.isfinite(d) or d == 0 else (a[0] / float(d), a[1], a[2])
    p = _poly(n, var)
    if p is not None:
        return 1.0, p, []
    return 1.0, np.array([1.0]), [n]


def _elementary(h, var):
    """(name, a, u) for sin/cos/exp/sinh/cosh of a linear argument u = a var + b, else None."""
    if isinstance(h, Fn) and h.name in _ANTI and len(h.args) == 1:
        ab = _linear(h.args[0], var)
        if ab is not None:
            return h.name, ab[0], h.args[0]
    return None


def _by_parts(c, name, a, u, var):
    """Antiderivative of polynomial(c) * name(u), u = a var + b: sum_k (-1)^k c^(k) H_{k+1}."""
    out, sign, coef, fname = _C0, 1.0, 1.0, name
    dc = np.asarray(c, float)
    while len(dc) and np.any(dc != 0.0):
        s, fname = _ANTI[fname]
        coef *= s / a
        out = add(out, mul(Const(sign * coef), mul(_poly_node(dc, var), fn(fname, u))))
        dc, sign = P.polyder(dc), -sign
    return out


# ----------------------------------------------------------------------------- one term
def _single(h, var):
    """Antiderivative of one non-polynomial factor h, or None."""
    e = _elementary(h, var)
    if e is not None:
        return _by_parts([1.0], *e, var)
    if isinstance(h, Fn) and h.name == "sqrt":
        return _power(h.args[0], 0.5, var)
    if isinstance(h, Bin) and h.op == "**" and isinstance(h.b, Const):
        return _power(h.a, h.b.value, var)
    if isinstance(h, Bin) and h.op == "/" and not _depends(h.a, var):
        k = _eval(h.a, {})
        r = _power(h.b, -1.0, var)
        return None if r is None else mul(Const(float(k)), r)
    if isinstance(h, Call) and h.table is None:
        return _call(h, var)
    return None


def _power(base, e, var):
    ab = _linear(base, var)
    if ab is None:
        return None
    a = ab[0]
    if e == -1.0:
        return div(fn("log", fn("abs", base)), Const(a))
    return div(pw(base, Const(e + 1.0)), Const(a * (e + 1.0)))


def _call(h, var):
    if any(_depends(x, var) for x in h.args[1:]):
        return None
    if h.name == "SHF":
        x, x0, amp, w, phi, b = h.args
        if h.order:
            return None
        return antiderivative(add(mul(amp, fn("sin", sub(mul(w, sub(x, x0)), phi))), b), var)
    if h.name in _STEPS:
        ab = _linear(h.args[0], var)
        if ab is None:
            return None
        a = ab[0]
        if h.order:
            return div(call(h.name, h.args, h.order - 1), Const(a))
        return div(Call(_NEG, (h, Const(1.0))), Const(a))
    if h.name == _NEG:
        inner, k = h.args
        ab = _linear(inner.args[0], var)
        return div(Call(_NEG, (inner, Const(k.value + 1.0))), Const(ab[0]))
    return None


def _antiderivative(n, var):
    if not _depends(n, var):
        return mul(n, Var(var))
    if isinstance(n, Bin) and n.op in "+-":
        a, b = _antiderivative(n.a, var), _antiderivative(n.b, var)
        if a is None or b is None:
            return None
        return add(a, b) if n.op == "+" else sub(a, b)
    if isinstance(n, Neg):
        a = _antiderivative(n.a, var)
        return None if a is None else neg(a)
    if isinstance(n, Bin) and n.op in "*/" and not _depends(n.b, var):      # f * c, f / c
        a = _antiderivative(n.a, var)
        return None if a is None else (mul(a, n.b) if n.op == "*" else div(a, n.b))
    if isinstance(n, Bin) and n.op == "*" and not _depends(n.a, var):       # c * f
        b = _antiderivative(n.b, var)
        return None if b is None else mul(n.a, b)
    f = _factors(n, var)
    if f is None:
        return None
    k, c, rest = f
    if not rest:
        return _poly_node(P.polyint(k * np.asarray(c, float)), var)
    if len(rest) != 1:
        return None
    h = rest[0]
    if len(np.trim_zeros(c, "b")) <= 1:
        r = _single(h, var)
        return None if r is None else mul(Const(k * float(c[0]) if len(c) else 0.0), r)
    e = _elementary(h, var)
    return None if e is None else mul(Const(k), _by_parts(c, *e, var))


# ----------------------------------------------------------------------------- lowering the step markers
_SHAPES = {"STEP": "3*s**2 - 2*s**3", "STEP5": "10*s**3 - 15*s**4 + 6*s**5", "HAVSIN": "(1 - cos(pi*s))/2"}


def _shape_antiderivatives(name, n):
    """[p, P_1, ..., P_n]: the step's 0-to-1 shape in s and its antiderivatives vanishing at s = 0."""
    from .expressions import parse
    out = [parse(_SHAPES[name], ("s",)).node]
    for _ in range(n):
        F = _antiderivative(out[-1], "s")
        out.append(sub(F, Const(float(_eval(F, {"s": 0.0})))))
    return out


def _lower_step(h, n, var):
    """n-th antiderivative in x of STEP-like h(x, x0, h0, x1, h1), every lower one zero at x = x0."""
    x, x0, h0, x1, h1 = h.args
    dx = sub(x1, x0)
    s = div(sub(x, x0), dx)
    sc = div(add(sub(fn("abs", s), fn("abs", sub(s, _C1))), _C1), Const(2.0))    # clamp(s, 0, 1)
    w = div(add(sub(s, _C1), fn("abs", sub(s, _C1))), Const(2.0))               # max(s - 1, 0)
    shapes = _shape_antiderivatives(h.name, n)
    mid = _subst(shapes[n], "s", sc)
    for k in range(1, n + 1):
        mid = add(mid, mul(Const(float(_eval(shapes[n - k], {"s": 1.0})) / factorial(k)), pw(w, Const(float(k)))))
    left = div(mul(h0, pw(sub(x, x0), Const(float(n)))), Const(float(factorial(n))))
    return add(left, mul(mul(sub(h1, h0), pw(dx, Const(float(n)))), mid))


def _subst(n, var, value):
    if isinstance(n, Var):
        return value if n.name == var else n
    if isinstance(n, Bin):
        a, b = _subst(n.a, var, value), _subst(n.b, var, value)
        return {"+": add, "-": sub, "*": mul, "/": div, "**": pw}[n.op](a, b)
    if isinstance(n, Neg):
        return neg(_subst(n.a, var, value))
    if isinstance(n, Fn):
        return fn(n.name, *(_subst(a, var, value) for a in n.args))
    if isinstance(n, Call):
        return Call(n.name, tuple(_subst(a, var, value) for a in n.args), n.order, n.table)
    return n


def _lower(n, var):
    if isinstance(n, Bin):
        return {"+": add, "-": sub, "*": mul, "/": div, "**": pw}[n.op](_lower(n.a, var), _lower(n.b, var))
    if isinstance(n, Neg):
        return neg(_lower(n.a, var))
    if isinstance(n, Fn):
        return fn(n.name, *(_lower(a, var) for a in n.args))
    if isinstance(n, Call) and n.name == _NEG:
        return _lower_step(n.args[0], int(n.args[1].value), var)
    return n


# ----------------------------------------------------------------------------- public
def antiderivative(node, var: str = "t", times: int = 1, at: float = 0.0):
    """The `times`-fold antiderivative of `node` in `var` whose value and lower antiderivatives vanish at
    var = at (so with times=1: integral_at^var node), as a tree; None without a closed form here."""
    F, lower = node, []
    for _ in range(times):
        F = _antiderivative(F, var)
        if F is None:
            return None
        lower.append(F)
    # anchor: subtract the Taylor polynomial at `at` of the unanchored result's value and derivatives
    out = _lower(F, var)
    for j in range(times):
        # the j-th derivative of the times-fold antiderivative is the (times - j)-fold one
        Fj = out if j == 0 else _lower(lower[times - 1 - j], var)
        v = float(_eval(Fj, {var: at}))
        if not np.isfinite(v):
            return None
        out = sub(out, mul(Const(v / factorial(j)), pw(sub(Var(var), Const(at)), Const(float(j)))))
    return out


__all__ = ["antiderivative"]

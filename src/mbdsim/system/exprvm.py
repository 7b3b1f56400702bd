"""Expressions in compiled code: parsed expression trees as postfix programs for one numba interpreter.

`compile_expr(expr, variables)` turns an `mbdsim.parse` tree into a `Program` (postfix code, constants,
spline tables); `pack(programs)` concatenates a model's programs into single arrays; `eval_program`
(numba, compiled once and cached: its signature is fixed arrays) evaluates program k with the variable
values x. Semantics are numpy's (nan for log of a negative number, inf for division by zero), the
Adams library (STEP, STEP5, HAVSIN, POLY, SHF with derivative orders; IMPACT, BISTOP and their d/dx) as in `mbdsim.functions`, and
spline tables (Akima, cubic) as piecewise cubics with their derivatives, and user functions (issue 29:
`mbdsim.userfunctions`, numba.njit / numba.cfunc functions of float64 arguments) called through their C
address: op USER after the arguments and a constant holding the address (exact as a float64: addresses are
below 2**53); its operand is 8 * (index of a constant counting the calls that returned a non-finite value:
the run reports them, `mbdsim.userfunctions.failures`) + the number of arguments (1..6). Variables are
slots of x (e.g. x[0] = t [s]); a program never runs Python (a sensor's Python callable is reached the same
way, through a ctypes callback: solvers.pyloads).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import entry, kernel  # noqa: F401  (njit without the wrappers that dominate compilation; issue 32)
from .._exprtree import Bin, Call, Const, ExpressionError, Fn, Neg, Var
from ..solvers.pycall import (call_double_1, call_double_2, call_double_3, call_double_4, call_double_5,
                              call_double_6)

# opcodes (operand in the second column)
CONST, VAR, ADD, SUB, MUL, DIV, POW, NEG, ATAN2 = 0, 1, 2, 3, 4, 5, 6, 7, 8
UNARY = {"sin": 10, "cos": 11, "tan": 12, "asin": 13, "acos": 14, "atan": 15, "sinh": 16, "cosh": 17,
         "tanh": 18, "exp": 19, "log": 20, "sqrt": 21, "abs": 22, "sign": 23}
LIB = {"STEP": 30, "STEP5": 31, "HAVSIN": 32, "POLY": 33, "SHF": 34, "IMPACT": 35, "BISTOP": 36}
TABLE = 40
USER = 50
_BIN = {"+": ADD, "-": SUB, "*": MUL, "/": DIV, "**": POW}


@dataclass(frozen=True)
class Program:
    """Postfix code (n, 2) int64 of (opcode, operand), constants, spline tables, stack depth needed."""

    code: np.ndarray
    consts: np.ndarray
    tables: np.ndarray
    depth: int


@dataclass(frozen=True)
class Packed:
    """Programs concatenated: program k is code[start[k]:end[k]] (operands already offset)."""

    code: np.ndarray
    consts: np.ndarray
    tables: np.ndarray
    start: np.ndarray
    end: np.ndarray
    stack_size: int


class _Emitter:
    def __init__(self, variables):
        self.vars, self.code, self.consts, self.tables = variables, [], [], []
        self.depth = self.max_depth = 0

    def push(self, op, arg=0, pops=0):
        self.code.append((op, arg))
        self.depth += 1 - pops
        self.max_depth = max(self.max_depth, self.depth)

    def emit(self, n):
        if isinstance(n, Const):
            self.consts.append(float(n.value))
            self.push(CONST, len(self.consts) - 1)
        elif isinstance(n, Var):
            if n.name not in self.vars:
                raise ExpressionError(f"variable {n.name!r} has no value in compiled code "
                                      f"(known: {', '.join(self.vars)})")
            self.push(VAR, self.vars[n.name])
        elif isinstance(n, Bin):
            self.emit(n.a)
            self.emit(n.b)
            self.push(_BIN[n.op], 0, 2)
        elif isinstance(n, Neg):
            self.emit(n.a)
            self.push(NEG, 0, 1)
        elif isinstance(n, Fn):
            for a in n.args:
                self.emit(a)
            if n.name == "atan2":
                self.push(ATAN2, 0, 2)
            elif n.name in UNARY:
                self.push(UNARY[n.name], 0, 1)
            else:
                raise ExpressionError(f"function {n.name!r} is not available in compiled code")
        elif isinstance(n, Call):
            self._call(n)
        else:  # pragma: no cover
            raise ExpressionError(f"cannot compile expression node {n!r}")

    def _call(self, n):
        if getattr(n.table, "address", None) is not None:   # a user function (mbdsim.userfunctions)
            self.user_call(n.table.address, n.args)
            return
        if n.table is not None:          # a spline table reads its first argument only
            self.emit(n.args[0])
            pp = getattr(n.table, "_interp", None)
            if pp is None or not hasattr(pp, "c") or pp.c.shape[0] != 4:
                raise ExpressionError(f"table {n.name!r} is not a piecewise cubic spline")
            off = len(self.tables)
            m = pp.c.shape[1]
            ext = 1.0 if pp.extrapolate else 0.0
            self.tables.extend([float(m), ext, *map(float, pp.x), *map(float, pp.c.T.ravel())])
            self.push(TABLE, off * 8 + n.order, 0)
            return
        for a in n.args:
            self.emit(a)
        if n.name in LIB:
            self.push(LIB[n.name], n.order * 64 + len(n.args), len(n.args) - 1)
        else:
            raise ExpressionError(f"function {n.name!r} is not available in compiled code")


    def user_call(self, address, args):
        """The arguments, the C address of the function (a constant) and the USER op (its operand: the
        counter constant of non-finite returns, and the number of arguments)."""
        for a in args:
            self.emit(a)
        self.consts.append(float(address))
        self.push(CONST, len(self.consts) - 1)
        self.consts.append(0.0)
        self.push(USER, (len(self.consts) - 1) * 8 + len(args), len(args) + 1)


def compile_expr(expr, variables: dict[str, int]) -> Program:
    """Program of a parsed expression (an `mbdsim.parse` Expr or its node); `variables` maps each
    variable name to its slot in the input vector x. Unknown variables raise ExpressionError."""
    node = getattr(expr, "node", expr)
    em = _Emitter(dict(variables))
    em.emit(node)
    return Program(np.array(em.code, dtype=np.int64).reshape(-1, 2), np.array(em.consts, dtype=float),
                   np.array(em.tables, dtype=float), max(em.max_depth, 1))


def constant_program(c: float) -> Program:
    """Program that returns the constant c."""
    return Program(np.array([[CONST, 0]], dtype=np.int64), np.array([float(c)]), np.zeros(0), 1)


def pack(programs) -> Packed:
    """One set of arrays for many programs (constant and table operands offset to the packed arrays)."""
    codes, consts, tables, start, end = [], [], [], [], []
    nc = nt = pos = 0
    for p in programs:
        c = p.code.copy()
        c[c[:, 0] == CONST, 1] += nc
        c[c[:, 0] == USER, 1] += nc * 8
        tab = c[:, 0] == TABLE
        c[tab, 1] += nt * 8
        codes.append(c)
        consts.append(p.consts)
        tables.append(p.tables)
        start.append(pos)
        pos += len(c)
        end.append(pos)
        nc += len(p.consts)
        nt += len(p.tables)
    cat = lambda xs, shape: np.concatenate(xs) if xs else np.zeros(shape)  # noqa: E731
    return Packed(cat(codes, (0, 2)).astype(np.int64).reshape(-1, 2), cat(consts, 0).astype(float),
                  cat(tables, 0).astype(float), np.array(start, np.int64), np.array(end, np.int64),
                  max([p.depth for p in programs], default=1) + 1)


def time_programs(tf):
    """(value, d1, d2) programs in the variable t (slot 0) of a TimeFunction, or None when it is a Python
    callable or an integral evaluated by quadrature (those stay on the Python path). A numba.njit /
    numba.cfunc function of t (and its d1 / d2 when given as such) is called from the programs
    (mbdsim.userfunctions.time_programs)."""
    from ..timefunctions import _Constant
    from ..userfunctions import time_programs as user_time_programs
    progs = user_time_programs(tf)
    if progs is not None:
        return progs
    if getattr(tf, "expr", None) is not None:
        return tuple(compile_expr(e, {"t": 0}) for e in (tf.f, tf.f_d1, tf.f_d2))
    if isinstance(tf.f, _Constant):
        return (constant_program(tf.f.c), constant_program(0.0), constant_program(0.0))
    return None


# ----------------------------------------------------------------------------- the interpreter
@kernel(_nrt=False, error_model="numpy")
def _poly_step(deg, x, x0, h0, x1, h1, order):
    """STEP (deg 3) / STEP5 (deg 5) and their derivatives, as mbdsim.functions."""
    if order == 0:
        if x <= x0:
            return h0
        if x >= x1:
            return h1
    elif x <= x0 or x >= x1:
        return 0.0
    dx = x1 - x0
    s = (x - x0) / dx
    # coefficients of s^k
    c0 = c1 = c2 = c3 = c4 = c5 = 0.0
    if deg == 3:
        c2, c3 = 3.0, -2.0
    else:
        c3, c4, c5 = 10.0, -15.0, 6.0
    val = 0.0
    cs = (c0, c1, c2, c3, c4, c5)
    for k in range(order, 6):
        f = 1.0
        for j in range(order):
            f *= k - j
        val += cs[k] * f * s ** (k - order)
    out = (h1 - h0) * val / dx ** order
    return out + h0 if order == 0 else out


@kernel(_nrt=False, error_model="numpy")
def _impact(x, xd, x1, k, e, cmax, d, order):
    """Adams IMPACT (mbdsim.functions.impact) and, order 1, its partial d/dx at fixed xd."""
    p = x1 - x
    if p <= 0.0:
        return 0.0
    c = _poly_step(3, x, x1 - d, cmax, x1, 0.0, 0)
    f = k * p ** e - c * xd
    if f <= 0.0:
        return 0.0
    if order == 0:
        return f
    return -k * e * p ** (e - 1.0) - _poly_step(3, x, x1 - d, cmax, x1, 0.0, 1) * xd


@kernel(_nrt=False, error_model="numpy")
def _table(tables, off, order, x):
    """Piecewise cubic (scipy PPoly layout) and its derivatives at x; nan outside when not extrapolating."""
    m = int(tables[off])
    ext = tables[off + 1] != 0.0
    xs = off + 2
    cs = xs + m + 1
    if not ext and (x < tables[xs] or x > tables[xs + m]):
        return np.nan
    i = 0
    lo, hi = 0, m - 1
    while lo < hi:                       # interval: last breakpoint <= x (clamped to the ends)
        mid = (lo + hi + 1) // 2
        if tables[xs + mid] <= x:
            lo = mid
        else:
            hi = mid - 1
    i = lo
    u = x - tables[xs + i]
    a3, a2, a1, a0 = tables[cs + 4 * i], tables[cs + 4 * i + 1], tables[cs + 4 * i + 2], tables[cs + 4 * i + 3]
    if order == 0:
        return ((a3 * u + a2) * u + a1) * u + a0
    if order == 1:
        return (3.0 * a3 * u + 2.0 * a2) * u + a1
    if order == 2:
        return 6.0 * a3 * u + 2.0 * a2
    if order == 3:
        return 6.0 * a3
    return 0.0


@kernel(_nrt=False, error_model="numpy")
def _user_call(address, nargs, stack, base):
    """f(stack[base], ..., stack[base + nargs - 1]) of the C function `double f(double, ...)` at `address`
    (nan for address 0 or an arity beyond pycall.MAX_ARGS)."""
    if address == 0:
        return np.nan
    if nargs == 1:
        return call_double_1(address, stack[base])
    if nargs == 2:
        return call_double_2(address, stack[base], stack[base + 1])
    if nargs == 3:
        return call_double_3(address, stack[base], stack[base + 1], stack[base + 2])
    if nargs == 4:
        return call_double_4(address, stack[base], stack[base + 1], stack[base + 2], stack[base + 3])
    if nargs == 5:
        return call_double_5(address, stack[base], stack[base + 1], stack[base + 2], stack[base + 3],
                             stack[base + 4])
    if nargs == 6:
        return call_double_6(address, stack[base], stack[base + 1], stack[base + 2], stack[base + 3],
                             stack[base + 4], stack[base + 5])
    return np.nan


@kernel(_nrt=False, error_model="numpy")
def eval_program(code, consts, tables, start, end, x, stack):
    """Value of the program code[start:end] for variable values x (stack: work array of the packed size)."""
    sp = 0
    for pc in range(start, end):
        op = code[pc, 0]
        arg = code[pc, 1]
        if op == 0:
            stack[sp] = consts[arg]
            sp += 1
        elif op == 1:
            stack[sp] = x[arg]
            sp += 1
        elif op <= 6 or op == 8:
            b = stack[sp - 1]
            a = stack[sp - 2]
            sp -= 1
            if op == 2:
                r = a + b
            elif op == 3:
                r = a - b
            elif op == 4:
                r = a * b
            elif op == 5:
                r = a / b
            elif op == 6:
                r = np.power(a, b)
            else:
                r = np.arctan2(a, b)
            stack[sp - 1] = r
        elif op == 7:
            stack[sp - 1] = -stack[sp - 1]
        elif op < 30:
            u = stack[sp - 1]
            if op == 10:
                r = np.sin(u)
            elif op == 11:
                r = np.cos(u)
            elif op == 12:
                r = np.tan(u)
            elif op == 13:
                r = np.arcsin(u)
            elif op == 14:
                r = np.arccos(u)
            elif op == 15:
                r = np.arctan(u)
            elif op == 16:
                r = np.sinh(u)
            elif op == 17:
                r = np.cosh(u)
            elif op == 18:
                r = np.tanh(u)
            elif op == 19:
                r = np.exp(u)
            elif op == 20:
                r = np.log(u)
            elif op == 21:
                r = np.sqrt(u)
            elif op == 22:
                r = abs(u)
            else:
                r = np.sign(u)
            stack[sp - 1] = r
        elif op < 40:
            nargs = arg % 64
            order = arg // 64
            base = sp - nargs
            xx = stack[base]
            if op == 30 or op == 31:
                r = _poly_step(3 if op == 30 else 5, xx, stack[base + 1], stack[base + 2], stack[base + 3],
                               stack[base + 4], order)
            elif op == 32:                         # HAVSIN
                x0, h0, x1, h1 = stack[base + 1], stack[base + 2], stack[base + 3], stack[base + 4]
                dx = x1 - x0
                uu = np.pi * (xx - x0) / dx
                dh = h1 - h0
                if order == 0:
                    r = h0 if xx <= x0 else (h1 if xx >= x1 else h0 + dh * (1.0 - np.cos(uu)) / 2.0)
                elif xx <= x0 or xx >= x1:
                    r = 0.0
                else:
                    r = -dh / 2.0 * (np.pi / dx) ** order * np.cos(uu + order * np.pi / 2.0)
            elif op == 35:                         # IMPACT(x, xdot, x1, k, e, cmax, d)
                r = _impact(xx, stack[base + 1], stack[base + 2], stack[base + 3], stack[base + 4],
                            stack[base + 5], stack[base + 6], order)
            elif op == 36:                         # BISTOP(x, xdot, x1, x2, k, e, cmax, d): IMPACT minus its mirror
                k, e, cm, d = stack[base + 4], stack[base + 5], stack[base + 6], stack[base + 7]
                r = (_impact(xx, stack[base + 1], stack[base + 2], k, e, cm, d, order)
                     - (-1.0) ** order * _impact(-xx, -stack[base + 1], -stack[base + 3], k, e, cm, d, order))
            elif op == 33:                         # POLY(x, x0, a0, ..., an): Horner on the derivative
                uu = xx - stack[base + 1]
                r = 0.0
                for j in range(nargs - 3, order - 1, -1):
                    f = 1.0
                    for k in range(order):
                        f *= j - k
                    r = r * uu + stack[base + 2 + j] * f
            else:                                  # SHF(x, x0, a, w, phi, b)
                x0, a, w, ph, b = stack[base + 1], stack[base + 2], stack[base + 3], stack[base + 4], stack[base + 5]
                r = a * w ** order * np.sin(w * (xx - x0) - ph + order * np.pi / 2.0)
                if order == 0:
                    r += b
            sp = base + 1
            stack[base] = r
        elif op == 40:                             # spline table: AKISPL-style, argument first
            r = _table(tables, arg // 8, arg % 8, stack[sp - 1])
            stack[sp - 1] = r
        else:                                      # USER: f(args) at the address on the stack's top
            nargs = arg % 8
            base = sp - 1 - nargs
            r = _user_call(np.int64(stack[sp - 1]), nargs, stack, base)
            if not np.isfinite(r):
                consts[arg // 8] += 1.0
            stack[base] = r
            sp = base + 1
    return stack[0]

"""Safe expression language for drivers and function-library calls, with exact derivatives.

``parse("pi/6*(1-cos(pi*t/2))")`` returns an :class:`Expr`: ``expr(t)`` evaluates it on a float or
a numpy array, ``expr.derivative()`` is its exact symbolic derivative (another Expr).

Grammar (everything else is rejected with an :class:`ExpressionError` that quotes the text, the
offending token and its position): numbers (``2``, ``0.5``, ``1e-3``); the variables given to
``parse`` (default only ``t``, time in s); the constant ``pi``; ``+ - * / **``, unary ``+``/``-``,
parentheses; the functions sin cos tan asin acos atan atan2 sinh cosh tanh exp log sqrt abs sign
(angles in rad); the Adams library STEP STEP5 HAVSIN POLY SHF (see :mod:`mbdsim.functions`;
lower-case aliases too, and ``order=n`` for their n-th derivative with respect to the first
argument); and tables passed to ``parse(..., tables={name: table})``, called as ``name(x)``.
The text is parsed with :mod:`ast` (``mode="eval"``) and the tree walked against a whitelist: it
is never given to eval/compile/exec.

The drivers' helper :func:`time_function` (in :mod:`mbdsim.timefunctions`, re-exported here)
turns a string, a number or a callable of t [s] into a :class:`TimeFunction` with value/d1/d2.
"""
from __future__ import annotations

import ast
from math import pi

import numpy as np

from . import functions as _lib
from ._exprtree import (FUNCTIONS, LIBRARY_FUNCTIONS, Const, ExpressionError, Var, _depends, _diff, _eval, _NP,
                        _text, add, call, div, fn, mul, neg, pw, sub)

__all__ = ["ExpressionError", "Expr", "parse", "FUNCTIONS", "LIBRARY_FUNCTIONS",
           "TimeFunction", "time_function", "integrated", "double_integrated"]

MAX_LENGTH, MAX_DEPTH, MAX_ORDER = 10_000, 200, 20
MAX_NODES = 20_000   # operations of an expression or of its derivatives: evaluation cost stays bounded


def tree_size(node, limit: int = MAX_NODES) -> int:
    """Operations in the expression tree `node` counted as evaluated (shared sub-trees count every time
    they occur), stopping once past `limit`: linear in the number of distinct nodes."""
    memo: dict[int, int] = {}
    stack = [(node, False)]
    while stack:
        n, done = stack.pop()
        kids = (n.a, n.b) if hasattr(n, "b") else (n.a,) if hasattr(n, "a") else tuple(getattr(n, "args", ()))
        if done:
            memo[id(n)] = min(limit + 1, 1 + sum(memo[id(k)] for k in kids))
        elif id(n) not in memo:
            stack.append((n, True))
            stack.extend((k, False) for k in kids if id(k) not in memo)
    return memo[id(node)]


# ----------------------------------------------------------------------------- Expr
class Expr:
    """A parsed expression of ``variables`` (default ``("t",)``); immutable.

    ``expr(t)`` / ``expr.evaluate(t)``: value for a float (returns float) or numpy array (returns
    ndarray of the broadcast shape); several variables are given positionally in the order of
    ``variables`` or by keyword. Units are the caller's: t in s, output in the unit of the
    quantity it describes (m, rad, N ...).
    """

    __slots__ = ("node", "variables", "_source")

    def __init__(self, node, variables=("t",), source: str | None = None):
        self.node, self.variables, self._source = node, tuple(variables), source

    @property
    def text(self) -> str:
        """The source text if parsed, else a canonical text that parse() reads back."""
        return self._source if self._source is not None else _text(self.node)

    def evaluate(self, *args, **kwargs):
        if not kwargs and len(args) == 1 == len(self.variables) and type(args[0]) in (float, int, np.float64):
            with np.errstate(all="ignore"):   # fast path: one real scalar (the solvers' hot path)
                return float(_eval(self.node, {self.variables[0]: float(args[0])}))
        if len(args) > len(self.variables):
            raise TypeError(f"expression of {self.variables} got {len(args)} positional values")
        values = dict(zip(self.variables, args), **kwargs)
        missing = [v for v in self.variables if v not in values and _depends(self.node, v)]
        if missing or set(values) - set(self.variables):
            raise TypeError(f"expression {self.text!r} takes values for {self.variables}, got {tuple(values)}")
        env = {k: np.asarray(v, dtype=complex if np.iscomplexobj(v) else float) for k, v in values.items()}
        with np.errstate(all="ignore"):
            out = _eval(self.node, env)
        shape = np.broadcast_shapes(*(a.shape for a in env.values())) if env else ()
        if shape:
            return np.array(np.broadcast_to(out, shape))
        out = np.asarray(out)[()]
        return complex(out) if np.iscomplexobj(out) else float(out)

    __call__ = evaluate

    def derivative(self, var: str = "t") -> "Expr":
        """Exact symbolic derivative d(self)/d(var), simplified; ExpressionError when it would take more
        than MAX_NODES operations to evaluate (deeply nested expressions)."""
        d = _diff(self.node, var)
        if tree_size(d) > MAX_NODES:
            raise ExpressionError(f"its derivative needs more than {MAX_NODES} operations (nesting too deep "
                                  "or expression too large): simplify or split it", self.text[:200])
        return Expr(d, self.variables)

    def depends_on(self, var: str = "t") -> bool:
        return _depends(self.node, var)

    @property
    def is_constant(self) -> bool:
        return not any(_depends(self.node, v) for v in self.variables)

    def __repr__(self) -> str:
        return f"Expr({self.text!r})"

    def __str__(self) -> str:
        return self.text


# ----------------------------------------------------------------------------- parser
_BINOPS = {ast.Add: ("+", add), ast.Sub: ("-", sub), ast.Mult: ("*", mul), ast.Div: ("/", div), ast.Pow: ("**", pw)}
_OPNAMES = {ast.Mod: "%", ast.FloorDiv: "//", ast.MatMult: "@", ast.BitXor: "^", ast.BitAnd: "&",
            ast.BitOr: "|", ast.LShift: "<<", ast.RShift: ">>", ast.Not: "not", ast.Invert: "~"}
_KINDS = {ast.Attribute: "attribute access", ast.Subscript: "subscript", ast.Lambda: "lambda",
          ast.Compare: "comparison", ast.BoolOp: "boolean operator", ast.IfExp: "conditional expression",
          ast.List: "list", ast.Tuple: "tuple", ast.Dict: "dict", ast.Set: "set", ast.Starred: "starred argument",
          ast.NamedExpr: "assignment", ast.JoinedStr: "f-string", ast.ListComp: "comprehension",
          ast.GeneratorExp: "generator", ast.DictComp: "comprehension", ast.SetComp: "comprehension",
          ast.Await: "await", ast.Yield: "yield", ast.Slice: "slice"}
_ARITY = {"atan2": (2, 2)}


def parse(text: str, variables: Sequence[str] = ("t",), *, tables: dict[str, Any] | None = None,
          measures: Any = None) -> Expr:
    """Parse ``text`` into an :class:`Expr` of ``variables`` (see the module docstring for the grammar).

    ``tables``: optional {name: table}, each callable as ``table(x, order=n)`` (e.g.
    :class:`mbdsim.functions.Akima`), usable in the text as ``name(x)``.
    ``measures``: optional hook for state measures (load expressions, :mod:`mbdsim.model.loadexpr`): an
    object with ``names`` (the measure function names) and ``call(name, args, fail) -> Var`` receiving
    the argument texts (``"rod"``, ``"rod.tip"``); the returned variable is added to the Expr's variables.
    """
    if not isinstance(text, str):
        raise TypeError(f"expression must be a str, got {type(text).__name__}")
    variables, tables = tuple(variables), dict(tables or {})
    reserved = set(FUNCTIONS) | set(LIBRARY_FUNCTIONS) | {"pi"}
    for name in (*variables, *tables):
        if not name.isidentifier() or name in reserved:
            raise ValueError(f"{name!r} cannot be a variable or table name (not an identifier, or reserved)")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression longer than {MAX_LENGTH} characters", text[:60] + "...")
    body = text.translate({9: " ", 10: " ", 13: " "})
    lead = len(body) - len(body.lstrip())
    if not body.strip():
        raise ExpressionError("empty expression", text, "", 0)
    try:
        tree = ast.parse(body.lstrip(), mode="eval")
    except SyntaxError as exc:
        pos = lead + max((exc.offset or 1) - 1, 0)
        raise ExpressionError(f"syntax error ({exc.msg}) near {text[pos:pos + 10]!r}", text, text[pos:pos + 10], pos) from None
    except (RecursionError, MemoryError, ValueError) as exc:
        raise ExpressionError(f"expression cannot be parsed ({type(exc).__name__})", text) from None

    src = body.lstrip()
    measure_names = tuple(getattr(measures, "names", ()))
    reserved |= set(measure_names)
    extra_vars: list[str] = []

    def fail(what, node, token=None):
        pos = lead + len(src.encode()[:node.col_offset].decode(errors="ignore"))
        token = ast.get_source_segment(src, node) if token is None else token
        shown = token if len(token) <= 60 else token[:57] + "..."
        raise ExpressionError(f"{what} {shown!r}" if token else what, text, token, pos)

    def finite(node, result, parts):
        if all(isinstance(p, Const) for p in parts) and not isinstance(result, Const):
            fail("constant subexpression is not a finite number:", node)
        return result

    def walk(n, depth):
        if depth > MAX_DEPTH:
            fail(f"expression nested deeper than {MAX_DEPTH} levels at", n)
        if isinstance(n, ast.Constant):
            if type(n.value) not in (int, float):
                fail("only real numbers are allowed as constants, not", n)
            try:
                return Const(float(n.value))
            except OverflowError:
                fail("number too large:", n)
        if isinstance(n, ast.Name):
            if n.id in variables:
                return Var(n.id)
            if n.id == "pi":
                return Const(pi)
            if n.id in reserved or n.id in tables:
                fail("function must be called with arguments:", n)
            fail(f"unknown name (allowed variables: {', '.join(variables)}; constant: pi):", n)
        if isinstance(n, ast.BinOp):
            if type(n.op) not in _BINOPS:
                hint = " (use ** for powers)" if isinstance(n.op, ast.BitXor) else ""
                fail(f"operator {_OPNAMES.get(type(n.op), '?')!r} not allowed{hint} in", n)
            a, b = walk(n.left, depth + 1), walk(n.right, depth + 1)
            return finite(n, _BINOPS[type(n.op)][1](a, b), (a, b))
        if isinstance(n, ast.UnaryOp):
            if isinstance(n.op, ast.USub):
                return neg(walk(n.operand, depth + 1))
            if isinstance(n.op, ast.UAdd):
                return walk(n.operand, depth + 1)
            fail(f"operator {_OPNAMES.get(type(n.op), '?')!r} not allowed in", n)
        if isinstance(n, ast.Call):
            return walk_call(n, depth)
        fail(f"{_KINDS.get(type(n), type(n).__name__)} not allowed:", n)

    def walk_call(n, depth):
        if not isinstance(n.func, ast.Name):
            fail("only whitelisted functions may be called, by name; not allowed: call of", n.func)
        name = n.func.id
        if name in measure_names:
            return walk_measure(n, name)
        lib = name.upper() if name in LIBRARY_FUNCTIONS else None
        if name not in _NP and lib is None and name not in tables:
            fail(f"function not allowed (allowed: "
                 f"{', '.join(FUNCTIONS + LIBRARY_FUNCTIONS + tuple(tables) + measure_names)}):", n.func)
        for a in n.args:
            if isinstance(a, ast.Starred):
                fail("starred argument not allowed:", a)
        order = 0
        for kw in n.keywords:
            if name in _NP or kw.arg != "order" or not (isinstance(kw.value, ast.Constant) and type(kw.value.value) is int
                                                        and 0 <= kw.value.value <= MAX_ORDER):
                fail(f"keyword argument not allowed (only order=<0..{MAX_ORDER}> for library functions and tables):", kw)
            order = kw.value.value
        args = [walk(a, depth + 1) for a in n.args]
        if name in tables:   # a table of x, or a user function of its arguments (mbdsim.userfunctions)
            lo = hi = getattr(tables[name], "nargs", 1)
            if order and hasattr(tables[name], "nargs"):
                fail(f"{name} is a user function: it has no derivatives (order=), in", n)
        elif lib:
            lo, hi = _lib.LIBRARY[lib].min_args, _lib.LIBRARY[lib].max_args
        else:
            lo, hi = _ARITY.get(name, (1, 1))
        if len(args) < lo or (hi is not None and len(args) > hi):
            fail(f"{name} takes {lo if lo == hi else f'at least {lo}'} argument(s), got {len(args)}:", n)
        if name in _NP:
            return finite(n, fn(name, *args), args)
        if lib and all(isinstance(a, Const) for a in args[1:]):         # check constant parameters now
            try:
                _lib.LIBRARY[lib].fn(0.0, *(a.value for a in args[1:]))
            except ValueError as exc:                                    # e.g. STEP with x1 <= x0
                fail(f"invalid arguments ({exc}):", n)
        return finite(n, call(lib or name, tuple(args), order, tables.get(name)), args)

    def walk_measure(n, name):
        if n.keywords:
            fail(f"{name} takes no keyword arguments:", n.keywords[0].value)
        args = []
        for a in n.args:
            if isinstance(a, ast.Name):
                args.append(a.id)
            elif isinstance(a, ast.Attribute) and isinstance(a.value, ast.Name):
                args.append(f"{a.value.id}.{a.attr}")
            else:
                fail(f"arguments of {name} name a body (its centre of mass) or a marker as body.marker, not", a)
        var = measures.call(name, args, lambda what, node=n: fail(what, node))
        if var.name not in extra_vars and var.name not in variables:
            extra_vars.append(var.name)
        return var

    node = walk(tree.body, 0)
    return Expr(node, variables + tuple(extra_vars), text)


from .timefunctions import TimeFunction, double_integrated, integrated, time_function  # noqa: E402
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Sequence
    from typing import Any

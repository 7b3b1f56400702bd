"""Outputs of a study: named scalar measures of a Result, as safe expressions or callables.

An output expression is Python-like text read with `ast` and interpreted here (never eval'd):
numbers, strings, + - * / ** , indexing ([:, 0]), and calls of the whitelisted names below.

Signals (arrays over the output times; SI units, ground axes unless a frame is given):
    t, position(x), velocity(x), acceleration(x), angular_velocity(b), angular_acceleration(b),
    joint_coordinate(j), joint_velocity(j), joint_acceleration(j), reaction_force(j), reaction_torque(j)
    (the minimum-norm values where redundant constraints leave components indeterminate, without
    Result's determinacy flags: check those once with Result.reaction_determinacy),
    driver_effort(m), spring_length(s), spring_velocity(s), spring_force(s), kinetic_energy(),
    potential_energy()      (keywords as in Result: frame=, on=, relative_to=, kind=)
Element-wise: x(v), y(v), z(v) (components of an (N, 3) signal), norm(v), abs, sqrt, sin, cos, degrees.
Reductions to a scalar: max, min, peak (max |s|), time_of_max, time_of_min (refined on the dense output,
mbdsim.results.refine: the conventions of Result.maximum/minimum, a grid of times per evaluation), mean,
rms, std, initial, final, integral (trapezoid over time), crossing(s, value, direction=0) (time of the
first crossing, refined like Result.crossings; NaN when none).
Example: "max(norm(reaction_force('crank_rod')))", "peak(x(acceleration('slider')))".

A callable output is called with the Result and must return a number.
Template values of a study's `set` section use the same reader with the parameters as names:
"{crank + rod}" -> crank + rod (SI numbers).
"""
from __future__ import annotations

import ast
import math
import operator
import re
from functools import lru_cache

import numpy as np

from ..errors import ModelError
from ..results import refine

__all__ = ["compile_output", "evaluate_outputs", "fill_template", "OutputError"]


class OutputError(ModelError):
    """An output expression that cannot be read or evaluated (names the output)."""


MEASURES = ("position", "velocity", "acceleration", "angular_velocity", "angular_acceleration",
            "joint_coordinate", "joint_velocity", "joint_acceleration", "reaction_force", "reaction_torque",
            "driver_effort", "spring_length", "spring_velocity", "spring_force", "kinetic_energy",
            "potential_energy")
ELEMENTWISE = {
    "x": lambda v: _component(v, 0), "y": lambda v: _component(v, 1), "z": lambda v: _component(v, 2),
    "norm": lambda v: np.linalg.norm(np.atleast_2d(v), axis=-1), "abs": np.abs, "sqrt": np.sqrt,
    "sin": np.sin, "cos": np.cos, "degrees": np.degrees,
}
SIMPLE_REDUCTIONS = {
    "mean": np.mean, "rms": lambda s: float(np.sqrt(np.mean(np.square(s)))), "std": np.std,
    "initial": lambda s: s[0], "final": lambda s: s[-1],
}
REFINED = {"max": (+1, 1), "min": (-1, 1), "time_of_max": (+1, 0), "time_of_min": (-1, 0)}
REACTIONS = {"reaction_force": 0, "reaction_torque": 1}
KEYWORDS = {"frame", "on", "relative_to", "kind", "direction"}
BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
          ast.Pow: operator.pow}
UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
CONSTANTS = {"pi": math.pi, "e": math.e}
TEMPLATE_FUNCS = frozenset({"sqrt", "sin", "cos", "abs", "max", "min"})


_trapezoid = getattr(np, "trapezoid", None) or np.trapz


def _component(v, k):
    a = np.asarray(v)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"x/y/z take a vector signal (N, 3), got shape {a.shape}")
    return a[:, k]


def _signal(v, fn):
    a = np.asarray(v, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"{fn}() takes a scalar signal; reduce a vector with norm(), x(), y() or z() "
                         f"(got shape {a.shape})")
    return a


class _Checker(ast.NodeVisitor):
    """Refuses every node except the small arithmetic/call language above."""

    def __init__(self, names: set[str]):
        self.names = names

    def generic_visit(self, node):
        allowed = (ast.Expression, ast.Constant, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load,
                   ast.Subscript, ast.Slice, ast.Tuple, ast.keyword, *BINOPS, *UNARY)
        if not isinstance(node, allowed):
            raise ValueError(f"{type(node).__name__} is not allowed in an expression")
        super().generic_visit(node)

    def visit_Name(self, node):
        if node.id not in self.names:
            raise ValueError(f"unknown name {node.id!r}")

    def visit_Constant(self, node):
        if not isinstance(node.value, (int, float, str)) or isinstance(node.value, bool):
            raise ValueError(f"constant {node.value!r} is not allowed")

    def visit_Call(self, node):
        if not isinstance(node.func, ast.Name):
            raise ValueError("only named functions may be called")
        for kw in node.keywords:
            if kw.arg not in KEYWORDS:
                raise ValueError(f"unknown keyword {kw.arg!r}; keywords are: {', '.join(sorted(KEYWORDS))}")
        self.generic_visit(node)


OUTPUT_NAMES = {"t", *MEASURES, *ELEMENTWISE, *SIMPLE_REDUCTIONS, *REFINED, "peak", "integral", "crossing",
                *CONSTANTS}


@lru_cache(maxsize=512)
def _parse(text: str, names: frozenset) -> ast.Expression:
    tree = ast.parse(text.strip(), mode="eval")
    _Checker(set(names)).visit(tree)
    return tree


class _Interpreter:
    """Evaluates a checked tree against a Result (signals) and a namespace of numbers."""

    def __init__(self, namespace: dict):
        self.ns = namespace

    def ev(self, node, res):
        if isinstance(node, ast.Expression):
            return self.ev(node.body, res)
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            if node.id == "t":
                return res.time
            return self.ns[node.id] if node.id in self.ns else CONSTANTS[node.id]
        if isinstance(node, ast.BinOp):
            a, b = self.ev(node.left, res), self.ev(node.right, res)
            if isinstance(node.op, ast.Pow):   # in double precision: Python's exact integer power of
                with np.errstate(all="ignore"):   # "9**9**9" would never end (inf instead: a clear error)
                    return np.power(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
            return BINOPS[type(node.op)](a, b)
        if isinstance(node, ast.UnaryOp):
            return UNARY[type(node.op)](self.ev(node.operand, res))
        if isinstance(node, ast.Subscript):
            return np.asarray(self.ev(node.value, res))[self._index(node.slice, res)]
        return self._call(node, res)

    def _index(self, node, res):
        if isinstance(node, ast.Tuple):
            return tuple(self._index(e, res) for e in node.elts)
        if isinstance(node, ast.Slice):
            part = [None if p is None else int(self.ev(p, res)) for p in (node.lower, node.upper, node.step)]
            return slice(*part)
        return int(self.ev(node, res))

    def _call(self, node, res):
        fn = node.func.id
        kw = {k.arg: self.ev(k.value, res) for k in node.keywords}
        if fn in MEASURES:
            args = [self.ev(a, res) for a in node.args]
            if fn in REACTIONS and hasattr(res, "_reaction"):
                # the values of Result.reaction_force/torque without their determinacy analysis (an SVD
                # per sample at every call; with redundant constraints the indeterminate components are
                # the minimum-norm split either way: check them once with Result.reaction_determinacy)
                given = {**dict(zip(("joint", "on", "frame"), args)), **kw}
                if len(args) > 3 or set(given) - {"joint", "on", "frame"} or "joint" not in given:
                    raise TypeError(f"{fn}(joint, on=None, frame=None): got {len(args)} arguments and "
                                    f"keywords {sorted(kw)}")
                return res._reaction(given["joint"], given.get("on"), given.get("frame"))[REACTIONS[fn]]
            return getattr(res, fn)(*args, **kw)
        args = node.args
        if fn in REFINED and len(args) == 1:
            sign, which = REFINED[fn]
            signal = lambda r: _signal(self.ev(args[0], r), fn)  # noqa: E731
            return float(refine.extremum(res, signal, sign)[which])
        vals = [self.ev(a, res) for a in args]
        if fn in ("max", "min"):
            return (np.maximum if fn == "max" else np.minimum)(*vals)
        if fn in ELEMENTWISE:
            return ELEMENTWISE[fn](*vals)
        if fn in SIMPLE_REDUCTIONS:
            return float(SIMPLE_REDUCTIONS[fn](_signal(vals[0], fn)))
        if fn == "peak":
            return float(np.max(np.abs(_signal(vals[0], fn))))
        if fn == "integral":
            return float(_trapezoid(_signal(vals[0], fn), res.time))
        if fn == "crossing":
            return self._crossing(args, vals, kw, res)
        raise ValueError(f"{fn!r} is not a function")

    def _crossing(self, args, vals, kw, res):
        if len(vals) != 2:
            raise ValueError("crossing(signal, value, direction=0) takes a signal and a level")
        return refine.first_crossing(res, lambda r: _signal(self.ev(args[0], r), "crossing"), float(vals[1]),
                                     int(kw.get("direction", 0)))


def compile_output(name: str, spec):
    """A callable f(result) -> float for output `name` (an expression string or a callable).

    Raises OutputError naming the output when the text is not a valid expression."""
    if callable(spec):
        return spec
    if not isinstance(spec, str):
        raise OutputError(f"study output '{name}'", "expression", f"expected a string or a callable, got {spec!r}")
    try:
        tree = _parse(spec, frozenset(OUTPUT_NAMES))
    except (SyntaxError, ValueError) as exc:
        raise OutputError(f"study output '{name}'", "expression", f"{spec!r}: {exc}") from None
    return lambda res: _Interpreter({}).ev(tree, res)


def evaluate_outputs(outputs: dict, res) -> dict:
    """{name: float} of every output on `res`; a value that is not one number raises OutputError (nan and
    inf pass through, e.g. the time of an event that never happens, or an overflow)."""
    out = {}
    for name, spec in outputs.items():
        try:
            value = np.asarray(compile_output(name, spec)(res), dtype=float)
        except OutputError:
            raise
        except Exception as exc:  # noqa: BLE001 - any failure of a user measure names the output
            raise OutputError(f"study output '{name}'", "expression", f"{type(exc).__name__}: {exc}") from None
        if value.size != 1:
            raise OutputError(f"study output '{name}'", "expression",
                              f"must give one number, got an array of shape {value.shape} (reduce it: max, final...)")
        out[name] = float(value.reshape(()))
    return out


_FIELD = re.compile(r"\{([^{}]+)\}")


def fill_template(value, params: dict, where: str):
    """A `set` value with {expr} fields filled from `params` (SI numbers); lists are filled item by item.

    A string that is one field gives the number itself; otherwise the numbers are written into the text
    (e.g. an expression "2*pi*{speed}*t").  Raises ModelError naming `where`."""
    if isinstance(value, list):
        return [fill_template(v, params, f"{where}[{k}]") for k, v in enumerate(value)]
    if isinstance(value, dict):
        return {k: fill_template(v, params, f"{where}.{k}") for k, v in value.items()}
    if not isinstance(value, str) or "{" not in value:
        return value
    names = frozenset(k for k in params if k.isidentifier()) | frozenset(CONSTANTS) | TEMPLATE_FUNCS

    def one(text):
        try:
            return float(_Interpreter(params).ev(_parse(text, names), None))
        except (SyntaxError, ValueError, TypeError, ZeroDivisionError) as exc:
            raise ModelError(f"study set '{where}'", "value", f"{{{text}}}: {exc}") from None
    whole = _FIELD.fullmatch(value.strip())
    if whole:
        return one(whole.group(1))
    return _FIELD.sub(lambda m: repr(one(m.group(1))), value)

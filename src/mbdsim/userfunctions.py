"""User functions that run inside the compiled kernels (issue 29): `numba.njit` and `numba.cfunc` scalar
functions of float64 arguments returning a float64.

- In load, sensor and output expressions: `model.add_function(name, fn)` (mbdsim.model.signals) makes
  `name(x, ...)` callable in the model's expression strings, with as many arguments as `fn` takes (1 to 6);
  e.g. `model.add_function("drag", drag)` and `add_torque(..., torque=(0, 0, "-drag(pin_dot)"))`.
- As a driver function of t: `add_motion(..., displacement=f)` with an njit f(t) -> float [m or rad], or
  `mb.time_function(f, d1=g, d2=h)` with njit derivatives g, h [unit/s, unit/s^2]. Without them d1 and d2
  are the 8th-order central differences of f at t + k H_STEP, k = -4..4 (H_STEP = 0.004 s): truncation
  error about (omega H_STEP)^8 / 600 relative for a component of angular frequency omega [rad/s] (2e-12 at
  3 rev/s, 1e-6 at 100 rad/s) and rounding about 1e-10 |f| / s^2 in d2; faster motions need d1/d2.

An njit dispatcher is compiled here into a numba.cfunc of the right arity (once per function and arity,
kept); a cfunc is used as given (its signature must be float64(float64, ...)). The kernels call the
function through its C address (system.exprvm's USER op, solvers.pycall.call_double_*), an indirect call
of a few ns: the cached kernels stay valid, only the address is run-time data, and no Python runs in the
loop. A call that returns a non-finite value is counted in the program's constants; the run then ends with
an EvaluationError naming the function and the elements that call it (`failures`). A plain Python callable
is refused where a compiled function is required (ModelError naming the function).
"""
from __future__ import annotations

import inspect

import numpy as np

from .errors import EvaluationError, ModelError

__all__ = ["UserFunction", "is_numba", "user_function"]

H_STEP = 0.004                      # [s] the central-difference step of a driver's d1/d2 without derivatives
MAX_ARGS = 6                        # solvers.pycall.MAX_ARGS
# 8th-order central-difference weights at offsets 1..4 (d1 antisymmetric, d2 symmetric; c0 the centre)
_D1_8 = (4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0)
_D2_8 = (8.0 / 5.0, -1.0 / 5.0, 8.0 / 315.0, -1.0 / 560.0)
_D2_8_C0 = -205.0 / 72.0

_CACHE: dict = {}                   # (id(fn), nargs, name) -> (fn, UserFunction): one cfunc per function and arity
_BY_ADDRESS: dict = {}              # C address -> UserFunction (naming a failure)


def _is_cfunc(fn) -> bool:
    return type(fn).__module__.startswith("numba.") and hasattr(fn, "address") and hasattr(fn, "_sig")


def _is_dispatcher(fn) -> bool:
    return type(fn).__module__.startswith("numba.") and callable(getattr(fn, "py_func", None))


def is_numba(fn) -> bool:
    """Whether `fn` is a numba.njit dispatcher or a numba.cfunc (compiled: runs inside the kernels)."""
    return _is_cfunc(fn) or _is_dispatcher(fn)


def _arity(fn, entity) -> int:
    if _is_cfunc(fn):
        return len(fn._sig.args)
    try:
        params = inspect.signature(fn.py_func).parameters.values()
    except (TypeError, ValueError):
        raise ModelError(entity, "function", "its arguments cannot be inspected: give a numba.cfunc") from None
    if any(p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD, p.KEYWORD_ONLY) for p in params):
        raise ModelError(entity, "function", "takes *args, **kwargs or keyword-only arguments: "
                         "a compiled user function takes positional float arguments only")
    return sum(1 for p in params if p.default is p.empty)


class UserFunction:
    """A numba function of `nargs` float64 arguments returning float64, callable from compiled code through
    `address` (its cfunc's) and from Python as `uf(*args)` (numpy arrays element-wise: the reference path
    and outputs). `name`: how expressions call it; `fn`: what the user gave."""

    def __init__(self, name: str, fn, nargs: int | None = None, entity: str | None = None):
        entity = entity or f"function '{name}'"
        if not is_numba(fn):
            what = "a plain Python callable" if callable(fn) else f"a {type(fn).__name__}"
            raise ModelError(entity, "function", f"{what} cannot run inside the compiled kernels: decorate it "
                             "with @numba.njit, or give a numba.cfunc of float64 arguments returning float64")
        n = _arity(fn, entity)
        if nargs is not None and n != nargs:
            raise ModelError(entity, "function", f"takes {n} argument(s), expected {nargs}")
        if not 1 <= n <= MAX_ARGS:
            raise ModelError(entity, "function", f"takes {n} arguments: a compiled user function takes 1 to "
                             f"{MAX_ARGS} float arguments")
        self.name, self.fn, self.nargs, self.entity = name, fn, n, entity
        self._cf = _cfunc(fn, n, entity)
        self.address = int(self._cf.address)
        _BY_ADDRESS[self.address] = self

    def __call__(self, *args, order=0):
        if order:
            raise EvaluationError(self.entity, "order", "a user function has no derivatives")
        call = self._cf.ctypes
        if any(np.ndim(a) for a in args):
            return np.vectorize(lambda *xs: call(*map(float, xs)), otypes=[float])(*args)
        return call(*map(float, args))

    def __reduce__(self):          # (a copy or pickle makes the cfunc again: once per function in a process)
        return user_function, (self.fn, self.name, self.nargs, self.entity)

    def __repr__(self) -> str:
        return f"UserFunction({self.name!r}, {self.nargs} argument(s))"


def _cfunc(fn, nargs, entity):
    """A numba.cfunc float64(float64 x nargs) of `fn` (a cfunc checked and returned as given)."""
    from numba import types
    if _is_cfunc(fn):
        sig = fn._sig
        if sig.return_type != types.float64 or any(a != types.float64 for a in sig.args):
            raise ModelError(entity, "function", f"a numba.cfunc of signature {sig}: a compiled user function "
                             "takes float64 arguments and returns float64")
        return fn
    from numba import cfunc
    names = ", ".join(f"x{k}" for k in range(nargs))
    ns = {"_f": fn}
    exec(f"def _wrapped({names}):\n    return _f({names})\n", ns)   # noqa: S102 - a fixed template, no user text
    try:
        return cfunc(types.float64(*([types.float64] * nargs)))(ns["_wrapped"])
    except Exception as exc:  # noqa: BLE001 - numba's typing errors: reported with the function's name
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ModelError(entity, "function", f"numba cannot compile it as float64({', '.join(['float64'] * nargs)})"
                         f" -> float64: {first}") from None


def user_function(fn, name: str | None = None, nargs: int | None = None, entity: str | None = None) -> UserFunction:
    """The UserFunction of a numba function (made once per function and arity)."""
    name = name or getattr(fn, "__name__", None) or getattr(getattr(fn, "_pyfunc", None), "__name__", "function")
    key = (id(fn), nargs, name)
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is fn:
        return hit[1]
    uf = UserFunction(name, fn, nargs, entity)
    _CACHE[key] = (fn, uf)
    return uf


# ----------------------------------------------------------------------------- drivers of t
def _call(uf, t_node):
    from ._exprtree import Call
    return Call(uf.name, (t_node,), 0, uf)


def _shifted(k):
    from ._exprtree import Const, Var, add
    return add(Var("t"), Const(k * H_STEP)) if k else Var("t")


def _stencil(uf, order):
    """The expression tree of the 8th-order central difference of order 1 or 2 of uf at t (step H_STEP)."""
    from ._exprtree import Const, add, mul, sub
    w = _D1_8 if order == 1 else _D2_8
    node = mul(Const(_D2_8_C0), _call(uf, _shifted(0))) if order == 2 else None
    for k in range(1, 5):
        a, b = _call(uf, _shifted(k)), _call(uf, _shifted(-k))
        term = mul(Const(w[k - 1]), sub(a, b) if order == 1 else add(a, b))
        node = term if node is None else add(node, term)
    return mul(node, Const(1.0 / H_STEP ** order))


def time_programs(tf):
    """(value, d1, d2) exprvm programs of a TimeFunction whose function is a numba.njit / numba.cfunc of t
    (its derivatives: numba functions when given as such, else the central differences of the module
    docstring), or None when it is not one."""
    from .system.exprvm import compile_expr
    from .timefunctions import _NumericDerivative
    f = tf.f
    if not is_numba(f):
        return None
    uf = user_function(f, nargs=1, entity=f"driver function {getattr(f, '__name__', '')}".strip())
    nodes = [_call(uf, _shifted(0))]
    for order, g in ((1, tf.f_d1), (2, tf.f_d2)):
        if is_numba(g):
            nodes.append(_call(user_function(g, nargs=1), _shifted(0)))
        elif isinstance(g, _NumericDerivative) and g.f is f and g.order == order:
            nodes.append(_stencil(uf, order))
        elif order == 2 and isinstance(g, _NumericDerivative) and is_numba(g.f) and g.order == 1:
            nodes.append(_stencil(user_function(g.f, nargs=1), 1))   # d2 as the difference of an njit d1
        else:
            return None   # a Python derivative: the driver callback (solvers.pyloads)
    return tuple(compile_expr(n, {"t": 0}) for n in nodes)


# ----------------------------------------------------------------------------- failures of a run
def program_sets(cm) -> list:
    """(code, consts) of every packed program set of a CompiledModel (drivers, expression loads and sensors,
    tree and loop coordinate constraints, point-on-curve)."""
    out = [(cm.code, cm.consts)]
    for arrs, c in ((cm.exprloads, 13), (cm.coords, 5), (cm.loop_coords, 3), (cm.paths, 8)):
        if arrs and len(arrs) > c + 1:
            out.append((arrs[c], arrs[c + 1]))
    return out


def sites(cm) -> list:
    """(consts, counter index, address) of every user-function call in the compiled model's programs."""
    from .system.exprvm import USER
    out = []
    for code, consts in program_sets(cm):
        if len(code) == 0:
            continue
        for pc in np.flatnonzero(code[:, 0] == USER):
            out.append((consts, int(code[pc, 1]) // 8, int(consts[code[pc - 1, 1]])))
    return out


def reset(user_sites) -> None:
    """Zero the non-finite counters (at the start of a run)."""
    for consts, k, _ in user_sites:
        consts[k] = 0.0


def failures(user_sites, model=None) -> EvaluationError | None:
    """The EvaluationError of the first user function that returned a non-finite value in the run (named
    with the elements of `model` that call it), or None."""
    for consts, k, address in user_sites:
        if consts[k] != 0.0:
            uf = _BY_ADDRESS.get(address)
            if uf is None or getattr(uf, "sensor", None) is not None:
                continue     # a sensor's callback: it keeps its own error (solvers.pyloads)
            users = callers(model, uf) if model is not None else []
            where = f" (called by {', '.join(users)})" if users else ""
            return EvaluationError(f"function '{uf.name}'{where}", "value",
                                   f"returned a non-finite value ({int(consts[k])} call(s))")
    return None


def callers(model, uf) -> list[str]:
    """The model's entities whose expressions or driver functions call `uf` ("load 'x'", "motion 'm'")."""
    from ._exprtree import Bin, Call, Fn, Neg
    from .model.loadexpr import LoadExpr

    def calls(node) -> bool:
        if isinstance(node, Call):
            return node.table is uf or any(calls(a) for a in node.args)
        if isinstance(node, Bin):
            return calls(node.a) or calls(node.b)
        if isinstance(node, (Neg,)):
            return calls(node.a)
        if isinstance(node, Fn):
            return any(calls(a) for a in node.args)
        return False

    def reads(v) -> bool:
        if isinstance(v, LoadExpr):
            return calls(getattr(v.expr, "node", v.expr))
        return any(reads(c) for c in getattr(v, "components", ()))

    out = []
    for e in getattr(model, "forces", {}).values():
        vals = [getattr(e, a, None) for a in ("force", "torque", "magnitude", "value")]
        if any(reads(v) for v in vals if v is not None):
            out.append(f"load '{e.name}'")
    for m in getattr(model, "motions", {}).values():
        fn = getattr(m, "function", None) or getattr(m, "fn", None)
        if fn is not None and uf.fn in (getattr(fn, "f", None), getattr(fn, "f_d1", None), getattr(fn, "f_d2", None)):
            out.append(f"motion '{m.name}'")
    for s in getattr(model, "sensors", {}).values():
        if s.text is not None and uf.name in s.text:
            out.append(f"sensor '{s.name}'")
    return out


"""Run-time guards around user functions: a failure names the element, the field and the time.

Drivers (TimeFunction value/d1/d2), applied forces and torques given as callables are called through
`guarded_time_function` / `call_vector`: an exception raised by the user's code, a value that is not a
number (None, a string) or a non-finite one becomes an `EvaluationError(entity, field, message, time)`;
the analysis loops turn that into `Result.success = False` keeping every step before it.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import EvaluationError, MbdsimError


def _time(t):
    try:
        return float(np.ravel(np.asarray(t, dtype=float))[0])
    except (TypeError, ValueError, IndexError):
        return None


def as_numbers(v) -> np.ndarray:
    """A user function's result as a float array; TypeError for text or booleans (which np.asarray would
    read as numbers: "1" -> 1.0, True -> 1.0), ValueError for what is not numbers at all."""
    from ..model._check import not_a_number
    bad = not_a_number(v)
    if bad:
        raise TypeError(f"{v!r} holds {bad}")
    return np.asarray(v, dtype=float)


class GuardedTimeFunction:
    """A TimeFunction whose evaluations are checked (finite numbers) and whose failures are named.
    Other attributes (expr, f, f_d1, f_d2, description) are the wrapped function's."""

    def __init__(self, tf, entity: str, field: str):
        self._tf, self._entity, self._field = tf, entity, field

    def __getattr__(self, name):
        return getattr(self._tf, name)

    def _call(self, fn, what, t):
        try:
            y = fn(t)
        except MbdsimError:
            raise
        except Exception as exc:  # noqa: BLE001 - user code: named, with the time
            raise EvaluationError(self._entity, self._field, f"{what} raised {type(exc).__name__}: {exc}",
                                  time=_time(t)) from exc
        try:
            finite = bool(np.all(np.isfinite(as_numbers(y))))
        except (TypeError, ValueError):
            raise EvaluationError(self._entity, self._field, f"{what} returned {y!r}, not a number",
                                  time=_time(t)) from None
        if not finite:
            raise EvaluationError(self._entity, self._field, f"{what} is not finite ({y!r})", time=_time(t))
        return y

    def value(self, t):
        return self._call(self._tf.value, "the function", t)

    def d1(self, t):
        return self._call(self._tf.d1, "its first derivative", t)

    def d2(self, t):
        return self._call(self._tf.d2, "its second derivative", t)

    __call__ = value

    def __repr__(self):
        return repr(self._tf)


def guarded_time_function(tf, entity: str, field: str):
    """tf wrapped by GuardedTimeFunction (once)."""
    return tf if isinstance(tf, GuardedTimeFunction) else GuardedTimeFunction(tf, entity, field)


def call_vector(fn, t, state, entity: str, field: str) -> np.ndarray:
    """fn(t, state) as a finite 3-vector, else EvaluationError naming entity, field and t [s]."""
    try:
        v = fn(t, state)
    except MbdsimError:
        raise
    except Exception as exc:  # noqa: BLE001 - user code
        raise EvaluationError(entity, field, f"callable raised {type(exc).__name__}: {exc}", time=_time(t)) from exc
    if type(v) in (tuple, list) and len(v) == 3:   # the usual answer, checked at a tenth of the cost
        x, y, z = v
        if (isinstance(x, float) or type(x) is int) and (isinstance(y, float) or type(y) is int) and \
                (isinstance(z, float) or type(z) is int) and math.isfinite(x + y + z):
            return np.array(v, dtype=float)
    try:
        a = as_numbers(v).reshape(-1)
    except (TypeError, ValueError):
        raise EvaluationError(entity, field, f"callable returned {v!r}; expected 3 finite numbers",
                              time=_time(t)) from None
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise EvaluationError(entity, field, f"callable returned {v!r}; expected 3 finite numbers", time=_time(t))
    return a

"""Input checks that name the offending entity and field."""
from __future__ import annotations

import inspect
import math

import numpy as np

from ..errors import ModelError


_NUMBERS = (float, int, np.float64)   # exact types, never booleans (bool is a subclass of int)


def _has_bool(value) -> bool:
    """True when value is a boolean or a (nested) sequence holding one: True is not the number 1 here."""
    if type(value) in _NUMBERS:
        return False
    if isinstance(value, (list, tuple)) and all(type(x) in _NUMBERS for x in value):
        return False   # a flat sequence of numbers (the common case)
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype == bool or (value.dtype == object and any(_has_bool(x) for x in value.ravel()))
    return isinstance(value, (list, tuple)) and any(_has_bool(x) for x in value)


def not_a_number(value) -> str | None:
    """Why `value` (a number or a sequence of them, as given to the Python API) is not one that float()
    should read: "a boolean" or "text" (float("2") and float(True) would succeed), else None."""
    if type(value) in _NUMBERS:
        return None
    if _has_bool(value):
        return "a boolean"
    if isinstance(value, np.ndarray):
        items = value.ravel() if value.dtype.kind == "O" else ()
        if value.dtype.kind in "US":
            return "text"
    else:
        items = value if isinstance(value, (list, tuple)) else ()
    if isinstance(value, (str, bytes)) or any(not_a_number(x) == "text" for x in items):
        return "text"
    return None


def _plain(x) -> bool:
    """A finite float, or an int that a float holds exactly (no booleans, no overflow)."""
    return (type(x) is float and math.isfinite(x)) or (type(x) is int and -2**53 <= x <= 2**53)


def vector(entity: str, field: str, value, n: int = 3, what: str = "") -> np.ndarray:
    """A finite n-vector, else ModelError (`what` names the components in the message)."""
    if type(value) in (tuple, list) and len(value) == n and all(_plain(x) for x in value):
        return np.array(value, dtype=float)   # the common case: n plain finite numbers
    bad = not_a_number(value)
    if bad:
        raise ModelError(entity, field, f"expected {n} numbers, got {bad} in {value!r}")
    try:
        v = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(entity, field, f"expected {n} numbers, got {value!r}") from None
    if v.shape != (n,):
        raise ModelError(entity, field, f"expected {n} numbers{what}, got {value!r}")
    if not np.isfinite(v).all():
        raise ModelError(entity, field, f"values must be finite, got {value!r}")
    return v


def vec3(entity: str, field: str, value, unit: bool = False) -> np.ndarray:
    """A finite 3-vector (a unit vector when unit=True), else ModelError."""
    v = vector(entity, field, value, 3)
    if unit:
        n = math.sqrt(v.dot(v))   # as np.linalg.norm of a vector
        if n < 1e-12:
            raise ModelError(entity, field, "direction vector must be non-zero")
        v = v / n
    return v


def scalar(entity: str, field: str, value, minimum: float | None = None, strict: bool = False) -> float:
    """A finite float, optionally bounded below, else ModelError (a boolean is not a number)."""
    if _has_bool(value):
        raise ModelError(entity, field, f"expected a number, got the boolean {value!r}")
    if isinstance(value, (str, bytes)):
        raise ModelError(entity, field, f"expected a number, got the text {value!r} (the Python API takes "
                         "numbers in SI units; unit strings such as '2 kg' belong in model files)")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(entity, field, f"expected a number, got {value!r}") from None
    if not math.isfinite(x):
        raise ModelError(entity, field, f"must be finite, got {value!r}")
    if minimum is not None and (x < minimum or (strict and x == minimum)):
        rel = ">" if strict else ">="
        raise ModelError(entity, field, f"must be {rel} {minimum}, got {x!r}")
    return x


class InertiaWarning(UserWarning):
    """Principal moments that no mass distribution has (the triangle inequality I1 + I2 >= I3 fails)."""


def inertia_matrix(entity: str, value, strict: bool = True) -> np.ndarray:
    """Inertia about the centre of mass in body axes: (ixx, iyy, izz) or a symmetric 3x3 [kg m^2].

    Checked: finite, symmetric, positive semi-definite (a slender rod may have a zero axial moment)
    and the triangle inequality of the principal moments (I1 + I2 >= I3, relative tolerance 1e-6),
    which every real mass distribution satisfies: a violation is a ModelError (strict=False, for
    callers that knowingly model such values, only warns with InertiaWarning)."""
    bad = not_a_number(value)
    if bad:
        raise ModelError(entity, "inertia", f"expected 3 numbers or a 3x3 matrix, got {bad} in {value!r}")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(entity, "inertia", f"expected 3 numbers or a 3x3 matrix, got {value!r}") from None
    J = np.diag(a) if a.shape == (3,) else a
    if J.shape != (3, 3) or not np.isfinite(J).all():
        raise ModelError(entity, "inertia", f"expected 3 numbers or a 3x3 matrix, got {value!r}")
    big = float(np.abs(J).max())
    if a.shape == (3,) and (big == 0.0 or 1e-100 < big < 1e100):
        ev = np.sort(a)   # a diagonal matrix: symmetric, and LAPACK's eigenvalues are its entries exactly
    else:   # np.allclose(J, J.T, atol=1e-12 * max(1, |J|max)) written out (J is finite)
        if not (np.abs(J - J.T) <= 1e-12 * max(1.0, big) + 1e-5 * np.abs(J.T)).all():
            raise ModelError(entity, "inertia", "matrix must be symmetric")
        ev = np.linalg.eigvalsh(J)
    if ev.min() < -1e-12 * max(1.0, ev.max()):
        raise ModelError(entity, "inertia", f"must be positive semi-definite, eigenvalues {ev}")
    if ev[0] + ev[1] < ev[2] - 1e-6 * ev[2]:
        err = ModelError(entity, "inertia", f"principal moments {ev[0]:.6g}, {ev[1]:.6g}, {ev[2]:.6g} kg m^2 "
                         "violate the triangle inequality (I1 + I2 >= I3): no mass distribution has them")
        if strict:
            raise err
        from .._userwarn import warn
        warn(str(err), InertiaWarning)
    return J


def check_load_callable(entity: str, field: str, fn) -> None:
    """ModelError unless fn can be called as fn(t, state) (checked at add time, without calling it)."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return   # builtins without a signature: checked at run time
    try:
        sig.bind(0.0, None)
    except TypeError:
        raise ModelError(entity, field, f"a callable load is called as f(t, state) -> 3 numbers; "
                         f"{getattr(fn, '__name__', fn)!r}{sig} cannot take (t, state)") from None


def check_time_callable(entity: str, field: str, fn) -> None:
    """ModelError unless fn can be called as fn(t)."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return
    try:
        sig.bind(0.0)
    except TypeError:
        raise ModelError(entity, field, f"a driver callable is called as f(t) -> number; "
                         f"{getattr(fn, '__name__', fn)!r}{sig} cannot take (t)") from None

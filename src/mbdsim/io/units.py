"""Quantities with units at the edge of mbdsim: strings such as "500 mm", "60 deg/s", "3 kN/m" -> SI floats.

One pint ``UnitRegistry`` is created on first use (pint is imported only when a string needs it).  A
bare number is taken as SI already.  Every conversion checks the dimension against the field's SI
unit, so "2 kg" for a length is an error naming the field.  Angles are dimensionless in pint:
"30 deg" converts to 0.5236 rad, a bare number is in radians.

pint evaluates the arithmetic of a string ("2*3 kg", "m**2") in Python numbers, and integer powers are
exact and unbounded ("9**9**9 kg" would run for ever, "2**10000 kg" overflows on conversion): every
integer literal is handed to pint as a float (`bounded`), so any arithmetic is double precision and a
result out of range is a UnitError at once; strings are at most MAX_CHARS characters.
"""
from __future__ import annotations

import math
import numbers
import re
from functools import lru_cache

__all__ = ["UnitError", "registry", "to_si", "dimension_name", "bounded"]

MAX_CHARS = 200   # characters of a quantity string, at most
_INTEGER = re.compile(r"(?<![\w.])(\d+)(?![\w.])")   # an integer literal (not part of 1.5, 1e3, m2, 0x1)

# SI units of the fields of a model file and the words used for them in messages.
DIMENSION_NAMES = {
    "m": "a length", "kg": "a mass", "kg*m**2": "an inertia", "rad": "an angle", "m/s": "a velocity",
    "rad/s": "an angular velocity", "m/s**2": "an acceleration", "N": "a force", "N*m": "a torque",
    "N/m": "a stiffness", "N*s/m": "a damping", "N*m/rad": "a rotational stiffness",
    "N*m*s/rad": "a rotational damping", "kg/m**3": "a density", "s": "a time", "": "a pure number",
    "rad/s**2": "an angular acceleration",
}


class UnitError(ValueError):
    """A value that is not a number or a quantity of the expected dimension (message names the value)."""


@lru_cache(maxsize=1)
def registry():
    """The one pint UnitRegistry of mbdsim (created lazily; 'rpm' is revolutions per minute)."""
    import pint
    try:    # pint's parsed definitions cached on disk (~/.cache/pint): about 10x faster after the first time
        return pint.UnitRegistry(autoconvert_offset_to_baseunit=True, cache_folder=":auto:")
    except Exception:  # noqa: BLE001 - no writable cache (or an older pint): parse the definitions
        return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def bounded(text: str) -> str:
    """`text` with every integer literal written as a float ("9**9**9 kg" -> "9.0**9.0**9.0 kg"), so that
    pint's evaluation is bounded: floats overflow (an error) where integer powers would grow for ever."""
    return _INTEGER.sub(r"\1.0", text)


def dimension_name(unit: str) -> str:
    """'a length [m]' for unit 'm' (used in error messages)."""
    what = DIMENSION_NAMES.get(unit, "a quantity")
    return f"{what} [{unit}]" if unit else what


@lru_cache(maxsize=256)
def _convert(text: str, unit: str) -> float:
    ureg = registry()
    import pint
    try:
        q = ureg.Quantity(bounded(text))
    except OverflowError:
        raise UnitError(f"{text!r} is out of the range of double precision numbers") from None
    except Exception as exc:  # noqa: BLE001 - pint's own parser (never eval) fails in many ways on garbage
        detail = f": {exc}" if str(exc) else ""
        raise UnitError(f"cannot read {text!r} as a number with units{detail}") from None
    if not isinstance(q, ureg.Quantity):   # a plain number written as a string
        q = ureg.Quantity(float(q))
    target = ureg.Quantity(1.0, unit) if unit else ureg.Quantity(1.0)
    if q.dimensionality != target.dimensionality:
        got = "dimensionless" if q.dimensionless else str(q.dimensionality)
        raise UnitError(f"{text!r} is not {dimension_name(unit)}: its dimension is {got}")
    try:
        x = float(q.to(target.units).magnitude)
    except OverflowError:
        raise UnitError(f"{text!r} is out of the range of double precision numbers") from None
    except pint.errors.PintError as exc:
        raise UnitError(f"cannot convert {text!r} to {unit or 'a pure number'}: {exc}") from None
    if not math.isfinite(x):
        raise UnitError(f"{text!r} is not finite")
    return x


def to_si(value, unit: str) -> float:
    """A number (taken as SI) or a string with units -> float in `unit` (an SI unit such as "m", "N*m/rad").

    Raises UnitError for booleans, non-numbers, non-finite values and wrong dimensions."""
    if isinstance(value, bool):
        raise UnitError(f"expected {dimension_name(unit)}, got the boolean {value!r}")
    if isinstance(value, numbers.Real):
        x = float(value)
        if not math.isfinite(x):
            raise UnitError(f"must be finite, got {value!r}")
        return x
    if isinstance(value, str):
        if len(value) > MAX_CHARS:
            raise UnitError(f"a quantity string is at most {MAX_CHARS} characters, got {len(value)}")
        try:
            x = float(value)   # a bare number written as a string is SI too
        except ValueError:
            return _convert(value.strip(), unit)
        return to_si(x, unit)
    raise UnitError(f"expected {dimension_name(unit)} (a number in SI or a string with units), got {value!r}")

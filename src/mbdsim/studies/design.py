"""Parameter specifications and the design of a study: the table of variants (one row per run, SI values).

A parameter is given as
    [v1, v2, ...] or {"values": [...]}                 discrete values (a grid axis)
    {"range": [low, high], "num": k}                   k evenly spaced values (grid) or, without num or
                                                       with a sampling method, the bounds of a uniform sample
    {"distribution": "normal", "mean": m, "std": s}    Monte Carlo; also "uniform" (low, high) and
                                                       "lognormal" (median, sigma: std of the log)
    a scipy.stats frozen distribution                  Monte Carlo (SI values)
    a number or a string with units                    a constant
Any number may be a string with units ("200 mm", "60 rpm", "3 kN/m"), or take the spec's "unit" (e.g.
{"range": [150, 250], "unit": "mm"}); values are converted to SI (angles in rad, rates in rad/s).
Strings that are not a number followed by units (expressions such as "2*pi*t") are kept as they are.

Sampling: "grid" (full factorial of the discrete values and ranges with num), or "lhs" / "sobol"
(scipy.stats.qmc) / "random" (Monte Carlo) for `samples` points of the continuous parameters (ranges
and distributions, mapped from the unit cube through each marginal's inverse CDF), crossed with the
discrete values.  The design is deterministic for a given seed.
"""
from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import ModelError

__all__ = ["ParameterSpec", "parse_parameter", "make_design", "to_si_value", "SAMPLING_METHODS"]

SAMPLING_METHODS = ("grid", "lhs", "sobol", "random")
MAX_VARIANTS = 1_000_000   # variants a study may have (refused above, before any is generated: a design
#                            of 10**9 rows would take tens of GB before the first run)
DISTRIBUTIONS = {"normal": ("mean", "std"), "uniform": ("low", "high"), "lognormal": ("median", "sigma")}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter: discrete `values`, a continuous `dist` (scipy frozen distribution), or both None
    with `bounds` (a uniform range) when no grid count is given.  Values are SI."""

    name: str
    values: tuple | None = None
    dist: object | None = None
    describe: str = ""

    @property
    def continuous(self) -> bool:
        return self.dist is not None


def _entity(name: str) -> str:
    return f"study parameter '{name}'"


def to_si_value(value, name: str, unit: str | None = None):
    """A number or a quantity string -> SI float; other strings (expressions) are returned unchanged.

    `unit` applies to bare numbers ("mm": 150 -> 0.15).  Raises ModelError naming the parameter."""
    if isinstance(value, bool):
        raise ModelError(_entity(name), "values", f"expected a number or a quantity, got {value!r}")
    from ..io.units import bounded, registry
    if isinstance(value, (int, float, np.integer, np.floating)):
        if unit is None:
            return float(value)
        value = f"{value} {unit}"
    if not isinstance(value, str):
        raise ModelError(_entity(name), "values", f"expected a number or a quantity, got {value!r}")
    m = _QUANTITY.match(value)
    if m is None:
        return value          # an expression string, e.g. a motion "2*pi*t"
    ureg = registry()
    rest = m.group(2)
    try:   # bounded: integer powers in the units ("kg**9**9**9") evaluated as floats, an error at once
        units = ureg.parse_units(bounded(rest)) if rest else ureg.dimensionless
    except OverflowError:
        raise ModelError(_entity(name), "values", f"{value!r} is out of the range of double precision "
                         "numbers") from None
    except Exception:  # noqa: BLE001 - pint fails in many ways: the string is not a quantity
        return value
    return float(ureg.Quantity(float(m.group(1)), units).to_base_units().magnitude)


def _number(value, name, unit, field):
    x = to_si_value(value, name, unit)
    if not isinstance(x, float) or not np.isfinite(x):
        raise ModelError(_entity(name), field, f"expected a finite number or quantity, got {value!r}")
    return x


def _dist_from_dict(name, spec, unit):
    from scipy import stats
    kind = spec["distribution"]
    if kind not in DISTRIBUTIONS:
        raise ModelError(_entity(name), "distribution", f"unknown distribution {kind!r}; choose from "
                         f"{', '.join(DISTRIBUTIONS)}")
    need = DISTRIBUTIONS[kind]
    missing = [k for k in need if k not in spec]
    if missing:
        raise ModelError(_entity(name), missing[0], f"a {kind} distribution needs {' and '.join(need)}")
    a = _number(spec[need[0]], name, unit, need[0])
    b = _number(spec[need[1]], name, None if kind == "lognormal" else unit, need[1])
    if kind == "uniform":
        if not b > a:
            raise ModelError(_entity(name), "high", f"must exceed low ({b!r} <= {a!r})")
        return stats.uniform(a, b - a), f"uniform({a:g}, {b:g})"
    if not b > 0:
        raise ModelError(_entity(name), need[1], f"must be positive, got {b!r}")
    if kind == "normal":
        return stats.norm(a, b), f"normal(mean={a:g}, std={b:g})"
    if not a > 0:
        raise ModelError(_entity(name), "median", f"must be positive, got {a!r}")
    return stats.lognorm(b, scale=a), f"lognormal(median={a:g}, sigma={b:g})"


def _from_dict(name, spec: dict) -> ParameterSpec:
    unit = spec.get("unit")
    kinds = [k for k in ("values", "range", "distribution") if k in spec]
    if len(kinds) != 1:
        raise ModelError(_entity(name), "(spec)", "give exactly one of 'values', 'range', 'distribution'")
    allowed = {"values": {"values", "unit"}, "range": {"range", "num", "unit"},
               "distribution": {"distribution", "unit", *DISTRIBUTIONS.get(spec.get("distribution"), ())}}[kinds[0]]
    extra = sorted(set(spec) - allowed)
    if extra:
        raise ModelError(_entity(name), extra[0], f"unknown field; valid fields: {', '.join(sorted(allowed))}")
    if "values" in spec:
        vals = spec["values"]
        if isinstance(vals, (str, bytes)) or not hasattr(vals, "__len__") or len(vals) == 0:
            raise ModelError(_entity(name), "values", f"expected a non-empty list, got {vals!r}")
        return ParameterSpec(name, values=tuple(to_si_value(v, name, unit) for v in vals))
    if "range" in spec:
        rng = spec["range"]
        if isinstance(rng, str) or len(rng) != 2:
            raise ModelError(_entity(name), "range", f"expected [low, high], got {rng!r}")
        lo, hi = (_number(v, name, unit, "range") for v in rng)
        if not hi > lo:
            raise ModelError(_entity(name), "range", f"high must exceed low, got {rng!r}")
        num = spec.get("num")
        from scipy import stats
        dist = stats.uniform(lo, hi - lo)
        if num is None:
            return ParameterSpec(name, dist=dist, describe=f"range({lo:g}, {hi:g})")
        if not isinstance(num, int) or isinstance(num, bool) or num < 1:
            raise ModelError(_entity(name), "num", f"expected a positive integer, got {num!r}")
        return ParameterSpec(name, values=tuple(np.linspace(lo, hi, num).tolist()), dist=dist,
                             describe=f"range({lo:g}, {hi:g})")
    dist, text = _dist_from_dict(name, spec, unit)
    return ParameterSpec(name, dist=dist, describe=text)


def quantity_texts(spec) -> list[str]:
    """The values of a parameter spec as written with their units ("2 m", or "1 <unit>" for a spec with a
    'unit'), for checking their dimension against the field a parameter path sets (Study): [] for
    plain numbers, expressions and distributions given as objects."""
    if isinstance(spec, dict):
        if isinstance(spec.get("unit"), str):
            return [f"1 {spec['unit']}"]
        spec = list(spec.get("values", ())) + list(spec.get("range", ()) if not isinstance(spec.get("range"), str) else ())
    items = list(spec) if isinstance(spec, (list, tuple)) else [spec]
    out = []
    for v in items:
        if isinstance(v, str):
            m = _QUANTITY.match(v)
            if m is not None and m.group(2) and v not in out:
                out.append(v)
    return out


def parse_parameter(name: str, spec) -> ParameterSpec:
    """ParameterSpec from the forms listed in the module docstring; raises ModelError naming it."""
    if not isinstance(name, str) or not name:
        raise ModelError("study", "parameters", f"parameter names are non-empty strings, got {name!r}")
    if isinstance(spec, ParameterSpec):
        return spec
    if isinstance(spec, dict):
        return _from_dict(name, spec)
    if hasattr(spec, "ppf") and hasattr(spec, "rvs"):
        return ParameterSpec(name, dist=spec, describe=str(getattr(spec.dist, "name", "distribution")))
    if isinstance(spec, (list, tuple, np.ndarray, pd.Series, range)):
        return _from_dict(name, {"values": list(spec)})
    return ParameterSpec(name, values=(to_si_value(spec, name),))


def _unit_cube(method: str, n: int, d: int, seed: int) -> np.ndarray:
    from scipy.stats import qmc
    if method == "random":
        return np.random.default_rng(seed).random((n, d))
    engine = qmc.Sobol if method == "sobol" else qmc.LatinHypercube
    try:
        sampler = engine(d, rng=np.random.default_rng(seed))
    except TypeError:   # scipy < 1.15
        sampler = engine(d, seed=seed)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)   # Sobol balance note for n not a power of two
        return sampler.random(n)


def make_design(params: list[ParameterSpec], sampling: str | None = None, samples: int | None = None,
                seed: int = 0) -> pd.DataFrame:
    """The variants: a DataFrame with one column per parameter (SI values), index 'run' = 0..n-1.

    Grid: the full factorial of every parameter's values (order: the first parameter varies slowest).
    lhs/sobol/random: `samples` points of the continuous parameters, crossed with the discrete ones."""
    if not params:
        raise ModelError("study", "parameters", "give at least one parameter")
    if sampling is None:
        sampling = "grid" if all(p.values is not None for p in params) else "lhs"
    if sampling not in SAMPLING_METHODS:
        raise ModelError("study", "sampling", f"unknown method {sampling!r}; choose from {', '.join(SAMPLING_METHODS)}")
    if sampling == "grid":
        bad = [p.name for p in params if p.values is None]
        if bad:
            raise ModelError(_entity(bad[0]), "values", "a grid needs discrete values (or a range with num); "
                             "use sampling 'lhs', 'sobol' or 'random' for ranges and distributions")
        _check_size("values", [len(p.values) for p in params], params)
        rows = list(itertools.product(*(p.values for p in params)))
        return _frame(rows, [p.name for p in params])
    cont = [p for p in params if p.dist is not None]
    disc = [p for p in params if p.dist is None]
    if not cont:
        raise ModelError("study", "sampling", f"'{sampling}' samples ranges or distributions; every parameter "
                         "here has discrete values: use sampling 'grid'")
    if not isinstance(samples, int) or isinstance(samples, bool) or samples < 1:
        raise ModelError("study", "samples", f"sampling '{sampling}' needs a positive number of samples, got {samples!r}")
    _check_size("samples", [len(p.values) for p in disc] + [samples], params)
    u = _unit_cube(sampling, samples, len(cont), seed)
    cols = [np.asarray(p.dist.ppf(u[:, k]), dtype=float) for k, p in enumerate(cont)]
    sampled = list(zip(*cols))
    rows = [d + s for d in itertools.product(*(p.values for p in disc)) for s in sampled]
    return _frame(rows, [p.name for p in disc] + [p.name for p in cont])[[p.name for p in params]]


def _check_size(field: str, counts: list, params) -> None:
    """ModelError naming the study's `field` when the design would have more than MAX_VARIANTS rows."""
    n = 1
    for c in counts:
        n *= int(c)
    if n > MAX_VARIANTS:
        what = " x ".join(str(int(c)) for c in counts)
        raise ModelError("study", field, f"the design has {n:.3g} variants ({what} over "
                         f"{', '.join(p.name for p in params)}), more than the {MAX_VARIANTS:,} a study runs "
                         "(mbdsim.studies.design.MAX_VARIANTS): use fewer values or samples, or split the study")


def _frame(rows, names) -> pd.DataFrame:
    df = pd.DataFrame(rows, columns=names)
    df.index = pd.RangeIndex(len(df), name="run")
    return df

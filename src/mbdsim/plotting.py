"""Time-history plots of a Result (or of its exported DataFrame) with matplotlib.

`plot(res, signal, x=None, ax=None, **kw)` draws curves against time [s], or against another signal
given as `x`, with axis labels carrying SI units (signals of different units on separate y axes), and
marks the run's events with vertical lines.
A signal is one of:

* a callable of the Result, e.g. ``lambda r: r.joint_coordinate("pin")``: when it returns a Result
  measure unchanged, the label and unit are taken from that measure ("pin angle [rad]");
* a column name of ``res.to_dataframe()`` ("pin.angle [rad]"), matched leniently: exactly, then
  case-insensitively ignoring the unit suffix, then by a unique case-insensitive prefix;
* a pair ``("label [unit]", callable)`` to name a computed signal yourself.

matplotlib is imported only when a plot is drawn (Agg backend when none was chosen).
"""
from __future__ import annotations

import re
import weakref
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from .errors import ModelError
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ._types import Signal as SignalSpec
    import pandas as pd
    from matplotlib.axes import Axes
    from .results.result import Result

TIME_COLUMN = "time [s]"
_UNIT_RE = re.compile(r"^(.*?)\s*\[([^\]]*)\]\s*$")

# Result measures: (label suffix, unit) for single-call signals; joint coordinates depend on the joint kind
_MEASURE_UNITS = {
    "position": ("position", "m"), "velocity": ("velocity", "m/s"), "acceleration": ("acceleration", "m/s^2"),
    "angular_velocity": ("angular velocity", "rad/s"),
    "angular_acceleration": ("angular acceleration", "rad/s^2"),
    "reaction_force": ("reaction force", "N"), "reaction_torque": ("reaction torque", "N m"),
    "kinetic_energy": ("kinetic energy", "J"), "potential_energy": ("potential energy", "J"),
    "dissipated_energy": ("dissipated energy", "J"),
}
_JOINT_UNITS = {  # joint kind -> (coordinate unit, component names or None for a scalar)
    "revolute": ("rad", None), "translational": ("m", None), "cylindrical": (None, ("angle", "slide")),
    "spherical": ("rad", ("rx", "ry", "rz")), "universal": ("rad", ("rx", "ry", "rz")),
    "fixed": ("rad", ("rx", "ry", "rz")), "planar": (None, ("u", "v", "angle")),
}


@dataclass
class Signal:
    """A resolved signal: `values` (N,) or (N, k), a label without unit and its unit ('' if unknown)."""

    label: str
    unit: str
    values: np.ndarray
    components: tuple[str, ...] | None = None

    @property
    def title(self) -> str:
        """'label [unit]' (or just the label when the unit is unknown)."""
        return f"{self.label} [{self.unit}]" if self.unit else self.label


def split_unit(name: str) -> tuple[str, str]:
    """'pin.angle [rad]' -> ('pin.angle', 'rad'); a name without brackets has unit ''."""
    m = _UNIT_RE.match(str(name))
    return (m.group(1), m.group(2)) if m else (str(name), "")


MAX_LISTED = 10    # columns named in an error message, at most


def match_column(columns: Sequence[str], name: str) -> str:
    """The column of `columns` that `name` designates: exact, then case-insensitive ignoring the unit
    suffix, then a unique case-insensitive prefix of the unit-less name.  Raises ModelError naming the
    columns when nothing (or more than one column) matches: all of them when there are at most
    MAX_LISTED, else the MAX_LISTED closest (`closest_columns`)."""
    cols = [str(c) for c in columns]
    if name in cols:
        return name
    key = split_unit(name)[0].strip().lower()
    bases = {c: split_unit(c)[0].strip().lower() for c in cols}
    exact = [c for c in cols if bases[c] == key]
    if len(exact) == 1:
        return exact[0]
    pref = [c for c in cols if bases[c].startswith(key)] if key else []
    if len(pref) == 1:
        return pref[0]
    if len(pref) > 1:
        more = f" and {len(pref) - MAX_LISTED} more" if len(pref) > MAX_LISTED else ""
        raise ModelError(f"signal {name!r}", "signal", "is ambiguous, it matches the columns "
                         + ", ".join(repr(c) for c in pref[:MAX_LISTED]) + more)
    if len(cols) <= MAX_LISTED:
        raise ModelError(f"signal {name!r}", "signal", "matches no column; valid columns: "
                         + ", ".join(repr(c) for c in cols))
    raise ModelError(f"signal {name!r}", "signal", f"matches no column; the closest of the {len(cols)} columns: "
                     + ", ".join(repr(c) for c in closest_columns(cols, name)) + " (all: the table's .columns)")


def closest_columns(columns: Sequence[str], name: str, n: int = MAX_LISTED) -> list[str]:
    """The n columns closest to `name` (unit-less, case-insensitive): those containing it first, then
    by difflib's similarity ratio."""
    import difflib
    key = split_unit(name)[0].strip().lower()
    bases = {str(c): split_unit(str(c))[0].strip().lower() for c in columns}
    hits = [c for c, b in bases.items() if key and key in b]
    ranked = sorted(bases, key=lambda c: -difflib.SequenceMatcher(None, key, bases[c]).ratio())
    return list(dict.fromkeys(hits[:n] + ranked))[:n]


class _Recorder:
    """Wraps a Result and records the measures a signal callable asks for (to label it with units)."""

    def __init__(self, res):
        self._res = res
        self.calls: list[tuple[str, tuple, Any]] = []

    def __getattr__(self, name):
        attr = getattr(self._res, name)
        if not callable(attr):
            return attr

        def call(*args, **kwargs):
            out = attr(*args, **kwargs)
            self.calls.append((name, args, out))
            return out
        return call


def _entity_name(obj) -> str:
    return str(getattr(obj, "name", obj))


def _measure_label(res, name: str, args: tuple) -> tuple[str, str, tuple[str, ...] | None]:
    """(label, unit, components) of the Result measure `name` called with `args`."""
    who = _entity_name(args[0]) if args else ""
    if name in ("joint_coordinate", "joint_velocity", "joint_acceleration") and args:
        joint = res._joint(args[0])  # noqa: SLF001 - the Result's own name lookup
        unit, comps = _JOINT_UNITS.get(joint.kind, ("", None))
        order = {"joint_coordinate": "", "joint_velocity": "/s", "joint_acceleration": "/s^2"}[name]
        noun = {"revolute": "angle", "translational": "displacement"}.get(joint.kind, "coordinate")
        what = {"joint_coordinate": noun, "joint_velocity": f"{noun} rate",
                "joint_acceleration": f"{noun} acceleration"}[name]
        return f"{who} {what}", (unit + order) if unit else "", comps
    if name in ("spring_length", "spring_velocity", "spring_force"):
        el = res._element(args[0])  # noqa: SLF001
        rot = type(el).__name__ in ("TorsionSpring",) or getattr(el, "dof", "") == "rotation" or \
            getattr(getattr(el, "joint", None), "kind", "") == "revolute"
        unit = {"spring_length": "rad" if rot else "m", "spring_velocity": "rad/s" if rot else "m/s",
                "spring_force": "N m" if rot else "N"}[name]
        return f"{who} {name.split('_')[1]}", unit, None
    if name in _MEASURE_UNITS:
        what, unit = _MEASURE_UNITS[name]
        return (f"{who} {what}" if who else what), unit, None
    return name, "", None


def resolve(res, spec, frame=None) -> Signal:
    """Evaluate a signal spec (callable, column name or ("label [unit]", callable)) on a Result or a
    DataFrame exported from one; see the module docstring."""
    if isinstance(spec, tuple) and len(spec) == 2 and isinstance(spec[0], str) and callable(spec[1]):
        label, unit = split_unit(spec[0])
        return Signal(label, unit, _as_array(spec[1](res), spec[0], res))
    if callable(spec):
        return _resolve_callable(res, spec)
    if isinstance(spec, str):
        df = frame if frame is not None else _dataframe(res)
        col = match_column(df.columns, spec)
        label, unit = split_unit(col)
        return Signal(label, unit, np.asarray(df[col], dtype=float))
    raise ModelError(f"signal {spec!r}", "signal", "expected a callable of the Result, a column name of "
                     "res.to_dataframe() or a ('label [unit]', callable) pair")


def _resolve_callable(res, fn: Callable) -> Signal:
    if _is_dataframe(res):
        raise ModelError(f"signal {getattr(fn, '__name__', fn)!r}", "signal",
                         "a callable needs a Result; for a results file give a column name")
    rec = _Recorder(res)
    out = fn(rec)
    values = _as_array(out, getattr(fn, "__name__", "signal"), res)
    if len(rec.calls) == 1 and rec.calls[0][2] is out:
        name, args, _ = rec.calls[0]
        label, unit, comps = _measure_label(res, name, args)
        if values.ndim == 2 and comps is None and values.shape[1] == 3:
            comps = ("x", "y", "z")
        return Signal(label, unit, values, comps)
    label = getattr(fn, "__name__", "signal")
    return Signal("signal" if label == "<lambda>" else label, "", values)


def _as_array(out, what, res) -> np.ndarray:
    a = np.asarray(out, dtype=float)
    n = len(_time(res))
    if a.ndim == 0 or a.shape[0] != n:
        raise ModelError(f"signal {what!r}", "signal", f"must give one value (or row) per output time "
                         f"({n}), got shape {a.shape}")
    return a


def _is_dataframe(obj) -> bool:
    return hasattr(obj, "columns") and hasattr(obj, "iloc")


_FRAMES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()   # Result -> its to_dataframe()


def _dataframe(res):
    if _is_dataframe(res):
        return res
    try:
        if res not in _FRAMES:
            _FRAMES[res] = res.to_dataframe()
        return _FRAMES[res]
    except TypeError:    # not weak-referenceable / hashable: no cache
        return res.to_dataframe()


def _time(res) -> np.ndarray:
    if _is_dataframe(res):
        return np.asarray(res[match_column(res.columns, TIME_COLUMN)], dtype=float)
    return np.asarray(res.time, dtype=float)


def event_times(res) -> list[float]:
    """Times [s] of the run's events: `res.events` when the Result offers them (times, or objects / pairs
    carrying a time), plus the stick/slip transitions of its joint-friction elements."""
    if _is_dataframe(res):
        return []
    out: list[float] = []
    for ev in getattr(res, "events", None) or ():
        t = getattr(ev, "time", ev[0] if isinstance(ev, (tuple, list)) else ev)
        out.append(float(t))
    model = getattr(getattr(res, "system", None), "model", None)
    for el in getattr(model, "forces", {}).values():
        if type(el).__name__ == "JointFriction" and hasattr(res, "friction_events"):
            try:
                out += [float(e[0]) for e in res.friction_events(el)]
            except Exception:  # noqa: BLE001 - markers are decoration; a failed measure must not stop the plot
                pass
    t = _time(res)
    return sorted({x for x in out if t[0] < x <= t[-1]})


def _pyplot():
    """matplotlib.pyplot, on the Agg backend when no backend was chosen and there is no display."""
    import os
    import sys

    import matplotlib
    if "matplotlib.pyplot" not in sys.modules and not os.environ.get("MPLBACKEND") \
            and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot(res: Result | pd.DataFrame, signal: SignalSpec | Sequence[SignalSpec], x: SignalSpec | None = None, ax: Axes | None = None,
         events: bool = True, **kw: Any) -> Axes:
    """Plot one signal or a list of signals of a Result (or of a DataFrame from `res.to_dataframe()` /
    a results file) against time [s], or against the signal `x`; returns the matplotlib Axes.

    Signals of different units get separate y axes, each labelled with its unit (a signal of unknown
    unit shares the first signal's axis): stacked subplots
    sharing x (the first Axes is returned, all are in `ax.figure.axes`), or, when `ax` is given, twin
    axes on its right.  Vector signals (N, 3) give one curve per component.  Vertical dotted lines mark
    the run's events (`event_times`) when `events` is true and curves are against time.  Extra keyword
    arguments go to `Axes.plot`.  Never calls `plt.show()`.
    """
    specs = list(signal) if isinstance(signal, list) else [signal]
    if not specs:
        raise ModelError("plot", "signal", "give at least one signal")
    frame = _dataframe(res) if any(isinstance(s, str) for s in specs + [x]) else None
    sigs = [resolve(res, s, frame) for s in specs]
    xs = resolve(res, x, frame) if x is not None else Signal("time", "s", _time(res))
    if xs.values.ndim != 1:
        raise ModelError("plot", "x", f"must be a scalar signal, {xs.title} has shape {xs.values.shape}")
    groups: dict[str, list[Signal]] = {}
    for s in sigs:     # one y axis per unit, in the order given; a signal of unknown unit joins the first
        groups.setdefault(s.unit or next(iter(groups), ""), []).append(s)
    axes = _axes(ax, len(groups), kw)
    marks = event_times(res) if events and x is None else []
    for k, (a, group) in enumerate(zip(axes, groups.values())):
        color = {} if ax is None or len(groups) == 1 else {"color": f"C{k}"}
        for s in group:
            _draw(a, xs.values, s, len(group) > 1, {**color, **kw} if len(group) == 1 else kw)
        a.set_ylabel(_ylabel(group))
        if ax is not None and len(groups) > 1 and len(group) == 1:
            a.yaxis.label.set_color(color["color"])
        if sum(1 if s.values.ndim == 1 else s.values.shape[1] for s in group) > 1:
            a.legend(fontsize="small")
        for t in marks if a is axes[0] or ax is None else ():
            a.axvline(t, color="0.5", lw=0.8, ls=":", zorder=0)
    (axes[0] if ax is not None else axes[-1]).set_xlabel(xs.title)
    axes[0].grid(True, alpha=0.3)
    for a in axes[1:] if ax is None else ():
        a.grid(True, alpha=0.3)
    return axes[0]


def _axes(ax, n: int, kw) -> list:
    """n y axes: `ax` and n - 1 twins on its right (spines 60 pt apart), or without `ax` a new figure of n
    stacked subplots sharing x."""
    if ax is None:
        plt = _pyplot()
        w, h = kw.pop("figsize", (7.0, 4.0 if n == 1 else 2.2 * n + 0.6))
        _, axs = plt.subplots(n, 1, sharex=True, squeeze=False, figsize=(w, h), layout="constrained")
        return list(axs[:, 0])
    out = [ax]
    for k in range(1, n):
        tw = ax.twinx()
        if k > 1:
            tw.spines["right"].set_position(("outward", 60 * (k - 1)))
        out.append(tw)
    return out


def _draw(ax, xv, s: Signal, several: bool, kw):
    if s.values.ndim == 1:
        ax.plot(xv, s.values, label=s.label, **kw)
        return
    comps = s.components or tuple(str(k) for k in range(s.values.shape[1]))
    for k in range(s.values.shape[1]):
        ax.plot(xv, s.values[:, k], label=f"{s.label} {comps[k]}", **kw)


def _ylabel(sigs: list[Signal]) -> str:
    units = {s.unit for s in sigs}
    if len(sigs) == 1:
        return sigs[0].title
    return f"[{units.pop()}]" if len(units) == 1 and "" not in units else \
        ", ".join(s.title for s in sigs)

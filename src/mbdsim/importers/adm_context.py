"""The state of one .adm import: the file, the units, the statements by id, the names given so far, the
marker table and the notes of what was approximated or ignored (see mbdsim.importers.adm)."""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelFileError
from .adm_expr import Context, number, translate
from .adm_lexer import Statement

# dataset unit names -> pint units (SI factors from pint, never typed here)
UNIT_NAMES = {
    "FORCE": {"NEWTON": "newton", "KNEWTON": "kilonewton", "KILONEWTON": "kilonewton", "MEGANEWTON": "meganewton",
              "MILLINEWTON": "millinewton", "MICRONEWTON": "micronewton", "NANONEWTON": "nanonewton",
              "DYNE": "dyne", "KILOGRAM_FORCE": "kilogram_force", "POUND_FORCE": "pound_force",
              "KPOUND_FORCE": "kip", "OUNCE_FORCE": "ounce_force", "POUNDAL": "poundal"},
    "MASS": {"KILOGRAM": "kilogram", "GRAM": "gram", "MEGAGRAM": "megagram", "TONNE": "tonne",
             "MILLIGRAM": "milligram", "MICROGRAM": "microgram", "NANOGRAM": "nanogram", "POUND_MASS": "pound",
             "KPOUND_MASS": "kilopound", "OUNCE_MASS": "ounce", "SLUG": "slug"},
    "LENGTH": {"METER": "meter", "MILLIMETER": "millimeter", "CENTIMETER": "centimeter", "KILOMETER": "kilometer",
               "MICROMETER": "micrometer", "NANOMETER": "nanometer", "ANGSTROM": "angstrom", "INCH": "inch",
               "FOOT": "foot", "YARD": "yard", "MILE": "mile", "MILS": "mil", "MICROINCH": "microinch"},
    "TIME": {"SECOND": "second", "MILLISECOND": "millisecond", "MICROSECOND": "microsecond",
             "NANOSECOND": "nanosecond", "MINUTE": "minute", "HOUR": "hour"},
}
SYSTEMS = {"MKS": ("NEWTON", "KILOGRAM", "METER", "SECOND"), "MMKS": ("NEWTON", "KILOGRAM", "MILLIMETER", "SECOND"),
           "CGS": ("DYNE", "GRAM", "CENTIMETER", "SECOND"), "IPS": ("POUND_FORCE", "POUND_MASS", "INCH", "SECOND"),
           "FPS": ("POUND_FORCE", "POUND_MASS", "FOOT", "SECOND")}


def _si(unit: str) -> float:
    from ..io.units import registry
    ureg = registry()
    if unit == "kilopound":
        return 1000.0 * ureg("pound").to_base_units().magnitude
    return float(ureg(unit).to_base_units().magnitude)


@dataclass
class Units:
    """SI per dataset unit of force [N], mass [kg], length [m] and time [s]."""

    force: float = 1.0
    mass: float = 1.0
    length: float = 1.0
    time: float = 1.0

    def scale(self, quantity: str) -> float:
        """SI per dataset unit of a derived quantity (names as in the Adams manuals)."""
        F, M, L, T = self.force, self.mass, self.length, self.time
        return {"force": F, "torque": F * L, "mass": M, "inertia": M * L * L, "length": L, "time": T,
                "velocity": L / T, "angular_velocity": 1.0 / T, "acceleration": L / T / T,
                "angular_acceleration": 1.0 / T / T, "stiffness": F / L, "damping": F * T / L,
                "rot_stiffness": F * L, "rot_damping": F * L * T, "angle": 1.0, "number": 1.0}[quantity]


@dataclass
class AdmImport:
    """One import in progress (see the module docstring)."""

    source: str
    model: object
    units: Units = field(default_factory=Units)
    statements: dict = field(default_factory=dict)     # name -> {id: Statement}
    parts: dict = field(default_factory=dict)          # part id -> Body
    markers: dict = field(default_factory=dict)        # marker id -> Marker
    floating: set = field(default_factory=set)         # ids of floating markers
    joints: dict = field(default_factory=dict)         # joint id -> Joint (JOINT and JPRIM share ids? no: own)
    variables: dict = field(default_factory=dict)      # VARIABLE id -> (text, line)
    splines: dict = field(default_factory=dict)        # SPLINE id -> (xs, ys, linear extrapolation)
    notes: list = field(default_factory=list)
    names: set = field(default_factory=set)
    folder: str = ""                                  # the dataset's folder (EXTERNAL FILE= is relative to it)

    # ------------------------------------------------------------- errors and notes
    def fail(self, st: Statement, fld: str, message: str, line: int | None = None):
        raise ModelFileError(st.label, fld, message, self.source, st.line if line is None else line)

    def note(self, st: Statement, message: str) -> None:
        self.notes.append(f"{st.label} (line {st.line}): {message}")

    # ------------------------------------------------------------- arguments
    def args(self, st: Statement, keys: tuple, flags: tuple = (), ignored: tuple = ()) -> tuple[dict, set]:
        """({full key: Arg}, {full flags}) of `st`, each key or flag given as any unique prefix (Adams
        abbreviations); an unknown or ambiguous one is an error naming it.  `ignored` keys/flags are
        accepted, noted and dropped."""
        out, fl = {}, set()
        for a in st.args:
            word = a.key if a.key is not None else a.values[0]
            pool = (keys if a.key is not None else flags) + ignored
            hits = [k for k in pool if k == word] or [k for k in pool if k.startswith(word)]
            if len(hits) != 1:
                what = "argument" if a.key is not None else "flag"
                self.fail(st, word, f"{'ambiguous' if hits else 'unknown or unsupported'} {what} {word!r} of "
                          f"{st.name} (mbdsim reads: {', '.join(keys + flags) or 'none'})", a.line)
            full = hits[0]
            if full in ignored:
                self.note(st, f"{full} ignored")
            elif a.key is None:
                fl.add(full)
            else:
                if full in out:
                    self.fail(st, full, f"{full} given twice", a.line)
                out[full] = a
        return out, fl

    def nums(self, st, args, key, n=None, default=None, quantity="number"):
        """The numbers of argument `key` (a list; scaled to SI by `quantity`), `default` when absent."""
        a = args.get(key)
        if a is None:
            return default
        try:
            vals = [number(v) for v in a.values]
        except ValueError:
            self.fail(st, key, f"expected numbers, got {', '.join(a.values)!r}", a.line)
        if n is not None and len(vals) != n:
            self.fail(st, key, f"expected {n} value(s), got {len(vals)}", a.line)
        if not all(np.isfinite(vals)):
            self.fail(st, key, "values must be finite", a.line)
        s = self.units.scale(quantity)
        return [v * s for v in vals]

    def num(self, st, args, key, default=None, quantity="number"):
        v = self.nums(st, args, key, 1, None, quantity)
        return default if v is None else v[0]

    def ident(self, st, args, key, required=True):
        """The integer id of argument `key` (None when absent and not required)."""
        a = args.get(key)
        if a is None:
            if required:
                self.fail(st, key, f"is required for {st.name}")
            return None
        if len(a.values) != 1 or not a.values[0].isdigit():
            self.fail(st, key, f"expected an id (integer), got {', '.join(a.values)!r}", a.line)
        return int(a.values[0])

    def marker(self, st, args, key, required=True, fixed=True):
        """The Marker of id argument `key`; errors for an unknown or (when `fixed`) a floating marker."""
        mid = self.ident(st, args, key, required)
        if mid is None:
            return None
        if mid not in self.markers:
            self.fail(st, key, f"no MARKER/{mid} in the dataset", args[key].line)
        if fixed and mid in self.floating:
            self.fail(st, key, f"MARKER/{mid} is FLOATING; {st.name} needs a fixed marker", args[key].line)
        return self.markers[mid]

    # ------------------------------------------------------------- names and expressions
    def name(self, st: Statement, default: str) -> str:
        """The mbdsim name of a statement: its Adams View name (last path component) when given, else
        `default` (PART_2, JOINT_1 ...); made a valid, unused identifier."""
        from ..model.loadexpr import reserved_names
        raw = (st.view_name or "").split(".")[-1] or default
        base = re.sub(r"\W", "_", raw)
        if not base or base[0].isdigit() or base in reserved_names() or base.endswith("_dot"):
            base = f"{st.name.lower()}_{base}"
        out, k = base, 2
        while out in self.names or out == "ground":
            out, k = f"{base}_{k}", k + 1
        self.names.add(out)
        return out

    def marker_name(self, st: Statement, body, default: str) -> str:
        """The mbdsim name of a MARKER on `body`: the last component of its Adams View name, else
        `default` (MARKER_3); a valid identifier, unique on the body."""
        from ..model.loadexpr import reserved_names
        raw = (st.view_name or "").split(".")[-1] or default
        base = re.sub(r"\W", "_", raw)
        if not base or base[0].isdigit() or base in reserved_names():
            base = f"marker_{base}"
        out, k = base, 2
        while out in body.markers:
            out, k = f"{base}_{k}", k + 1
        return out

    def marker_ref(self, st, line):
        """The function marking marker ids as "body.marker" (0: ground) in translated expressions."""
        def ref(mid: int) -> str:
            if mid == 0:
                return "ground"
            m = self.markers.get(mid)
            if m is None:
                raise ModelFileError(st.label, "FUNCTION", f"the function refers to MARKER/{mid}, which is not in "
                                     "the dataset", self.source, line)
            return f"{m.body.name}.{m.name}"
        return ref

    def expression(self, st, args, key, quantity, time_name="TIME") -> str:
        """The mbdsim text of the function argument `key` of `st`, its result scaled to SI `quantity`."""
        a = args.get(key)
        if a is None:
            self.fail(st, key, f"is required for {st.name}")
        text = a.values[0]
        if re.match(r"\s*USER\s*\(", text, re.IGNORECASE):
            self.fail(st, key, "USER(...) calls a compiled user subroutine, which mbdsim does not run", a.line)
        from .adm_spline import table_name
        spline = None if time_name == "t" else (lambda sid, kind: table_name(self, st, a.line, sid, kind))
        ctx = Context(st.label, self.source, a.line, self.marker_ref(st, a.line), self.variables,
                      self.units.length, self.units.time, time_name, spline)
        out = translate(text, ctx)
        s = self.units.scale(quantity)
        return out if s == 1.0 else f"{s!r}*({out})"

    def model_error(self, st, exc, line=None):
        """Re-raise a ModelError of the Model API as a ModelFileError naming the statement and line."""
        raise ModelFileError(st.label, getattr(exc, "field", "?"), str(exc), self.source,
                             st.line if line is None else line) from None

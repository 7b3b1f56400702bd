"""Load expressions (issue 14): run-time functions of time and state, written as in Adams.

`parse_load(model, text, entity, field)` parses an expression string with the whitelist parser of
`mbdsim.expressions` (never evaluated as code) extended by state measures, Adams names and argument
order (marker i relative to marker j, components in the axes of marker k):

    DX DY DZ (i[, j][, k])   position of i relative to j [m]            DM (i[, j])  distance [m]
    VX VY VZ (i[, j][, k])   velocity of i relative to j [m/s]           VM (i[, j])  its magnitude
    VR (i[, j])              radial (separation) velocity d|DM|/dt [m/s]
    WX WY WZ (i[, j][, k])   angular velocity of i relative to j [rad/s]  WM (i[, j])
    ACCX ACCY ACCZ (i[, j][, k])  acceleration of i relative to j [m/s^2] (outputs and sensors only)
    AX AY AZ (i[, j])        rotation of i about the x/y/z axis of j [rad], in (-pi, pi] (Adams'
                             atan2(-zi.yj, zi.zj), atan2(zi.xj, zi.zj), atan2(xi.yj, xi.xj))

Arguments name a body (its centre-of-mass frame: CM origin, body axes) or a marker as body.marker;
j and k default to ground. Differences are taken in ground (Adams' reference frame l = ground).
Variables: t and TIME [s]; the coordinate of every revolute, screw (angle [rad], continuous) and
translational joint (slide [m]) by its name, and its rate as <joint>_dot [rad/s, m/s]; the model's
inputs (Model.add_input) by name.  Tables: the model's `tables` {name: table} (the Adams SPLINEs that
mb.from_adm reads, a model file's `tables:` section) are called as name(x) or name(x, order=n).
Functions: the model's `functions` (Model.add_function: numba.njit / numba.cfunc functions, run inside the
compiled kernels, mbdsim.userfunctions) are called as name(x, ...) with their number of arguments.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Union

import numpy as np

from ..errors import ModelError
from .joint_kinds import JOINT_KINDS

if TYPE_CHECKING:
    from .._types import JointRef, Location
    from .forces import JointForce, LineForce

ScalarLoad = Union[float, str, Callable[..., Any]]   # a number, an expression string or f(t, state)

POSITION = {"DX": 0, "DY": 1, "DZ": 2, "DM": 3}
VELOCITY = {"VX": 4, "VY": 5, "VZ": 6, "VM": 7, "VR": 8}
ANGULAR = {"WX": 9, "WY": 10, "WZ": 11, "WM": 12}
ANGLES = {"AX": 13, "AY": 14, "AZ": 15}
ACCEL = {"ACCX": 16, "ACCY": 17, "ACCZ": 18}
MEASURE_KIND = {**POSITION, **VELOCITY, **ANGULAR, **ANGLES, **ACCEL}
JOINT_ANGLE, JOINT_ANGLE_RATE, JOINT_SLIDE, JOINT_SLIDE_RATE = 20, 21, 22, 23
INPUT = 30   # a model input (Model.add_input): Measure("input", i=<input name>)
WITH_K = {"DX", "DY", "DZ", "VX", "VY", "VZ", "WX", "WY", "WZ", "ACCX", "ACCY", "ACCZ"}
# the coordinate a one-coordinate joint's name reads in an expression (joint-kind registry)
JOINT_DOF = {n: k.axis_dofs[0] for n, k in JOINT_KINDS.items() if k.ncoord == 1 and k.axis_dofs}
TIME_NAMES = ("t", "TIME")


@dataclass(frozen=True)
class Measure:
    """One measure of an expression: `name` (DX ... or 'joint'), its targets as "body" / "body.marker"
    strings (j, k None for ground), or for a joint measure the joint's name, dof and whether it is the rate."""

    name: str
    i: str | None = None
    j: str | None = None
    k: str | None = None
    joint: str | None = None
    dof: str | None = None
    rate: bool = False

    @property
    def kind(self) -> int:
        if self.name == "input":
            return INPUT
        if self.joint is not None:
            return (JOINT_ANGLE if self.dof == "rotation" else JOINT_SLIDE) + int(self.rate)
        return MEASURE_KIND[self.name]

    @property
    def needs_acceleration(self) -> bool:
        return self.name in ACCEL


@dataclass(frozen=True, eq=False)
class LoadExpr:
    """A parsed load expression: the Expr (variables: t, TIME and one per measure) and its measures
    {variable name: Measure}. Units: those of the quantity it gives (N, N m)."""

    expr: object
    measures: dict

    @property
    def text(self) -> str:
        return self.expr.text

    def __repr__(self) -> str:
        return f"LoadExpr({self.text!r})"

    @property
    def joint_angles(self) -> list[str]:
        """Joints whose (continued) angle the expression reads."""
        return sorted({m.joint for m in self.measures.values() if m.joint and m.dof == "rotation" and not m.rate})


@dataclass(frozen=True, eq=False)
class ExprVector:
    """A 3-vector whose components are numbers or LoadExprs."""

    components: tuple

    def __repr__(self) -> str:
        return "[" + ", ".join(c.text if isinstance(c, LoadExpr) else repr(float(c)) for c in self.components) + "]"

    @property
    def exprs(self) -> list:
        return [c for c in self.components if isinstance(c, LoadExpr)]


class _Hook:
    """The measures hook of `mbdsim.expressions.parse` for one model."""

    names = tuple(MEASURE_KIND)

    def __init__(self, model, allow_acc):
        self.model, self.allow_acc, self.found = model, allow_acc, {}

    def _target(self, text, fail):
        bodies = self.model.bodies
        if text in bodies:
            return text
        body, dot, marker = text.partition(".")
        if dot and body in bodies:
            if marker in bodies[body].markers:
                return text
            fail(f"body {body!r} has no marker {marker!r} (its markers: "
                 f"{', '.join(bodies[body].markers) or 'none'}) in")
        fail(f"no body or body.marker named {text!r} (bodies: {', '.join(bodies)}) in")

    def call(self, name, args, fail):
        from .._exprtree import Var
        hi = 3 if name in WITH_K else 2
        if not 1 <= len(args) <= hi:
            fail(f"{name} takes 1 to {hi} arguments ({'i, j, k' if hi == 3 else 'i, j'}), got {len(args)}:")
        if name in ACCEL and not self.allow_acc:
            fail(f"{name} depends on the accelerations, which depend on the loads themselves (an algebraic "
                 f"loop): use it in outputs or sensors, not in a load:")
        tg = [self._target(a, fail) for a in args] + [None] * (3 - len(args))
        tg = [None if x == "ground" else x for x in tg]
        m = Measure(name, *tg)
        var = f"{name}({', '.join(args)})"
        self.found[var] = m
        return Var(var)


def joint_variables(model) -> dict:
    """{variable: Measure} of the joint coordinates and rates an expression may read."""
    out = {}
    for jn, jt in model.joints.items():
        dof = JOINT_DOF.get(jt.kind)
        if dof is None or not jn.isidentifier():
            continue
        out[jn] = Measure("joint", joint=jn, dof=dof)
        out[f"{jn}_dot"] = Measure("joint", joint=jn, dof=dof, rate=True)
    return out


def reserved_names() -> frozenset:
    """The names the expression languages read as themselves: the time t and TIME [s], the constant pi,
    the functions (sin ...), the Adams library (STEP ..., both cases) and the measures (DX ...)."""
    from ..expressions import FUNCTIONS, LIBRARY_FUNCTIONS
    return frozenset(FUNCTIONS) | frozenset(LIBRARY_FUNCTIONS) | frozenset(MEASURE_KIND) | {"pi", *TIME_NAMES}


def check_name(entity: str, name, read_in_expressions: bool) -> None:
    """ModelError(entity, "name") unless `name` is a non-empty string without '.' (which separates body
    and marker: a body "rod.tip" would hide the marker tip of body rod) and, for the entities that
    expressions read (bodies, markers, joints), not a reserved name (a joint "t" would be shadowed by
    the time, a body "pi" by the constant)."""
    if not isinstance(name, str) or not name:
        raise ModelError(entity, "name", "must be a non-empty string")
    if "." in name:
        raise ModelError(entity, "name", f"{name!r} contains '.', which separates a body from its marker "
                         "(body.marker) in references: choose another name")
    if read_in_expressions and name in reserved_names():
        raise ModelError(entity, "name", f"{name!r} is reserved by the expression language (time t and TIME, "
                         "the constant pi, function and measure names): choose another name")


def parse_load(model, text, entity, field, allow_acc=False) -> LoadExpr:
    """LoadExpr of `text` against the model's bodies, markers and joints; ModelError(entity, field) with
    the parser's message (which lists the valid names) when it does not parse."""
    from ..expressions import ExpressionError, parse
    reserved = reserved_names()
    joints = {v: m for v, m in joint_variables(model).items() if v not in reserved}
    hook = _Hook(model, allow_acc)
    inputs = [v for v in getattr(model, "inputs", {}) if v not in reserved and v not in joints]
    try:
        tables = {**getattr(model, "tables", {}), **getattr(model, "functions", {})}   # (functions: add_function)
        e = parse(text, (*TIME_NAMES, *joints, *inputs), measures=hook, tables=tables)
    except (ExpressionError, ValueError) as exc:
        raise ModelError(entity, field, f"{exc} (measures: {', '.join(MEASURE_KIND)} of bodies and "
                         f"body.marker; variables: t, TIME, the joints {', '.join(joints) or '(none)'}"
                         f"{'; inputs ' + ', '.join(inputs) if inputs else ''})") from None
    used = {v: m for v, m in joints.items() if e.depends_on(v)}
    for v, m in used.items():
        jt = model.joints[m.joint]
        if m.dof == "rotation" and getattr(jt.body_j, "is_particle", False):
            raise ModelError(entity, field, f"reads {v!r}, the angle of joint '{m.joint}', whose body_j "
                             f"'{jt.body_j.name}' is a particle: it has no rotation, so the joint no angle")
    used.update({v: Measure("input", i=v) for v in inputs if e.depends_on(v)})
    used.update(hook.found)
    return LoadExpr(e, used)


def load_value(model, entity, field, value, allow_callable=True):
    """A number, a LoadExpr (from a string or a LoadExpr), or a callable (t, state) when allowed."""
    from ._check import scalar
    if isinstance(value, LoadExpr):
        return value
    if isinstance(value, str):
        return parse_load(model, value, entity, field)
    if callable(value):
        if not allow_callable:
            raise ModelError(entity, field, "expected a number or an expression string")
        return value
    return scalar(entity, field, value)


def load_vector(model, entity, field, value):
    """A constant 3-vector (ndarray), a callable, or an ExprVector when a component is an expression."""
    from ._check import vec3
    if callable(value) and not isinstance(value, (str, LoadExpr)):
        return value
    if isinstance(value, ExprVector):
        return value
    if isinstance(value, (list, tuple, np.ndarray)) and len(value) == 3 and \
            any(isinstance(c, (str, LoadExpr)) for c in value):
        comps = tuple(load_value(model, entity, f"{field}[{k}]", c, allow_callable=False)
                      for k, c in enumerate(value))
        return ExprVector(comps)
    if isinstance(value, str):
        raise ModelError(entity, field, "expected 3 components (numbers or expression strings), got one string")
    return vec3(entity, field, value)


def load_text(value):
    """What a model file stores for a load value: a float, an expression text, or a list of those."""
    if isinstance(value, LoadExpr):
        return value.text
    if isinstance(value, ExprVector):
        return [load_text(c) for c in value.components]
    return float(value)


class ExprLoadsMixin:
    """add_line_force, add_joint_force (Model methods)."""

    def add_line_force(self, name: str, at_i: Location, at_j: Location, magnitude: ScalarLoad) -> LineForce:
        """Action-reaction force [N] along the line between two points (each a Marker, a body (its centre
        of mass) or (body, point in ground at t=0 [m])): `magnitude` is a number, an expression string
        (e.g. "k*(DM(a.p, b.q) - L0) + c*VR(a.p, b.q)") or a callable (t, state); positive pulls the
        points together (the sign of add_spring_damper's tension)."""
        from .forces import LineForce
        entity = f"line force '{name}'"
        self._claim(name, "line force")
        try:
            mi, mj = self._location(entity, "at_i", at_i), self._location(entity, "at_j", at_j)
            val = load_value(self, entity, "magnitude", magnitude)
        except ModelError:
            self._names.discard(name)
            raise
        e = LineForce(name, mi, mj, val)
        self.forces[name] = e
        return e

    def add_joint_force(self, name: str, joint: JointRef, value: ScalarLoad, dof: str | None = None) -> JointForce:
        """Generalized force [N] along, or torque [N m] about, a joint's axis, on body_j and reacting on
        body_i (positive drives the joint coordinate up): a motor's torque, an actuator's force. `value`
        is a number, an expression string (e.g. "T0*(1 - WZ(rotor)/w0)") or a callable (t, state); `dof`
        "rotation" or "translation" picks the coordinate of a cylindrical joint (default: the joint's
        only one)."""
        from .forces import JointForce
        entity = f"joint force '{name}'"
        self._claim(name, "joint force")
        try:
            jt = self._lookup(joint, self.joints, entity, "joint")
            from .joint_kinds import kinds_with_axis, pick_axis_dof
            dof = pick_axis_dof(entity, jt, dof, True, lambda: f"a {jt.kind} joint has no single axis; use a "
                                f"{', '.join(kinds_with_axis(loads=True))} joint")
            if jt.body_j.is_particle and dof == "rotation":
                raise ModelError(entity, "joint", f"body_j of joint {jt.name!r} is a particle: no torque")
            val = load_value(self, entity, "value", value)
        except ModelError:
            self._names.discard(name)
            raise
        e = JointForce(name, jt, dof, val)
        self.forces[name] = e
        return e

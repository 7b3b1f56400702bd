"""Model methods for constraints between joint coordinates: couplers, gears, user constraints (issue 11).

Mixed into mbdsim.Model.  A coordinate constraint is f(x_1, ..., x_k, t) = 0 in the coordinates x of
one-axis joints: a revolute angle [rad], a translational slide [m], a screw angle, or either coordinate
of a cylindrical joint (dof "rotation" / "translation").  Angles are continuous (they count whole
turns), zero as built, right-handed about the joint axis on body_i; slides are along it.  The
equations live in mbdsim.system.constraints.coupler.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import ModelError
from ._check import scalar
from .joint_kinds import JOINT_KINDS, coupled_dofs
from .joints import Joint
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._types import JointRef



@dataclass(eq=False)
class CoordConstraint:
    """f(x, t) = 0 over joint coordinates: `terms` [(Joint, dof)], `expr` an mbdsim Expr of
    `variables` = ("t", one name per term); `kind` "coupler", "gear" or "user"; `ratio` for couplers
    (x_2 = ratio x_1: [rad/rad, m/rad, rad/m or m/m] by the two coordinates' kinds); `text` the
    user's expression."""

    name: str
    kind: str
    terms: list
    expr: Any
    variables: tuple
    ratio: float | None = None
    text: str | None = None
    derivs: dict = field(default_factory=dict)   # symbolic first and second derivatives, by variable

    def __repr__(self) -> str:
        return f"CoordConstraint({self.kind} {self.name!r}: {self.text or self.expr.text})"


class CouplersMixin:
    """add_coupler, add_gear, add_user_constraint."""

    def add_coupler(self, name: str, joint_1: JointRef, joint_2: JointRef, ratio: float, dof_1: str | None = None,
                    dof_2: str | None = None) -> CoordConstraint:
        """Coupler: x_2 = ratio * x_1 between the coordinates of two joints (Adams COUPLER).

        Two revolutes: a gear pair, ratio = -r_1 / r_2 for external gears (pitch radii r).  A revolute
        (pinion, radius r) and a translational joint (rack): ratio = r [m/rad] gives the rack's slide
        x_2 = r theta_1.  `dof_k` picks "rotation"/"translation" of a cylindrical joint.  The load it
        transmits: `Result.coupler_load(name)`."""
        entity = f"coupler '{name}'"
        self._claim(name, "coupler")
        try:
            r = scalar(entity, "ratio", ratio)
            if r == 0.0:
                raise ModelError(entity, "ratio", "must be non-zero (a zero ratio locks joint_2)")
            terms = [self._coupled(entity, "joint_1", joint_1, "dof_1", dof_1),
                     self._coupled(entity, "joint_2", joint_2, "dof_2", dof_2)]
            if terms[0] == terms[1]:
                raise ModelError(entity, "joint_2", "couples a coordinate with itself")
            c = self._coord_constraint(entity, name, "coupler", terms, f"x1 - ({r!r})*x0", ("t", "x0", "x1"))
        except ModelError:
            self._names.discard(name)
            raise
        c.ratio = r
        return c

    def add_gear(self, name: str, joint_1: JointRef, joint_2: JointRef, ratio: float) -> CoordConstraint:
        """Gear pair (a coupler of two revolute joints): theta_2 = ratio * theta_1, ratio = -r_1 / r_2
        for external gears, +r_1 / r_2 for an internal (ring) gear; pitch radii r [m]."""
        for k, jt in ((1, joint_1), (2, joint_2)):
            j = self.joints.get(jt) if isinstance(jt, str) else jt
            if isinstance(j, Joint) and j.kind != "revolute":
                raise ModelError(f"gear '{name}'", f"joint_{k}", f"a gear couples revolute joints; "
                                 f"{j.name!r} is {j.kind} (use add_coupler)")
        c = self.add_coupler(name, joint_1, joint_2, ratio)
        c.kind = "gear"
        return c

    def add_user_constraint(self, name: str, expression: str) -> CoordConstraint:
        """General constraint expression(...) = 0 written in joint coordinates by joint name, e.g.
        "crank - 2*rocker" or "sin(j1) - 0.5*j2", and time t [s] (safe whitelist parser, never eval'd;
        its Jacobian and acceleration terms come from exact symbolic derivatives).  Joints: revolute,
        translational, screw (one coordinate each; angles in rad, continuous; slides in m)."""
        from ..expressions import ExpressionError, parse
        from .loadexpr import reserved_names
        entity = f"user constraint '{name}'"
        self._claim(name, "user constraint")
        try:
            if not isinstance(expression, str):
                raise ModelError(entity, "expression", f"expected an expression string, got {expression!r}")
            names = [n for n in self.joints if n.isidentifier() and n not in reserved_names()]
            try:
                e = parse(expression, ("t", *names))
            except (ExpressionError, ValueError) as exc:
                raise ModelError(entity, "expression", f"{exc} (variables: t and the joints "
                                 f"{', '.join(names) or '(none)'})") from None
            used = [n for n in names if e.depends_on(n)]
            if not used:
                raise ModelError(entity, "expression", "uses no joint coordinate")
            terms = [self._coupled(entity, "expression", n, "dof", None, single=True) for n in used]
            c = self._coord_constraint(entity, name, "user", terms, expression, ("t", *used))
        except ModelError:
            self._names.discard(name)
            raise
        c.text = expression
        return c

    # ----------------------------------------------------------------- helpers
    def _coupled(self, entity, field, joint, dof_field, dof, single=False):
        jt = self._lookup(joint, self.joints, entity, field)
        allowed = coupled_dofs(jt.kind)
        if not allowed or (single and len(allowed) > 1):
            names = [k for k in JOINT_KINDS if coupled_dofs(k) and (not single or len(coupled_dofs(k)) == 1)]
            kinds = ", ".join(names[:-1]) + " or " + names[-1]
            raise ModelError(entity, field, f"joint {jt.name!r} is {jt.kind}; coordinates of {kinds} joints "
                             "can be coupled")
        dof = allowed[0] if dof is None else dof
        if dof not in allowed:
            raise ModelError(entity, dof_field, f"{dof!r} is not a coordinate of {jt.kind} joint {jt.name!r}")
        if dof == "rotation" and jt.body_j.is_particle:
            raise ModelError(entity, field, f"body_j of {jt.name!r} is a particle: it has no rotation")
        return (jt, dof)

    def _coord_constraint(self, entity, name, kind, terms, text, variables) -> CoordConstraint:
        from ..expressions import parse
        e = parse(text, variables)
        c = CoordConstraint(name, kind, terms, e, tuple(variables))
        try:
            for a in variables:
                da = e.derivative(a)
                c.derivs[a] = da
                for b in variables:
                    c.derivs[(a, b)] = da.derivative(b)
        except Exception as exc:   # a function without a derivative (e.g. a table of order 0)
            raise ModelError(entity, "expression", f"cannot differentiate: {exc}") from None
        self.__dict__.setdefault("coord_constraints", {})[name] = c
        return c

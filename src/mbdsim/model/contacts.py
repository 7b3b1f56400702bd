"""Shape contact (issue 30): `Model.add_contact` between geometry placed on bodies (Body.add_shape), legacy
mb.Sphere / mb.Plane, or lists of them (every pair between the two lists; the broad phase prunes).

The law (solvers.fastcontact): Adams IMPACT at each contact point (stiffness [N/m^e], exponent, damping
[N s/m] reached at penetration [m]) or POISSON (coefficient of restitution); Coulomb friction with
`mu` regularised below `friction_velocity` [m/s] as before, or Adams' static and dynamic coefficients
with stiction and transition velocities [m/s].
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import ModelError
from ._check import scalar


@dataclass(eq=False)
class ShapeContact:
    """Compliant contact between every pair of `pairs` ((shape_i, shape_j) of geometry.Shape or resolved
    legacy shapes); normal law IMPACT (restitution None) or POISSON (0 <= restitution <= 1); friction mode
    0 (mu, friction_velocity) or 1 (mu_static, mu_dynamic, stiction_velocity, transition_velocity)."""

    name: str
    pairs: list
    stiffness: float
    exponent: float
    damping: float
    penetration: float
    mu: float = 0.0
    friction_velocity: float = 1e-3
    restitution: float | None = None
    mu_static: float | None = None
    mu_dynamic: float | None = None
    stiction_velocity: float | None = None
    transition_velocity: float | None = None
    shapes_i: list = field(default_factory=list)
    shapes_j: list = field(default_factory=list)

    @property
    def friction_mode(self) -> int:
        return 0 if self.mu_static is None else 1

    def parameters(self) -> tuple:
        """The kernel's row (fastcontact.PAR_FIELDS, without the element index)."""
        if self.friction_mode == 0:
            fr = (0.0, self.mu, self.mu, self.friction_velocity, self.friction_velocity)
        else:
            fr = (1.0, self.mu_static, self.mu_dynamic, self.stiction_velocity, self.transition_velocity)
        eps = -1.0 if self.restitution is None else self.restitution
        return (self.stiffness, self.exponent, self.damping, self.penetration, eps) + fr


def friction_options(entity, mu, friction_velocity, mu_static, mu_dynamic, stiction_velocity, transition_velocity):
    """Checked (mu_static, mu_dynamic, stiction_velocity, transition_velocity), all None for the mu law."""
    given = [x is not None for x in (mu_static, mu_dynamic, stiction_velocity, transition_velocity)]
    if not any(given):
        return None, None, None, None
    if mu:
        raise ModelError(entity, "mu", "give either mu (and friction_velocity) or mu_static/mu_dynamic, not both")
    if mu_static is None or mu_dynamic is None:
        raise ModelError(entity, "mu_static" if mu_static is None else "mu_dynamic",
                         "give both mu_static and mu_dynamic")
    ms = scalar(entity, "mu_static", mu_static, minimum=0.0)
    md = scalar(entity, "mu_dynamic", mu_dynamic, minimum=0.0)
    vs = scalar(entity, "stiction_velocity", 1e-4 if stiction_velocity is None else stiction_velocity,
                minimum=0.0, strict=True)
    vt = scalar(entity, "transition_velocity", 10 * vs if transition_velocity is None else transition_velocity,
                minimum=0.0, strict=True)
    if not vt > vs:
        raise ModelError(entity, "transition_velocity", f"must be > stiction_velocity ({vs!r}), got {vt!r}")
    return ms, md, vs, vt


def supported(kind_a: str, kind_b: str) -> bool:
    """Whether the narrow phase handles this pair of kinds (fastnarrow.KIND_NAMES): any pair of a plane
    and another shape, any two convex shapes (closed forms, separating axes, GJK/EPA), a convex shape
    against a triangle mesh and two triangle meshes (vertices against triangles); not two planes."""
    return not (kind_a == kind_b == "plane")


def shape_list(entity, field, value) -> list:
    return list(value) if isinstance(value, (list, tuple)) else [value]


def kind_of(shape) -> str:
    """Kind name of a resolved shape (a geometry.Shape or a legacy AttachedShape)."""
    from ..geometry.pack import kind_name
    return kind_name(shape)


def make_pairs(entity, shapes_i, shapes_j) -> list:
    """All (i, j) pairs on two different bodies; ModelError for an unsupported pair or none at all."""
    pairs, seen = [], set()
    for a in shapes_i:
        for b in shapes_j:
            if (id(b), id(a)) in seen or (id(a), id(b)) in seen:
                continue   # a pair in both lists once only
            seen.add((id(a), id(b)))
            if a.body is b.body:
                if len(shapes_i) == 1 and len(shapes_j) == 1:
                    raise ModelError(entity, "shape_j", "the two shapes are on the same body")
                continue
            ka, kb = kind_of(a), kind_of(b)
            if not supported(ka, kb):
                raise ModelError(entity, "shape_j", f"{ka}-{kb} contact is not supported (supported: any shape "
                                 "against a plane, any two convex shapes, a convex shape or a triangle mesh against a triangle mesh)")
            pairs.append((a, b))
    if not pairs:
        raise ModelError(entity, "shape_j", "no pair of shapes on two different bodies")
    return pairs


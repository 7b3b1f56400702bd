"""The joint-kind registry: the one place a joint kind is declared for the model layer, the model files
and the results (its constraint equations are the class of the same `kind` in
mbdsim.system.constraints.registry; tests/test_joint_kinds.py checks that both list the same kinds).

Each entry says what a kind leaves free and how it is addressed: relative degrees of freedom between
two rigid bodies, the values of Result.joint_coordinate, the freedoms along or about the joint axis
that motions, couplers, joint forces and stops may act on, whether the first coordinate is an angle
continued beyond +-pi, the constraint counts of `mbdsim info`, and the Model method and model-file
fields that create it."""
from __future__ import annotations

from dataclasses import dataclass

ROT, TRA = "rotation", "translation"


@dataclass(frozen=True)
class JointKind:
    """One joint kind.

    dof: relative degrees of freedom between two rigid bodies; ncoord: values of
    Result.joint_coordinate (a universal joint reports a 3-value rotation vector, 2 of them free);
    coord_names: how those values read, for messages and docs; axis_dofs: freedoms along/about the
    joint axis that a motion or coupler may drive (the first is the default); loads: joint forces,
    stops and friction may act on axis_dofs; angle: the first coordinate is an angle [rad] continued
    beyond +-pi along an analysis; slide: a coordinate is a slide [m] along the joint axis (the last of
    Result.joint_coordinate); translation_constraints: constraints on the relative translation
    (what a particle as body_j feels); planar_dof: in-plane freedoms left in a planar model (None: it
    depends on the placement); fields: the model-file fields besides name/body_i/body_j, in the order
    of the Model method `add_<name>`; coupled: the axis freedoms a coupler may tie (None: axis_dofs; a
    screw's slide follows its angle, so only the angle is coupled); coord_units: the unit of each joint
    coordinate where they differ (else `units` derives them from angle / slide)."""

    name: str
    dof: int
    ncoord: int
    translation_constraints: int
    fields: tuple
    coord_names: str = ""
    axis_dofs: tuple = ()
    loads: bool = False
    angle: bool = False
    planar_dof: int | None = None
    coupled: tuple | None = None
    slide: bool = False
    coord_units: tuple = ()

    @property
    def units(self) -> tuple:
        """The SI unit of each joint coordinate ("rad" or "m"), in the order of Result.joint_coordinate."""
        if self.coord_units:
            return self.coord_units
        return ("m",) * self.ncoord if self.slide and not self.angle else ("rad",) * self.ncoord

    @property
    def method(self) -> str:
        """The Model method that adds a joint of this kind."""
        return f"add_{self.name}"


_ROTVEC = "a relative rotation vector [rad] (angular velocity [rad/s]) in body_i axes"
JOINT_KINDS: dict[str, JointKind] = {k.name: k for k in (
    JointKind("revolute", 1, 1, 3, ("point", "axis"), "angle [rad]", (ROT,), True, True, 1),
    JointKind("translational", 1, 1, 2, ("point", "axis"), "slide [m]", (TRA,), True, False, 1, slide=True),
    JointKind("cylindrical", 2, 2, 2, ("point", "axis"), "(angle [rad], slide [m])", (ROT, TRA), True, True,
              slide=True, coord_units=("rad", "m")),
    JointKind("spherical", 3, 3, 3, ("point",), _ROTVEC, planar_dof=1),
    JointKind("universal", 2, 3, 3, ("point", "axis_i", "axis_j"), _ROTVEC),
    JointKind("planar", 3, 3, 1, ("point", "normal", "u_axis"), "(u [m], v [m], angle [rad])", planar_dof=3,
              coord_units=("m", "m", "rad")),
    JointKind("fixed", 0, 0, 3, ("point",), planar_dof=0),
    # joint primitives (Adams JPRIM): no joint coordinates
    JointKind("inline", 4, 0, 2, ("point", "axis")),
    JointKind("inplane", 5, 0, 1, ("point", "normal")),
    JointKind("orientation", 3, 0, 0, ()),
    JointKind("parallel_axes", 4, 0, 0, ("axis",)),
    JointKind("perpendicular", 5, 0, 0, ("axis_i", "axis_j")),
    JointKind("atpoint", 3, 0, 3, ("point",), planar_dof=1),
    # a screw reports its angle [rad] (slide = lead * angle / 2 pi); motions and couplers drive either
    JointKind("screw", 1, 1, 2, ("point", "axis", "lead"), "angle [rad]", (ROT, TRA), False, True, coupled=(ROT,)),
    JointKind("constant_velocity", 2, 3, 3, ("point", "axis_i", "axis_j"), _ROTVEC),
)}


def axis_dofs(kind: str, loads: bool = False) -> tuple:
    """The axis freedoms of `kind` a motion or coupler (loads=False) or a joint force, stop or friction
    (loads=True) may act on; () when none."""
    k = JOINT_KINDS.get(kind)
    if k is None or (loads and not k.loads):
        return ()
    return k.axis_dofs


def coupled_dofs(kind: str) -> tuple:
    """The axis freedoms of `kind` a coupler or gear may tie ("rotation"/"translation"); () when none."""
    k = JOINT_KINDS.get(kind)
    if k is None:
        return ()
    return k.axis_dofs if k.coupled is None else k.coupled


def pick_axis_dof(entity: str, joint, dof, loads: bool, no_axis) -> str:
    """The axis freedom of `joint` that `entity` acts on: `dof` ("rotation"/"translation") or, when None,
    the kind's first; ModelError(entity, "joint", no_axis) when the kind has none for a motion or coupler
    (loads=False) or a load (loads=True), ModelError(entity, "dof") when `dof` is not one of them.
    no_axis: the message, or a function giving it (called only then)."""
    from ..errors import ModelError
    allowed = axis_dofs(joint.kind, loads)
    if not allowed:
        raise ModelError(entity, "joint", no_axis() if callable(no_axis) else no_axis)
    if dof is None:
        return allowed[0]
    if dof not in allowed:
        raise ModelError(entity, "dof", f"{dof!r} is not a coordinate of {joint.kind} joint {joint.name!r} "
                         f"(choose from {allowed})")
    return dof


def kinds_with_axis(loads: bool = False) -> tuple:
    """Names of the kinds that have axis freedoms (for error messages)."""
    return tuple(n for n in JOINT_KINDS if axis_dofs(n, loads))


def has_slide(kind: str) -> bool:
    """True when a coordinate of `kind` is a slide [m] along the joint axis."""
    k = JOINT_KINDS.get(kind)
    return bool(k and k.slide)


def is_angle(kind: str) -> bool:
    """True when the first joint coordinate of `kind` is an angle continued beyond +-pi."""
    k = JOINT_KINDS.get(kind)
    return bool(k and k.angle)

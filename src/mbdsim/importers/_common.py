"""What the importers share: mass-property merging, entity names, notes of approximations, visual shapes.

Everything is SI and in ground axes at t=0 unless said otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Joint limits become compliant stops (mbdsim.Model.add_stop) with these parameters: stiffness
# [N m/rad^e or N/m^e], exponent e, damping [N m s/rad or N s/m] reached at penetration [rad or m].
STOP_STIFFNESS, STOP_EXPONENT, STOP_DAMPING, STOP_PENETRATION = 1e5, 1.5, 10.0, 1e-3
# Coulomb joint friction of a revolute joint needs a pin radius [m]; this one makes the load-dependent
# part of its normal load (pin_radius * |reaction|) negligible: the friction torque is the file's value.
FRICTION_PIN_RADIUS = 1e-9


class ImportApproximationWarning(UserWarning):
    """An importer approximated or left out something of a file (the list is `model.import_notes`)."""


@dataclass
class MassPart:
    """Mass [kg], centre of mass [m] and inertia about it [kg m^2], in ground axes."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray


def merge_mass(parts) -> MassPart:
    """One rigid body's mass properties from parts welded together (parallel-axis theorem)."""
    parts = list(parts)
    m = float(sum(p.mass for p in parts))
    if m <= 0.0:
        com = parts[0].com.copy() if parts else np.zeros(3)
        return MassPart(0.0, com, sum((p.inertia for p in parts), np.zeros((3, 3))))
    com = sum(p.mass * p.com for p in parts) / m
    J = np.zeros((3, 3))
    for p in parts:
        d = p.com - com
        J += p.inertia + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return MassPart(m, com, 0.5 * (J + J.T))


def rpy_matrix(rpy) -> np.ndarray:
    """Rotation matrix of URDF roll-pitch-yaw angles [rad]: Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


@dataclass
class VisualShape:
    """A shape drawn on a body (not part of the dynamics): kind "box" (size: edge lengths), "sphere"
    (size: radius), "cylinder" / "capsule" (size: radius, length; along the shape's z axis),
    "ellipsoid" (size: semi-axes) or "mesh" (file, scale); pose `point` [m] and `orientation` (3x3,
    shape -> ground) in ground at t=0; `role` "visual" or "collision"."""

    body: str
    kind: str
    size: tuple = ()
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))
    file: str | None = None
    scale: tuple = (1.0, 1.0, 1.0)
    role: str = "visual"
    name: str = ""


class Names:
    """Entity names for a model: the file's names where the model accepts them, else a close variant
    (a note says which); `None` names are generated as f"{prefix}_{k}"."""

    def __init__(self, notes: list):
        from ..model.loadexpr import reserved_names
        self.reserved = set(reserved_names()) | {"ground"}
        self.taken: set = set()
        self.notes = notes

    def take(self, name: str | None, prefix: str, expression: bool = True) -> str:
        """A free, valid name for `name` (an entity of kind `prefix`)."""
        base = name if name else f"{prefix}_{len(self.taken) + 1}"
        cand = base.replace(".", "_")
        if expression and cand in self.reserved:
            cand = f"{cand}_{prefix}"
        k = 2
        root = cand
        while cand in self.taken:
            cand = f"{root}_{k}"
            k += 1
        if name and cand != name:
            self.notes.append(f"{prefix} {name!r} is named {cand!r} in the model (the name is taken or not "
                              "valid there)")
        self.taken.add(cand)
        return cand


def _geometry(v: VisualShape):
    """The mbdsim geometry of a VisualShape (None for a mesh with unequal axis scales)."""
    import mbdsim as mb
    if v.kind == "box":
        return mb.Box(v.size)
    if v.kind == "sphere":
        return mb.Sphere(radius=v.size[0])
    if v.kind in ("cylinder", "capsule"):
        return (mb.Cylinder if v.kind == "cylinder" else mb.Capsule)(v.size[0], v.size[1], axis="z")
    if v.kind == "ellipsoid":
        return mb.Ellipsoid(v.size)
    if v.kind == "mesh" and v.file and len(set(float(x) for x in v.scale)) == 1:
        return mb.Mesh(v.file, scale=float(v.scale[0]))
    return None


def attach_shapes(model, visuals: list, notes: list) -> None:
    """Place each body's visual geometry (its collision geometry where it has no visual one) on the body
    with Body.add_shape (no density: the file's inertials stay the mass properties), so that the viewer
    draws the imported shapes; a shape that cannot be made (a mesh file missing or unreadable, unequal
    mesh scales) is a note, never a failure. Contacts are not created: Model.add_contact takes them."""
    drawn = {v.body for v in visuals if v.role == "visual"}
    for k, v in enumerate(visuals):
        if v.role != "visual" and v.body in drawn:
            continue
        body = model.ground if v.body == getattr(model.ground, "name", None) else model.bodies.get(v.body)
        if body is None:
            continue
        try:
            geom = _geometry(v)
            if geom is None:
                notes.append(f"shape {v.name or k!r} on {v.body!r}: not drawn (mesh scale {tuple(v.scale)})")
                continue
            body.add_shape(f"{v.role}_{k}", geom, center=v.point, orientation=v.orientation)
        except Exception as exc:  # noqa: BLE001 - a drawing only: noted, the import goes on
            notes.append(f"shape {v.name or k!r} on {v.body!r}: not drawn ({type(exc).__name__}: {exc})")


def is_identifier(name: str) -> bool:
    """Whether expressions can read a joint of this name (its coordinate and <name>_dot)."""
    return name.isidentifier()


def finish(model, notes: list, visuals: list, source: str, then=None) -> None:
    """Attach the notes and visual shapes to the model (`attach_shapes`: drawn by the viewer), run `then()`
    (the collision step, importers.collision) and warn once about the approximations."""
    attach_shapes(model, visuals, notes)
    if then is not None:
        then()
    model.import_notes = list(notes)
    model.visuals = list(visuals)
    model.source_file = source
    if notes:
        from .._userwarn import warn
        shown = "; ".join(notes[:8]) + (f"; ... ({len(notes) - 8} more in model.import_notes)"
                                        if len(notes) > 8 else "")
        warn(f"{source}: imported with approximations: {shown}", ImportApproximationWarning)

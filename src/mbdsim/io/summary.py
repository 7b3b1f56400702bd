"""Counts of a model for `mbdsim info` / `mbdsim run`: entities, drivers and the Gruebler mobility."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..model.joint_kinds import JOINT_KINDS

# from the joint-kind registry: constraints on the relative translation (what a particle feels), and the
# in-plane freedoms a joint leaves in a model flagged planar (3 per rigid body: two slides, one turn);
# kinds whose in-plane freedom depends on how they are placed are left out (no planar count then)
TRANSLATION_CONSTRAINTS = {n: k.translation_constraints for n, k in JOINT_KINDS.items()}
PLANAR_DOF = {n: k.planar_dof for n, k in JOINT_KINDS.items() if k.planar_dof is not None}


@dataclass
class ModelSummary:
    """Entity counts and Gruebler's (Kutzbach's) mobility 6 n_rigid + 3 n_particles - constraints (couplers
    and user constraints count one equation each); for a model flagged planar, `planar_dof` is the planar
    count 3 n_rigid + 2 n_particles - in-plane constraints (None when a joint kind has no fixed planar count)."""

    name: str
    bodies: list = field(default_factory=list)       # (name, kind, mass [kg])
    joints: list = field(default_factory=list)       # (name, kind, body_i, body_j, constraints)
    drivers: list = field(default_factory=list)      # (name, joint, kind, expression text)
    elements: list = field(default_factory=list)     # (name, kind)
    gruebler_dof: int = 0
    planar_dof: int | None = None


def joint_constraints(kind: str, particle: bool) -> int:
    """Equations a joint of `kind` removes (only the translational ones when a particle is involved)."""
    from ..model.joints import JOINT_DOF
    return TRANSLATION_CONSTRAINTS[kind] if particle else 6 - JOINT_DOF[kind]


def summarize(model) -> ModelSummary:
    """The ModelSummary of `model` (no analysis run)."""
    s = ModelSummary(model.name)
    mobility = 0
    for b in model.bodies.values():
        if b.is_ground:
            continue
        s.bodies.append((b.name, "particle" if b.is_particle else "body", float(b.mass)))
        mobility += 3 if b.is_particle else 6
    for j in model.joints.values():
        nc = joint_constraints(j.kind, j.body_i.is_particle or j.body_j.is_particle)
        s.joints.append((j.name, j.kind, j.body_i.name, j.body_j.name, nc))
        mobility -= nc
    for p in getattr(model, "path_constraints", {}).values():
        s.joints.append((p.name, "point_on_curve", p.marker.body.name, p.body.name, 2))   # 3 rows, 1 new coordinate
        mobility -= 2
    for c in getattr(model, "coord_constraints", {}).values():
        s.joints.append((c.name, c.kind, ", ".join(j.name for j, _ in c.terms), "", 1))
        mobility -= 1
    for m in model.motions.values():
        s.drivers.append((m.name, m.joint.name, m.kind, m.function.description))
        mobility -= 1
    for e in model.forces.values():
        s.elements.append((e.name, type(e).__name__))
    s.gruebler_dof = mobility
    if getattr(model, "planar", None) is not None:
        s.planar_dof = planar_mobility(model)
    return s


def planar_mobility(model) -> int | None:
    """3 per rigid body and 2 per particle, less each joint's in-plane constraints, couplers and drivers
    (None when a joint's in-plane freedom depends on its placement, or the model has curve paths)."""
    if getattr(model, "path_constraints", {}):
        return None
    mobility = sum(2 if b.is_particle else 3 for b in model.bodies.values() if not b.is_ground)
    for j in model.joints.values():
        if j.kind not in PLANAR_DOF:
            return None
        particle = j.body_i.is_particle or j.body_j.is_particle
        mobility -= (1 if j.kind == "translational" else 0 if j.kind == "planar" else 2) if particle \
            else 3 - PLANAR_DOF[j.kind]
    return mobility - len(getattr(model, "coord_constraints", {})) - len(model.motions)

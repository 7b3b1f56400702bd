"""URDF import: `from_urdf(path, ...)` builds an ordinary mbdsim Model from a robot description.

Mapping (docs/import.md has the full table):
  link            -> a body (position: its centre of mass; axes: the link frame; inertia rotated from the
                     inertial frame into the link frame); links joined by fixed joints are merged into
                     one body (mass properties combined; each merged link a marker of its name on it)
  revolute        -> revolute joint, limits -> a compliant two-sided stop
  continuous      -> revolute joint (no stop)
  prismatic       -> translational joint, limits -> stop
  planar          -> planar joint (normal = the axis);  floating -> no joint (a free body)
  fixed           -> merged (see link)
  mimic           -> coupler (x_mimic = multiplier x_ref, + offset: a user constraint)
  dynamics        -> damping: torsion damper / joint force; friction: Coulomb joint friction
  visual/collision-> model.visuals (VisualShape, meshes resolved through package:// and relative paths;
                     a missing mesh is a warning); with collision=True, collision geometry -> contact
                     shapes and IMPACT contacts between bodies not joined by a joint (importers.collision)
The root link is ground with floating_base=False (its mass, like that of links fixed to it, does not
move: a note says so), else a free body.  Joint coordinates are the file's joint positions: the model
is drawn at q = 0 and `initial_displacement` / `initial_velocity` {joint name: value} [rad or m, rad/s
or m/s] are held at assembly (other joints start at 0 and at rest).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError, ModelFileError
from ._common import (FRICTION_PIN_RADIUS, STOP_DAMPING, STOP_EXPONENT, STOP_PENETRATION, STOP_STIFFNESS,
                      ImportApproximationWarning, MassPart, Names, VisualShape, finish, is_identifier,
                      merge_mass)
from ._xml import read_xml, resolve_file
from .urdf_parse import parse_robot

_KIND = {"revolute": "revolute", "continuous": "revolute", "prismatic": "translational", "planar": "planar"}


def from_urdf(path, floating_base: bool = False, gravity=(0.0, 0.0, -9.81), initial_displacement: dict | None = None,
              initial_velocity: dict | None = None, package_dirs=(), collision: bool = False,
              contact: dict | None = None):
    """Build a Model from a URDF file (SI units; ground axes = the root link's frame at q = 0).

    floating_base: the root link moves freely (6 DOF) instead of being ground.  gravity [m/s^2] in ground
    axes.  initial_displacement / initial_velocity: {joint name: value} for revolute/continuous [rad,
    rad/s], prismatic [m, m/s] and planar ((u, v, angle) [m, m, rad]) joints, from the file's zero
    position; joints not named start at 0, at rest.  package_dirs: folders searched for package://
    meshes (also $ROS_PACKAGE_PATH and the folders above the file).  collision: each <collision>
    geometry also becomes a contact shape on its body, and each pair of them on two bodies that no joint
    joins gets a contact (Model.add_contact) with the IMPACT parameters `contact` (a dict of add_contact
    arguments; defaults importers.collision.DEFAULT_CONTACT, listed in import_notes).  Returns a Model whose
    `import_notes` lists what was approximated and `visuals` the shapes; errors are ModelFileError
    naming the file, line and element."""
    from ..model.model import Model
    notes: list = []
    doc = read_xml(path, "URDF file")
    robot = parse_robot(doc, notes)
    init_q = _by_joint(initial_displacement, "initial_displacement", robot, doc.source)
    init_v = _by_joint(initial_velocity, "initial_velocity", robot, doc.source)
    try:
        model = Model(robot.name, gravity=gravity)
    except ModelError as exc:
        raise ModelFileError("from_urdf", "gravity", str(exc), doc.source) from None
    poses = _link_poses(robot)
    head, order = _groups(robot, floating_base)
    names = Names(notes)
    body_of = _add_bodies(model, robot, poses, head, order, names, floating_base, notes)
    joint_of = _add_joints(model, robot, poses, body_of, names, init_q, init_v, notes)
    _add_mimics(model, robot, joint_of, init_q, notes)
    visuals = _visuals(robot, poses, body_of, Path(doc.source).resolve().parent, package_dirs)
    then = None
    if collision:
        from .collision import urdf_contacts
        then = lambda: urdf_contacts(model, robot, body_of, visuals, names, notes, contact)  # noqa: E731
    finish(model, notes, visuals, doc.source, then)
    return model


def _by_joint(values, field, robot, source) -> dict:
    if values is None:
        return {}
    if not isinstance(values, dict):
        raise ModelFileError("from_urdf", field, f"expected a dict {{joint name: value}}, got {type(values).__name__}",
                             source)
    for k in values:
        jt = robot.joints.get(k)
        if jt is None or jt.type in ("fixed", "floating"):
            movable = [n for n, j in robot.joints.items() if j.type not in ("fixed", "floating")]
            raise ModelFileError("from_urdf", field, f"{k!r} is not a movable joint of the file (joints: "
                                 f"{', '.join(movable[:20]) or 'none'})", source)
    return values


def _link_poses(robot) -> dict:
    """4x4 pose of every link frame in ground at q = 0 (ground = the root link frame)."""
    children: dict = {}
    for jt in robot.joints.values():
        children.setdefault(jt.parent, []).append(jt)
    poses, stack = {robot.root: np.eye(4)}, [robot.root]
    while stack:
        parent = stack.pop()
        for jt in children.get(parent, ()):
            poses[jt.child] = poses[parent] @ jt.origin
            stack.append(jt.child)
    return poses


def _groups(robot, floating_base) -> tuple[dict, list]:
    """(link -> the head link of its rigid group (None: ground), links in tree order)."""
    children: dict = {}
    for jt in robot.joints.values():
        children.setdefault(jt.parent, []).append(jt)
    head = {robot.root: robot.root if floating_base else None}
    order, stack = [robot.root], [robot.root]
    while stack:
        parent = stack.pop(0)
        for jt in children.get(parent, ()):
            head[jt.child] = head[parent] if jt.type == "fixed" else jt.child
            order.append(jt.child)
            stack.append(jt.child)
    return head, order


def _mass_part(link, pose) -> MassPart:
    T = pose @ link.inertial_origin
    R = T[:3, :3]
    return MassPart(link.mass, T[:3, 3].copy(), R @ link.inertia @ R.T)


def _add_bodies(model, robot, poses, head, order, names, floating_base, notes) -> dict:
    """Bodies of the rigid groups; returns link -> model Body (ground for the fixed root group)."""
    groups: dict = {}
    for lk in order:
        groups.setdefault(head[lk], []).append(lk)
    body_of = {}
    for h, members in groups.items():
        if h is None:
            body = model.ground
            moving = [m for m in members if robot.links[m].mass > 0]
            if moving:
                notes.append(f"link(s) {', '.join(moving)} fixed to ground (root {robot.root!r}, "
                             f"{sum(robot.links[m].mass for m in moving):g} kg) do not move: their mass does "
                             "not enter the dynamics")
        else:
            mp = merge_mass(_mass_part(robot.links[m], poses[m]) for m in members)
            R = poses[h][:3, :3]
            pos = mp.com if mp.mass > 0 else poses[h][:3, 3]
            if mp.mass <= 0:
                notes.append(f"link {h!r} has no mass (no <inertial>): a massless body")
            name = names.take(h, "link")
            fixed = floating_base and h == robot.root
            body = model.add_body(name, mass=mp.mass, inertia=R.T @ mp.inertia @ R, position=pos, orientation=R,
                                  velocity=(0, 0, 0) if fixed else None, angular_velocity=(0, 0, 0) if fixed else None)
        for m in members:
            body_of[m] = body
            if m != h:
                mk = m if m not in body.markers and "." not in m else f"{m.replace('.', '_')}_frame"
                body.add_marker(mk, poses[m][:3, 3], poses[m][:3, :3])
    return body_of


def _add_joints(model, robot, poses, body_of, names, init_q, init_v, notes) -> dict:
    """Model joints of the movable URDF joints (tree order) with their stops, dampers and friction."""
    joint_of = {}
    doc = robot.doc
    for jt in robot.joints.values():
        if jt.type == "fixed":
            continue
        bi, bj = body_of[jt.parent], body_of[jt.child]
        if jt.type == "floating":
            notes.append(f"floating joint {jt.name!r}: link {jt.child!r} is a free body (no joint)")
            continue
        T = poses[jt.child]
        axis = T[:3, :3] @ jt.axis
        kind = _KIND[jt.type]
        name = names.take(jt.name, "joint")
        x0 = init_q.get(jt.name)
        v0 = init_v.get(jt.name)
        zero = (0.0, 0.0, 0.0) if kind == "planar" else 0.0
        try:
            if jt.mimic is not None:    # a mimic joint's start follows its reference joint (_add_mimics)
                x0, v0 = None, None
            else:
                x0, v0 = zero if x0 is None else x0, zero if v0 is None else v0
            if kind == "planar":
                j = model.add_planar(name, bi, bj, T[:3, 3], axis, initial_displacement=x0, initial_velocity=v0)
            else:
                j = getattr(model, f"add_{kind}")(name, bi, bj, T[:3, 3], axis, initial_displacement=x0,
                                                  initial_velocity=v0)
            _joint_loads(model, jt, j, kind, notes)
        except ModelFileError:
            raise
        except ModelError as exc:
            raise ModelFileError(f"joint '{jt.name}'", exc.field, str(exc), doc.source, jt.line) from None
        joint_of[jt.name] = j
    return joint_of


def _joint_loads(model, jt, j, kind, notes) -> None:
    """Stops from <limit>, dampers and friction from <dynamics> on model joint `j`."""
    if jt.lower is not None and kind != "planar":
        model.add_stop(f"{j.name}_limit", j, lower=jt.lower, upper=jt.upper, stiffness=STOP_STIFFNESS,
                       exponent=STOP_EXPONENT, damping=STOP_DAMPING, penetration=STOP_PENETRATION)
        notes.append(f"joint {jt.name!r}: limits [{jt.lower:g}, {jt.upper:g}] are a compliant stop "
                     f"(stiffness {STOP_STIFFNESS:g}, exponent {STOP_EXPONENT:g})")
    if kind == "planar" and (jt.damping or jt.friction or jt.lower is not None):
        notes.append(f"planar joint {jt.name!r}: its limits, damping and friction are not imported")
        return
    if jt.damping > 0:
        if kind == "revolute":
            model.add_torsion_spring(f"{j.name}_damping", j, stiffness=0.0, damping=jt.damping)
        elif is_identifier(j.name):
            model.add_joint_force(f"{j.name}_damping", j, f"-({jt.damping!r})*{j.name}_dot")
        else:
            raise ModelError(f"joint '{jt.name}'", "dynamics", "prismatic damping is written as an expression "
                             "in the joint's rate, which needs a joint name that is an identifier")
    if jt.friction > 0:
        params = {"preload": jt.friction}
        if kind == "revolute":
            params["pin_radius"] = FRICTION_PIN_RADIUS
        model.add_friction(f"{j.name}_friction", j, 1.0, 1.0, **params)


def _add_mimics(model, robot, joint_of, init_q, notes) -> None:
    """<mimic>: x_j = multiplier * x_ref + offset, a coupler (or a user constraint with an offset)."""
    doc = robot.doc
    for jt in robot.joints.values():
        if jt.mimic is None or jt.name not in joint_of:
            continue
        ref, mult, off = jt.mimic
        entity = f"joint '{jt.name}'"
        if ref not in joint_of:
            raise ModelFileError(entity, "mimic", f"mimics {ref!r}, which is not a movable joint of the file",
                                 doc.source, jt.line)
        jr, jm = joint_of[ref], joint_of[jt.name]
        if jr.kind == "planar" or jm.kind == "planar":
            raise ModelFileError(entity, "mimic", "a planar joint cannot mimic or be mimicked", doc.source, jt.line)
        x_ref = float(np.ravel(jr.initial_displacement if jr.initial_displacement is not None else [0.0])[0])
        v_ref = float(np.ravel(jr.initial_velocity if jr.initial_velocity is not None else [0.0])[0])
        try:
            if off == 0.0:
                model.add_coupler(f"{jm.name}_mimic", jr, jm, mult)
            elif is_identifier(jr.name) and is_identifier(jm.name):
                model.add_user_constraint(f"{jm.name}_mimic", f"{jm.name} - ({mult!r})*{jr.name} - ({off!r})")
            else:
                raise ModelError(entity, "mimic", "a mimic with an offset is a constraint expression, which "
                                 "needs joint names that are identifiers")
        except ModelError as exc:
            raise ModelFileError(entity, "mimic", str(exc), doc.source, jt.line) from None
        if jt.name in init_q:
            notes.append(f"joint {jt.name!r} mimics {ref!r}: its initial_displacement is set by the mimic")
        jm.initial_displacement = np.array([mult * x_ref + off])
        jm.initial_velocity = np.array([mult * v_ref])


def _visuals(robot, poses, body_of, base, package_dirs) -> list:
    """VisualShape of every visual and collision geometry (ground pose at q = 0)."""
    from .._userwarn import warn
    out = []
    for lk in robot.links.values():
        body = body_of[lk.name]
        for g in lk.geometries:
            T = poses[lk.name] @ g.origin
            f = None
            if g.kind == "mesh":
                found = resolve_file(g.file, base, package_dirs)
                if found is None:
                    warn(f"{robot.doc.source}, line {g.line}: link {lk.name!r}: mesh {g.file!r} not found "
                         "(searched package_dirs, $ROS_PACKAGE_PATH, the folders above the file); "
                         "it is not drawn", ImportApproximationWarning)
                    continue
                f = str(found)
            out.append(VisualShape(body.name, g.kind, g.size, T[:3, 3].copy(), T[:3, :3].copy(), f, g.scale,
                                   g.role, lk.name))
    return out

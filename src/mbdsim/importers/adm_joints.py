"""JOINT, JPRIM, COUPLER, GEAR and MOTION statements of an .adm dataset -> mbdsim joints, couplers and
motions between marker pairs.

Adams measures a joint's motion as the I marker's relative to the J marker: the mbdsim joint is built
between the J marker (its marker_i, on body_i) and the I marker (marker_j, on body_j), so that
Result.joint_coordinate, motions and couplers read Adams' sign and zero (markers coincident).
HOOKE uses the crosspin axes x_I and y_J, CONVEL the shafts z_I and -z_J (Adams points both away from
the centre).  SCREW next to a CYLINDRICAL joint between the same parts is a coupler of the
cylindrical joint's angle and slide (PITCH per turn); alone it is mbdsim's screw joint (which also
holds the axis).  RACKPIN and GEAR become couplers of the joints that carry the two parts, the ratio
from the pitch point's velocity (the CV marker; for RACKPIN the J marker and PD).
"""
from __future__ import annotations

from math import pi

import numpy as np

from ..errors import ModelError

SIMPLE = {"REVOLUTE": "add_revolute", "TRANSLATIONAL": "add_translational", "CYLINDRICAL": "add_cylindrical",
          "SPHERICAL": "add_spherical", "PLANAR": "add_planar", "FIXED": "add_fixed", "UNIVERSAL": "add_universal"}
OTHER = ("HOOKE", "CONVEL", "SCREW", "RACKPIN")
PRIMITIVES = {"INLINE": "add_inline", "INPLANE": "add_inplane", "ORIENTATION": "add_orientation",
              "PARALLEL_AXES": "add_parallel_axes", "PERPENDICULAR": "add_perpendicular", "ATPOINT": "add_atpoint"}
WITH_IC = ("REVOLUTE", "TRANSLATIONAL", "CYLINDRICAL")


def _kind(imp, st, fl, kinds):
    given = [f for f in fl if f in kinds]
    if len(given) != 1:
        imp.fail(st, "type", f"give exactly one type of {st.name} ({', '.join(kinds)}); got "
                 f"{', '.join(given) or 'none'}")
    return given[0]


def _derived(body, marker, R, tag):
    """A marker at `marker`'s origin with axes R (ground), on the same body."""
    name, k = f"{marker.name}_{tag}", 2
    while name in body.markers:
        name, k = f"{marker.name}_{tag}{k}", k + 1
    return body.add_marker(name, marker.point, R)


def joint(imp, st, later: list) -> None:
    """JOINT/id, I=, J=, one of REVOLUTE ... CONVEL [, ICROT=, ICTRAN=, PD=, PITCH=]."""
    a, fl = imp.args(st, ("I", "J", "PD", "PITCH", "ICROT", "ICTRAN"), tuple(SIMPLE) + OTHER)
    kind = _kind(imp, st, fl, tuple(SIMPLE) + OTHER)
    mi, mj = imp.marker(st, a, "I"), imp.marker(st, a, "J")
    if kind in ("SCREW", "RACKPIN"):
        later.append((st, kind, a, mi, mj))   # after the joints they couple
        return
    name = imp.name(st, f"JOINT_{st.id}")
    kw = _initial(imp, st, a, kind)
    try:
        if kind in SIMPLE:
            jt = getattr(imp.model, SIMPLE[kind])(name, mj, mi, **kw)
        elif kind == "HOOKE":   # crosspin: x of I, y of J
            Rj, Ri = mj.orientation, mi.orientation
            mj2 = _derived(mj.body, mj, np.column_stack([Rj[:, 2], Rj[:, 0], Rj[:, 1]]), "hooke")
            mi2 = _derived(mi.body, mi, np.column_stack([Ri[:, 1], Ri[:, 2], Ri[:, 0]]), "hooke")
            jt = imp.model.add_universal(name, mj2, mi2)
        else:                   # CONVEL: I's shaft turned to point on through the joint
            mi2 = _derived(mi.body, mi, mi.orientation @ np.diag([1.0, -1.0, -1.0]), "shaft")
            jt = imp.model.add_constant_velocity(name, mj, mi2)
    except ModelError as exc:
        imp.model_error(st, exc)
    imp.joints[st.id] = jt


def _initial(imp, st, a, kind):
    """initial_displacement / initial_velocity from ICROT and ICTRAN (displacement[, velocity])."""
    if "ICROT" not in a and "ICTRAN" not in a:
        return {}
    if kind not in WITH_IC:
        imp.fail(st, "ICROT" if "ICROT" in a else "ICTRAN", f"initial conditions of a {kind} joint are not supported")
    rot = imp.nums(st, a, "ICROT", None, None, "angle")
    tra = imp.nums(st, a, "ICTRAN", None, None, "length")
    if rot and len(rot) > 1:
        rot = [rot[0], rot[1] / imp.units.time]
    if tra and len(tra) > 1:
        tra = [tra[0], tra[1] / imp.units.time]
    parts = {"REVOLUTE": [rot], "TRANSLATIONAL": [tra], "CYLINDRICAL": [rot, tra]}[kind]
    if any(p is None for p in parts):
        imp.note(st, "a coordinate without ICROT/ICTRAN starts as drawn")
        parts = [p or [0.0] for p in parts]
    disp = [p[0] for p in parts]
    vel = [p[1] if len(p) > 1 else None for p in parts]
    kw = {"initial_displacement": disp[0] if len(disp) == 1 else disp}
    if all(v is not None for v in vel):
        kw["initial_velocity"] = vel[0] if len(vel) == 1 else vel
    return kw


def jprim(imp, st) -> None:
    """JPRIM/id, I=, J=, one of INLINE, INPLANE, ORIENTATION, PARALLEL_AXES, PERPENDICULAR, ATPOINT."""
    a, fl = imp.args(st, ("I", "J"), tuple(PRIMITIVES))
    kind = _kind(imp, st, fl, tuple(PRIMITIVES))
    mi, mj = imp.marker(st, a, "I"), imp.marker(st, a, "J")
    try:
        imp.joints[("JPRIM", st.id)] = getattr(imp.model, PRIMITIVES[kind])(imp.name(st, f"JPRIM_{st.id}"), mj, mi)
    except ModelError as exc:
        imp.model_error(st, exc)


def screw_rackpin(imp, st, kind, a, mi, mj) -> None:
    """SCREW (a coupler beside a cylindrical joint, else mbdsim's screw joint) and RACKPIN (a coupler)."""
    name = imp.name(st, f"JOINT_{st.id}")
    try:
        if kind == "SCREW":
            lead = imp.num(st, a, "PITCH", None, "length")
            if lead is None:
                imp.fail(st, "PITCH", "is required for a SCREW joint")
            cyl = [j for j in imp.joints.values() if j.kind == "cylindrical" and
                   {j.body_i.name, j.body_j.name} == {mi.body.name, mj.body.name}]
            if cyl:
                imp.model.add_coupler(name, cyl[0], cyl[0], lead / (2 * pi), dof_1="rotation", dof_2="translation")
                return
            imp.note(st, "SCREW without a CYLINDRICAL joint between its parts: mbdsim's screw joint, which also "
                     "keeps the axes aligned")
            imp.joints[st.id] = imp.model.add_screw(name, mj, mi, lead=lead)
            return
        pd = imp.num(st, a, "PD", None, "length")
        if pd is None:
            imp.fail(st, "PD", "is required for a RACKPIN joint")
        rev = _carrier_joint(imp, mi.body, "revolute")
        tra = _carrier_joint(imp, mj.body, "translational", other=_other(rev, mi.body) if rev else None)
        if rev is None or tra is None:
            imp.fail(st, "I", "RACKPIN is read as a coupler: it needs a REVOLUTE joint carrying the pinion (I part) "
                     "and a TRANSLATIONAL joint carrying the rack (J part) on a common part")
        axis = rev.axis
        r = mj.point - rev.point
        r = r - (r @ axis) * axis
        u = r / np.linalg.norm(r) if np.linalg.norm(r) > 1e-12 else -mj.orientation[:, 0]
        z = mj.orientation[:, 2]
        g1 = _sign(rev, mi.body) * (np.cross(axis, 0.5 * pd * u) @ z)
        g2 = _sign(tra, mj.body) * (tra.axis @ z)
        imp.model.add_coupler(name, rev, tra, g1 / g2)
        imp.note(st, "RACKPIN read as a coupler of the pinion's revolute and the rack's translational joint")
    except ModelError as exc:
        imp.model_error(st, exc)


def _other(jt, body):
    return jt.body_i if jt.body_j is body else jt.body_j


def _sign(jt, body):
    """+1 when `body` is the moving side (body_j) of the joint, -1 when it is body_i."""
    return 1.0 if jt.body_j is body else -1.0


def _carrier_joint(imp, body, kind, other=None):
    for jt in imp.joints.values():
        if jt.kind == kind and body in (jt.body_i, jt.body_j) and (other is None or _other(jt, body) is other):
            return jt
    return None


def coupler(imp, st) -> None:
    """COUPLER/id, JOINTS=j1,j2[,j3], TYPE=R:T..., SCALES=s1,s2[,s3]: s1 x1 + s2 x2 (+ s3 x3) = 0."""
    a, _ = imp.args(st, ("JOINTS", "TYPE", "SCALES"), ignored=("FUNCTION",))
    ids = imp.nums(st, a, "JOINTS")
    if ids is None or len(ids) not in (2, 3):
        imp.fail(st, "JOINTS", "expected 2 or 3 joint ids")
    joints = []
    for k in ids:
        if int(k) not in imp.joints:
            imp.fail(st, "JOINTS", f"no JOINT/{int(k)} in the dataset", a["JOINTS"].line)
        joints.append(imp.joints[int(k)])
    types = a["TYPE"].values[0].upper().split(":") if "TYPE" in a else [None] * len(joints)
    if len(types) != len(joints) or any(t not in (None, "R", "T") for t in types):
        imp.fail(st, "TYPE", f"expected {len(joints)} of R and T separated by ':'", a["TYPE"].line)
    dofs = [None if t is None else ("rotation" if t == "R" else "translation") for t in types]
    scales = imp.nums(st, a, "SCALES", None, [1.0] + [-1.0] * (len(joints) - 1))
    if len(scales) != len(joints) or any(s == 0.0 for s in scales):
        imp.fail(st, "SCALES", f"expected {len(joints)} non-zero scales")
    units = [imp.units.length if _is_slide(j, d) else 1.0 for j, d in zip(joints, dofs)]
    name = imp.name(st, f"COUPLER_{st.id}")
    try:
        if len(joints) == 2:
            ratio = -scales[0] / scales[1] * units[1] / units[0]
            imp.model.add_coupler(name, joints[0], joints[1], ratio, dof_1=dofs[0], dof_2=dofs[1])
        else:
            terms = " + ".join(f"({s!r})*{j.name}/{u!r}" for s, j, u in zip(scales, joints, units))
            imp.model.add_user_constraint(name, terms)
    except ModelError as exc:
        imp.model_error(st, exc)


def _is_slide(jt, dof):
    return dof == "translation" or (dof is None and jt.kind == "translational")


def gear(imp, st) -> None:
    """GEAR/id, JOINTS=j1,j2, CV=marker: the pitch point (CV origin, common velocity along its z) moves
    alike on both gears: a coupler x2 = (g1/g2) x1 from the geometry at t=0."""
    a, _ = imp.args(st, ("JOINTS", "CV"))
    ids = imp.nums(st, a, "JOINTS", 2)
    if ids is None:
        imp.fail(st, "JOINTS", "is required (two joint ids)")
    cv = imp.marker(st, a, "CV")
    joints = []
    for k in ids:
        jt = imp.joints.get(int(k))
        if jt is None or jt.kind not in ("revolute", "translational", "cylindrical"):
            imp.fail(st, "JOINTS", f"JOINT/{int(k)} must be a revolute, translational or cylindrical joint in the "
                     "dataset", a["JOINTS"].line)
        joints.append(jt)
    z, p = cv.orientation[:, 2], cv.point
    g = []
    for jt in joints:
        s = -1.0 if jt.body_j is cv.body else 1.0     # the carrier (CV's part) is the reference side
        g.append(s * (jt.axis @ z if jt.kind == "translational" else np.cross(jt.axis, p - jt.point) @ z))
    if abs(g[1]) < 1e-12 * max(1.0, abs(g[0])):
        imp.fail(st, "CV", "the CV marker's z axis gives no velocity for the second joint (check its placement)")
    name = imp.name(st, f"GEAR_{st.id}")
    try:
        add = imp.model.add_gear if all(j.kind == "revolute" for j in joints) else imp.model.add_coupler
        add(name, joints[0], joints[1], g[0] / g[1])
    except ModelError as exc:
        imp.model_error(st, exc)


def motion(imp, st) -> None:
    """MOTION/id, JOINT=, ROTATION|TRANSLATION, DISPLACEMENT|VELOCITY|ACCELERATION, FUNCTION= (of TIME)
    [, ICDISP=, ICVEL=]."""
    a, fl = imp.args(st, ("JOINT", "FUNCTION", "ICDISP", "ICVEL", "I", "J"),
                     ("ROTATION", "TRANSLATION", "DISPLACEMENT", "VELOCITY", "ACCELERATION", "B1", "B2", "B3",
                      "X", "Y", "Z"))
    if "JOINT" not in a:
        imp.fail(st, "I" if "I" in a else "JOINT", "only joint motions (JOINT=id) are supported; a motion between "
                 "two markers (I, J with X/Y/Z/B1/B2/B3) is not")
    jid = imp.ident(st, a, "JOINT")
    jt = imp.joints.get(jid)
    if jt is None:
        imp.fail(st, "JOINT", f"no JOINT/{jid} in the dataset", a["JOINT"].line)
    dof = "translation" if "TRANSLATION" in fl else "rotation" if "ROTATION" in fl else \
        ("translation" if jt.kind == "translational" else "rotation")
    kind = "velocity" if "VELOCITY" in fl else "acceleration" if "ACCELERATION" in fl else "displacement"
    base = "length" if dof == "translation" else "angle"
    q = {("length", "displacement"): "length", ("length", "velocity"): "velocity",
         ("length", "acceleration"): "acceleration", ("angle", "displacement"): "angle",
         ("angle", "velocity"): "angular_velocity", ("angle", "acceleration"): "angular_acceleration"}[(base, kind)]
    text = imp.expression(st, a, "FUNCTION", q, time_name="t")
    x0 = imp.num(st, a, "ICDISP", 0.0, base)
    v0 = imp.num(st, a, "ICVEL", 0.0, "velocity" if base == "length" else "angular_velocity")
    try:
        imp.model.add_motion(imp.name(st, f"MOTION_{st.id}"), jt, **{kind: text}, initial_displacement=x0,
                             initial_velocity=v0, dof=dof if jt.kind == "cylindrical" else None)
    except ModelError as exc:
        imp.model_error(st, exc, a["FUNCTION"].line)

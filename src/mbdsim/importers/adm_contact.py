"""Adams CONTACT and the GRAPHICS it collides (issue 31): ELLIPSOID (a sphere for equal scales), PLANE,
BOX, CYLINDER, FRUSTUM with equal radii (a cylinder), EXTERNAL mesh files -> shapes on the parts
(Body.add_shape, no mass added) and Model.add_contact with the IMPACT or POISSON law and Adams' Coulomb
friction.  A GRAPHICS statement is read when a CONTACT uses it: one only drawn in Adams is never checked.

Adams conventions: ELLIPSOID's XSCALE/YSCALE/ZSCALE are diameters along CM's axes; BOX's X, Y, Z are
lengths from the CORNER marker along its axes (a negative length goes the other way); CYLINDER's and
FRUSTUM's CM marker is at the centre of the bottom circle, the solid extending LENGTH along CM's z (a
negative LENGTH along -z); EXTERNAL's FILE is relative to the dataset, its coordinates in the dataset's
length unit in RM's axes; PLANE is RM's xy plane (solid below, normal +z)."""
from __future__ import annotations

import os

import numpy as np

from ..errors import ModelError

KINDS = ("ELLIPSOID", "PLANE", "CYLINDER", "BOX", "FRUSTUM", "EXTERNAL")


def graphics(imp, st, table: dict) -> None:
    """GRAPHICS/id: its arguments are checked for spelling now, kept for CONTACT (see the module)."""
    a, fl = imp.args(st, ("CM", "RM", "XSCALE", "YSCALE", "ZSCALE", "XMIN", "XMAX", "YMIN", "YMAX", "CORNER", "X",
                          "Y", "Z", "LENGTH", "RADIUS", "RANGE", "SIDES", "SEG", "TOP", "BOTTOM", "CRM", "FILE",
                          "SCALE", "ELEMENT", "CID", "CSEG", "ETYPE", "EMARKER", "FORCE", "EID", "ANGLE",
                          "MINOR_RADIUS", "MAJOR_RADIUS", "RECTANGLE"),
                     ("ELLIPSOID", "PLANE", "CYLINDER", "BOX", "FRUSTUM", "CIRCLE", "ARC", "OUTLINE", "POINT",
                      "TORUS", "EXTERNAL", "CURVE", "SPDP", "DEFAULT"))
    kind = next((k for k in KINDS if k in fl), None)
    table[st.id] = {"st": st, "args": a, "kind": kind, "shape": None}


def _required(imp, st, a, key):
    v = imp.num(st, a, key, None, "length")
    if v is None:
        imp.fail(st, key, "is required for this GRAPHICS (a length)")
    return v


def _positive(imp, st, a, key, v):
    if not v > 0:
        imp.fail(st, key, f"must be > 0, got {v!r} (SI)", a[key].line)
    return v


def build(imp, g: dict):
    """The mbdsim shape of a GRAPHICS entry (made once; ModelFileError naming the GRAPHICS line)."""
    import mbdsim as mb
    if g["shape"] is not None:
        return g["shape"]
    st, a, kind = g["st"], g["args"], g["kind"]
    name = f"GRAPHICS_{st.id}"
    try:
        if kind == "PLANE":
            m = imp.marker(st, a, "RM")
            shape = mb.Plane(m.body, m.point, m.orientation[:, 2])
        elif kind == "ELLIPSOID":
            m = imp.marker(st, a, "CM")
            d = [_positive(imp, st, a, k, _required(imp, st, a, k)) for k in ("XSCALE", "YSCALE", "ZSCALE")]
            if max(d) - min(d) <= 1e-12 * max(d):
                shape = mb.Sphere(m.body, 0.5 * d[0], m.point)   # the exact sphere contact
            else:
                shape = m.body.add_shape(name, mb.Ellipsoid(0.5 * np.array(d)), m.point, m.orientation)
        elif kind == "BOX":
            m = imp.marker(st, a, "CORNER")
            x = np.array([_required(imp, st, a, k) for k in ("X", "Y", "Z")])
            for k, v in zip("XYZ", x):
                if v == 0:
                    imp.fail(st, k, "must not be 0", a[k].line)
            centre = m.point + m.orientation @ (0.5 * x)
            shape = m.body.add_shape(name, mb.Box(np.abs(x)), centre, m.orientation)
        elif kind in ("CYLINDER", "FRUSTUM"):
            m = imp.marker(st, a, "CM")
            length = _required(imp, st, a, "LENGTH")
            if length == 0:
                imp.fail(st, "LENGTH", "must not be 0", a["LENGTH"].line)
            if kind == "CYLINDER":
                r = _positive(imp, st, a, "RADIUS", _required(imp, st, a, "RADIUS"))
            else:
                top, bottom = (_positive(imp, st, a, k, _required(imp, st, a, k)) for k in ("TOP", "BOTTOM"))
                if abs(top - bottom) > 1e-12 * max(top, bottom):
                    imp.fail(st, "TOP", f"a FRUSTUM collides only as a cylinder (TOP = BOTTOM); got TOP {top!r}, "
                             f"BOTTOM {bottom!r} (SI)", a["TOP"].line)
                r = bottom
            centre = m.point + m.orientation[:, 2] * (0.5 * length)
            shape = m.body.add_shape(name, mb.Cylinder(r, abs(length), axis="z"), centre, m.orientation)
        elif kind == "EXTERNAL":
            m = imp.marker(st, a, "RM", required=False) or imp.marker(st, a, "CM")
            f = a.get("FILE")
            if f is None:
                imp.fail(st, "FILE", "is required for GRAPHICS EXTERNAL")
            rel = f.values[0].strip().strip("'\"")
            path = rel if os.path.isabs(rel) else os.path.join(imp.folder, rel)
            if not os.path.isfile(path):
                imp.fail(st, "FILE", f"no such mesh file {rel!r} (looked for {path})", f.line)
            mesh = mb.Mesh(path, scale=imp.units.length)
            shape = m.body.add_shape(name, mesh, m.point, m.orientation)
        else:
            imp.fail(st, "kind", "mbdsim collides GRAPHICS ELLIPSOID, PLANE, BOX, CYLINDER, FRUSTUM (equal radii) "
                     "and EXTERNAL (mesh FILE); this one is none of them")
    except ModelError as exc:
        if type(exc).__name__ == "ModelFileError":
            raise
        imp.model_error(st, exc)
    g["shape"] = shape
    return shape


def contact(imp, st, table: dict) -> None:
    """CONTACT/id, IGEOM=, JGEOM=, IMPACT (STIFFNESS EXPONENT DAMPING DMAX) or POISSON (PENALTY
    RESTITUTION_COEFFICIENT), COULOMB_FRICTION=ON (MU_STATIC MU_DYNAMIC STICTION_TRANSITION_VELOCITY
    FRICTION_TRANSITION_VELOCITY) -> Model.add_contact between the two GRAPHICS' shapes."""
    a, fl = imp.args(st, ("IGEOM", "JGEOM", "STIFFNESS", "DAMPING", "DMAX", "EXPONENT", "MU_STATIC", "MU_DYNAMIC",
                          "COULOMB_FRICTION", "STICTION_TRANSITION_VELOCITY", "FRICTION_TRANSITION_VELOCITY",
                          "PENALTY", "RESTITUTION_COEFFICIENT"),
                     ("IMPACT", "POISSON"), ignored=("AUGMENTED_LAGRANGIAN_FORMULATION",))
    shapes = []
    for key in ("IGEOM", "JGEOM"):
        gid = imp.ident(st, a, key)
        g = table.get(gid)
        if g is None:
            imp.fail(st, key, f"no GRAPHICS/{gid} in the dataset", a[key].line)
        shapes.append(build(imp, g))
    opts = {}
    if "POISSON" in fl:
        k = imp.num(st, a, "PENALTY", None, "stiffness")
        if k is None:
            imp.fail(st, "PENALTY", "is required for POISSON")
        e, c = 1.0, 0.0
        opts["restitution"] = imp.num(st, a, "RESTITUTION_COEFFICIENT", None)
        if opts["restitution"] is None:
            imp.fail(st, "RESTITUTION_COEFFICIENT", "is required for POISSON")
    else:
        e = imp.num(st, a, "EXPONENT", 1.0)
        k = imp.num(st, a, "STIFFNESS", None)
        if k is None:
            imp.fail(st, "STIFFNESS", "is required")
        k *= imp.units.force / imp.units.length ** e
        c = imp.num(st, a, "DAMPING", 0.0, "damping")
    d = imp.num(st, a, "DMAX", 1e-3 / imp.units.length, "length")
    if "COULOMB_FRICTION" in a and a["COULOMB_FRICTION"].values[0].upper() == "ON":
        md = imp.num(st, a, "MU_DYNAMIC", None)
        if md is None:
            imp.fail(st, "MU_DYNAMIC", "is required with COULOMB_FRICTION = ON")
        opts.update(mu_static=imp.num(st, a, "MU_STATIC", md), mu_dynamic=md,
                    stiction_velocity=imp.num(st, a, "STICTION_TRANSITION_VELOCITY", None, "velocity"),
                    transition_velocity=imp.num(st, a, "FRICTION_TRANSITION_VELOCITY", None, "velocity"))
        if opts["stiction_velocity"] is None or opts["transition_velocity"] is None:
            imp.note(st, "transition velocities not given: mbdsim's defaults (stiction 1e-4 m/s, transition 10 "
                     "times it), not Adams'")
    try:
        imp.model.add_contact(imp.name(st, f"CONTACT_{st.id}"), shapes[0], shapes[1], k, e, c, d, **opts)
    except ModelError as exc:
        imp.model_error(st, exc)

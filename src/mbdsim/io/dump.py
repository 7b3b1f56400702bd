"""Model -> plain data in the model-file schema (SI numbers only), the inverse of mbdsim.io.build.

Callables cannot be stored: a motion, load or curve given as a Python function raises ModelError
naming the element.  The output is canonical: building it and dumping again gives the same dict.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError



def _vec(v) -> list:
    return [float(x) for x in np.asarray(v, dtype=float).reshape(-1)]


def _unit(v) -> list:
    """A vector whose normalisation (as the API does it) gives exactly the stored unit vector `v`."""
    v = np.asarray(v, dtype=float)
    for k in (0, 1, -1, 2, -2, 3, -3, 4, -4):   # scaling by 1 + k ulp; the first whose normalisation is v
        c = v * (1.0 + k * 2.0 ** -53)
        if np.array_equal(c / np.linalg.norm(c), v):
            return _vec(c)
    for i in range(3):       # one component nudged by one ulp
        for d in (-1, 1):
            c = v.copy()
            c[i] = np.nextafter(c[i], d * np.inf)
            if np.array_equal(c / np.linalg.norm(c), v):
                return _vec(c)
    return _vec(v)


def _rounded(x: float, scale: float) -> float:
    """x rounded to 13 significant digits of `scale` (undoes the rounding of a body-axes round trip)."""
    digits = 13 - int(math.floor(math.log10(max(abs(scale), 1e-300))))
    return float(round(x, digits)) + 0.0


def _matrix(R) -> list | None:
    return None if np.array_equal(R, np.eye(3)) else [_vec(row) for row in R]


def _inertia(J):
    return _vec(np.diag(J)) if np.array_equal(J, np.diag(np.diag(J))) else [_vec(row) for row in J]


def _dof(joint, dof, loads=False):
    """`dof` ("rotation"/"translation") when the joint's kind has another default, else None (left out)."""
    from ..model.joint_kinds import axis_dofs
    allowed = axis_dofs(joint.kind, loads)
    return dof if len(allowed) > 1 and dof != allowed[0] else None


def _put(d: dict, key, value, default=None):
    if value is not None and value != default:
        d[key] = value
    return d


def _marker_ref(m):
    """'body.marker' for a marker registered on its body, else {body, point}."""
    if m.body.markers.get(m.name) is m:
        return f"{m.body.name}.{m.name}"
    return {"body": m.body.name, "point": _vec(m.point)}


def _frame_ref(entity, frame):
    if frame is None:
        return None
    if hasattr(frame, "markers"):   # a Body
        return frame.name
    if frame.body.markers.get(frame.name) is frame:
        return f"{frame.body.name}.{frame.name}"
    raise ModelError(entity, "frame", "only a body or one of its named markers can be stored as a frame")


def _markers(body) -> list:
    out = []
    for m in body.markers.values():
        out.append(_put({"name": m.name, "point": _vec(m.point)}, "orientation", _matrix(m.orientation)))
    return out


def _given(b, field):
    """A body's velocity / angular_velocity when the user gave it (held at assembly), else None (free)."""
    return _vec(getattr(b, field)) if getattr(b, field + "_given", True) else None


def _body(b, base_dir=None) -> dict:
    from .dump_shapes import base_mass, shapes
    mass, inertia, with_density = base_mass(b)   # the shapes with a density add theirs on loading
    if b.is_particle:
        d = {"name": b.name, "mass": float(mass), "position": _vec(b.position)}
        _put(d, "velocity", _given(b, "velocity"))
    else:
        d = {"name": b.name, "mass": float(mass), "inertia": _inertia(inertia), "position": _vec(b.position)}
        _put(d, "orientation", _matrix(b.orientation))
        _put(d, "velocity", _given(b, "velocity"))
        _put(d, "angular_velocity", _given(b, "angular_velocity"))
    _put(d, "markers", _markers(b), [])
    return _put(d, "shapes", shapes(b, base_dir, with_density, _vec, _unit, _matrix), [])


def _joint_values(j, field):
    """A joint's initial_displacement / initial_velocity as given (a number for one coordinate), else None."""
    v = getattr(j, field)
    if v is None:
        return None
    return float(v[0]) if j.ncoord == 1 else _vec(v)


def _joint(j) -> dict:
    d = _marker_joint(j) if j.marker_i is not None else _body_joint(j)
    _put(d, "initial_displacement", _joint_values(j, "initial_displacement"))
    return _put(d, "initial_velocity", _joint_values(j, "initial_velocity"))


def _marker_joint(j) -> dict:
    """A joint between two markers: "body.marker" as body_i and body_j, no point or axes (as the API)."""
    refs = []
    for field, m in (("body_i", j.marker_i), ("body_j", j.marker_j)):
        if m.body.markers.get(m.name) is not m:
            raise ModelError(f"joint '{j.name}'", field, "a marker not added to its body (Body.add_marker) "
                             "cannot be stored in a model file")
        refs.append(f"{m.body.name}.{m.name}")
    return _put({"name": j.name, "type": j.kind, "body_i": refs[0], "body_j": refs[1]}, "lead", j.lead)


def _body_joint(j) -> dict:
    d = {"name": j.name, "type": j.kind, "body_i": j.body_i.name, "body_j": j.body_j.name, "point": _vec(j.point)}
    if j.kind in ("orientation", "parallel_axes", "perpendicular"):   # primitives without a point
        del d["point"]
    if j.kind in ("revolute", "translational", "cylindrical", "inline", "parallel_axes", "screw"):
        d["axis"] = _unit(j.axis)
        _put(d, "lead", j.lead)
    elif j.kind == "inplane":
        d["normal"] = _unit(j.axis)
    elif j.kind in ("perpendicular", "constant_velocity"):
        d.update(axis_i=_unit(j.axis), axis_j=_unit(j.axis_j))
    elif j.kind == "universal":
        d.update(axis_i=_unit(j.axis), axis_j=_unit(j.axis_j))
    elif j.kind == "planar":
        d.update(normal=_unit(j.axis), u_axis=_unit(j.u_axis))
    return d


def _curve(entity, curve) -> dict:
    from ..model.curves import Spline
    if isinstance(curve, Spline):
        pts = curve.points[:-1] if curve.closed else curve.points
        return {"type": "spline", "points": [_vec(p) for p in pts], "closed": curve.closed}
    if getattr(curve, "expressions", None) is not None:
        x, y, z = (e.text for e in curve.expressions)
        return {"type": "curve", "x": x, "y": y, "z": z, "s_range": _vec(curve.s_range), "closed": curve.closed}
    raise ModelError(entity, "curve", "a curve given as a Python callable cannot be stored in a model file; "
                     "use mb.Spline or expression strings of s in the file")


def _path(pc) -> dict:
    entity = f"joint '{pc.name}'"
    return {"name": pc.name, "type": "point_on_curve", "marker": _marker_ref(pc.marker), "body": pc.body.name,
            "curve": _curve(entity, pc.curve)}


def _source(entity, field, tf):
    """The number or expression text a TimeFunction was made from, else ModelError (a callable)."""
    from ..timefunctions import _Constant
    if getattr(tf, "symbolic", None) is not None:   # a driver reading model inputs: its text as given
        return tf.symbolic.text
    if tf.expr is not None:
        return tf.expr.text
    if isinstance(tf.f, _Constant):
        return tf.f.c
    raise ModelError(entity, field, "a Python callable cannot be stored in a model file; "
                     "use a number or an expression string in t")


def _motion(m) -> dict:
    entity, tf = f"motion '{m.name}'", m.function
    d = {"name": m.name, "joint": m.joint.name}
    if m.kind == "displacement":
        d["displacement"] = _source(entity, "displacement", tf)
    else:
        d[m.kind] = _source(entity, m.kind, m.given)
        d["initial_displacement"] = float(m.initial[0])
        if m.kind == "acceleration":
            d["initial_velocity"] = float(m.initial[1])
    return _put(d, "dof", _dof(m.joint, m.dof))


def _constant(entity, field, value):
    """A load as stored: numbers, or the expression texts of components written as expressions."""
    from ..model.loadexpr import ExprVector, LoadExpr, load_text
    if isinstance(value, (ExprVector, LoadExpr)):
        return load_text(value)
    if callable(value):
        raise ModelError(entity, field, "a Python callable cannot be stored in a model file; "
                         "use a constant or an expression string of time and state")
    return _vec(value) if np.ndim(value) else float(value)


def _force(f) -> dict:
    entity = f"force '{f.name}'"
    b = f.body
    at = next((f"{b.name}.{m.name}" for m in b.markers.values() if np.array_equal(m.s_B, f.s_B)), None)
    if at is None:
        p = b.position + b.orientation @ f.s_B
        scale = max(1.0, float(np.abs(b.position).max()), float(np.abs(p).max()))
        at = {"body": b.name, "point": [_rounded(x, scale) for x in p]}
    d = {"name": f.name, "type": "force", "at": at, "force": _constant(entity, "force", f.force)}
    return _put(d, "frame", _frame_ref(entity, f.frame))


def _torque(t) -> dict:
    entity = f"torque '{t.name}'"
    d = {"name": t.name, "type": "torque", "body": t.body.name, "torque": _constant(entity, "torque", t.torque)}
    return _put(d, "frame", _frame_ref(entity, t.frame))


def _shape(s) -> dict:
    src, body = s.source, s.body.name
    if s.kind == "sphere":
        d = {"type": "sphere", "body": body, "radius": float(src.radius)}
        return _put(d, "center", None if src.center is None else _vec(src.center))
    return {"type": "plane", "body": body, "point": _vec(src.point), "normal": _unit(src.normal)}


def _element(e) -> dict:
    from ..model.element_specs import Bushing, Contact, Stop, TorsionSpring
    from ..model.forces import Force, JointForce, LineForce, SpringDamper, Torque
    from ..model.friction_path import JointFriction
    if isinstance(e, Force):
        return _force(e)
    if isinstance(e, Torque):
        return _torque(e)
    head = {"name": e.name}
    if isinstance(e, LineForce):
        return {**head, "type": "line_force", "at_i": _marker_ref(e.marker_i), "at_j": _marker_ref(e.marker_j),
                "magnitude": _constant(f"line force '{e.name}'", "magnitude", e.magnitude)}
    if isinstance(e, JointForce):
        d = {**head, "type": "joint_force", "joint": e.joint.name,
             "value": _constant(f"joint force '{e.name}'", "value", e.value)}
        return _put(d, "dof", _dof(e.joint, e.dof, loads=True))
    if isinstance(e, SpringDamper):
        return {**head, "type": "spring_damper", "at_i": _marker_ref(e.marker_i), "at_j": _marker_ref(e.marker_j),
                "stiffness": e.stiffness, "damping": e.damping, "free_length": e.free_length, "preload": e.preload}
    if isinstance(e, TorsionSpring):
        return {**head, "type": "torsion_spring", "joint": e.joint.name, "stiffness": e.stiffness,
                "damping": e.damping, "free_angle": e.free_angle, "preload": e.preload}
    if isinstance(e, Bushing):
        return {**head, "type": "bushing", "marker_i": _marker_ref(e.marker_i), "marker_j": _marker_ref(e.marker_j),
                "stiffness": _vec(e.stiffness), "damping": _vec(e.damping), "preload": _vec(e.preload)}
    from ..model.contacts import ShapeContact
    if isinstance(e, ShapeContact):
        from .dump_shapes import shape_contact
        return shape_contact(e, _shape)
    if isinstance(e, Contact):
        return {**head, "type": "contact", "shape_i": _shape(e.shape_i), "shape_j": _shape(e.shape_j),
                "stiffness": e.stiffness, "exponent": e.exponent, "damping": e.damping,
                "penetration": e.penetration, "mu": e.mu, "friction_velocity": e.friction_velocity}
    if isinstance(e, Stop):
        d = {**head, "type": "stop", "joint": e.joint.name}
        _put(d, "lower", e.lower)
        _put(d, "upper", e.upper)
        d.update(stiffness=e.stiffness, exponent=e.exponent, damping=e.damping, penetration=e.penetration)
        return _put(d, "dof", _dof(e.joint, e.dof, loads=True))
    if isinstance(e, JointFriction):
        d = {**head, "type": "friction", "joint": e.joint.name, "mu_static": e.mu_static, "mu_dynamic": e.mu_dynamic,
             "preload": e.preload}
        for k in ("pin_radius", "friction_arm", "bending_arm", "effective_length", "reaction_arm"):
            _put(d, k, getattr(e, k))
        return d
    raise ModelError(f"element '{e.name}'", "type", f"{type(e).__name__} cannot be stored in a model file")


def model_to_dict(model, base_dir=None) -> dict:
    """Plain data (SI numbers, expression strings) describing `model` in the model-file schema; mesh files
    are written relative to `base_dir` (the model file's folder; None: absolute paths)."""
    from .dump_shapes import shapes
    bodies = [b for b in model.bodies.values() if not b.is_ground]
    d = {"name": model.name, "gravity": _vec(model.gravity)}
    ground = {k: v for k, v in (("markers", _markers(model.ground)),
                                ("shapes", shapes(model.ground, base_dir, False, _vec, _unit, _matrix))) if v}
    if ground:
        d["ground"] = ground
    d |= {"bodies": [_body(b, base_dir) for b in bodies if not b.is_particle],
         "particles": [_body(b, base_dir) for b in bodies if b.is_particle],
         "joints": [_joint(j) for j in model.joints.values()]
         + [_path(p) for p in getattr(model, "path_constraints", {}).values()],
         "motions": [_motion(m) for m in model.motions.values()],
         "forces": [_element(e) for e in model.forces.values()]}
    d["constraints"] = [_constraint(c) for c in getattr(model, "coord_constraints", {}).values()]
    d["sensors"] = [_sensor(s) for s in getattr(model, "sensors", {}).values()]
    d["inputs"] = [{"name": i.name, "value": i.value} for i in getattr(model, "inputs", {}).values()]
    d["outputs"] = [{"name": o.name, "expression": o.text} for o in getattr(model, "outputs", {}).values()]
    d["tables"] = [_table(n, t) for n, t in getattr(model, "tables", {}).items()]
    for name in getattr(model, "functions", {}):   # compiled Python code (Model.add_function): not stored
        raise ModelError(f"function '{name}'", "function", "a numba function is Python code, which model files "
                         "do not carry; store the model without it and add it after loading (Model.add_function)")
    for f in getattr(model, "fmus", {}).values():   # an FMU is code: model files never carry (and run) one
        raise ModelError(f"fmu '{f.name}'", "path", "an FMU runs its own code, so model files do not carry FMUs; "
                         "store the model without it and add it after loading (Model.add_fmu)")
    if getattr(model, "planar", None) is not None:
        d["planar"] = True if np.allclose(model.planar, [0, 0, 1]) else _unit(model.planar)
    return {k: v for k, v in d.items() if v != [] or k == "bodies"}


def _table(name, t) -> dict:
    from ..importers.adm_spline import AdamsSpline
    if not isinstance(t, AdamsSpline):
        raise ModelError(f"table '{name}'", "tables", f"a {type(t).__name__} cannot be stored in a model file; "
                         "only the tables of Adams SPLINEs (AKISPL, CUBSPL) can")
    out = {"name": name, "kind": t.kind, "x": [float(v) for v in t.xs], "y": [float(v) for v in t.ys]}
    return out | ({"linear_extrapolate": True} if t.linear else {})


def _constraint(c) -> dict:
    """Coupler, gear or user constraint (issue 11)."""
    if c.kind == "user":
        return {"type": "user_constraint", "name": c.name, "expression": c.text}
    (j1, d1), (j2, d2) = c.terms
    d = {"type": c.kind, "name": c.name, "joint_1": j1.name, "joint_2": j2.name, "ratio": c.ratio}
    _put(d, "dof_1", _dof(j1, d1))
    return _put(d, "dof_2", _dof(j2, d2))


def _sensor(s) -> dict:
    if s.text is None:
        raise ModelError(f"sensor '{s.name}'", "signal", "a Python callable cannot be stored in a model file "
                         "(give the signal as an expression string)")
    d = {"name": s.name, "signal": s.text, "value": s.value}
    _put(d, "direction", s.direction, 0)
    return _put(d, "action", s.action, "stop")

"""Export of a Result to a pandas DataFrame (and .parquet / .csv): one row per output time.

Column names are "<entity>.<quantity> [<SI unit>]" (ground axes unless stated), "[-]" for pure numbers:

time            "time [s]"
bodies          "<body>.x [m]" .y .z (centre of mass); rigid bodies "<body>.qw [-]" .qx .qy .qz (Euler
                parameters, body -> ground, scalar first, qw >= 0 at the first sample and continuous in
                time); with `euler="ZYX"` (any scipy sequence, upper case intrinsic, lower case extrinsic)
                "<body>.ZYX_1 [rad]" _2 _3 (continuous in time); "<body>.vx [m/s]" .vy .vz; rigid
                "<body>.wx [rad/s]" .wy .wz; with accelerations "<body>.ax [m/s^2]" .ay .az and rigid
                "<body>.alphax [rad/s^2]" .alphay .alphaz
markers         with `markers=True` for every marker of every body (or markers=["tip", "coupler.B"] for those
                named, by marker name or "<body>.<marker>"), "<body>.<marker>.x [m]" .y .z,
                rigid "<body>.<marker>.qw [-]" .qx .qy .qz, "<body>.<marker>.vx [m/s]" ..., and
                "<body>.<marker>.ax [m/s^2]" ... (its angular motion is its body's)
joints          coordinates and rates as Result.joint_coordinate / joint_velocity:
                revolute "<joint>.angle [rad]", "<joint>.angle_rate [rad/s]";
                translational "<joint>.displacement [m]", "<joint>.displacement_rate [m/s]";
                cylindrical both; planar "<joint>.u [m]" .v .angle with "_rate" columns;
                spherical, universal, fixed "<joint>.rx [rad]" .ry .rz (rotation vector, body_i axes) and
                "<joint>.wx [rad/s]" .wy .wz (relative angular velocity, body_i axes); universal also
                "<joint>.angle1 [rad]" .angle2 (yoke angles) and their "_rate" columns.  Angles of a
                particle body_j (which has none) are left out.  With multipliers, the reaction on body_j
                "<joint>.Fx [N]" .Fy .Fz and "<joint>.Tx [N m]" .Ty .Tz (about the joint point).
drivers         "<motion>.effort [N m]" (rotation) or "[N]" (translation), Result.driver_effort
force elements  "<element>.force [N]" (spring-damper, translational stop, contact: Result.spring_force;
                translational joint friction) or "<element>.torque [N m]" (torsion spring, rotational
                stop, revolute joint friction); bushings "<element>.Fx [N]" ... "<element>.Tz [N m]", the
                load on marker_j's body in marker_i axes
shape contacts  (results.contacts) "<element>.Fx [N]" .Fy .Fz (total force on shape_j); the centre of
                pressure "<element>.x [m]" .y .z (touching points weighted by their normal forces) and
                the unit normal of the resultant normal force "<element>.nx [-]" .ny .nz (shape_i towards
                shape_j), both NaN when nothing touches; ".points [-]" (touching points),
                ".penetration [m]" (deepest), ".slip_velocity [m/s]" (fastest slip)
                Applied forces and torques are inputs and are not repeated.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..model.body import Marker

_XYZ = "xyz"


def _vec(cols, prefix, data, unit):
    for k, axis in enumerate(_XYZ):
        cols[f"{prefix}{axis} [{unit}]"] = data[:, k]


def _quaternions(R):
    """Euler parameters (N, 4), scalar first, continuous in time (sign of the first sample: qw >= 0)."""
    from scipy.spatial.transform import Rotation
    x = Rotation.from_matrix(R).as_quat()
    q = np.concatenate([x[:, 3:], x[:, :3]], axis=1)
    flip = np.concatenate([[q[0, 0] < 0], np.einsum("ni,ni->n", q[1:], q[:-1]) < 0])
    return q * np.where(np.logical_xor.accumulate(flip), -1.0, 1.0)[:, None]


def _frame_columns(res, target, name, rigid, euler):
    cols = {}
    _vec(cols, f"{name}.", res.position(target), "m")
    if rigid:
        R = res.orientation(target)
        q = _quaternions(R)
        for k, c in enumerate("wxyz"):
            cols[f"{name}.q{c} [-]"] = q[:, k]
        if euler:
            ang = np.unwrap(res.rotation(target).as_euler(euler), axis=0)
            for k in range(3):
                cols[f"{name}.{euler}_{k + 1} [rad]"] = ang[:, k]
    _vec(cols, f"{name}.v", res.velocity(target), "m/s")
    if rigid and not isinstance(target, Marker):
        _vec(cols, f"{name}.w", res.angular_velocity(target), "rad/s")
    if res.vd is not None:
        _vec(cols, f"{name}.a", res.acceleration(target), "m/s^2")
        if rigid and not isinstance(target, Marker):
            _vec(cols, f"{name}.alpha", res.angular_acceleration(target), "rad/s^2")
    return cols


_ONE_AXIS = {"revolute": (("angle", "rad"),), "translational": (("displacement", "m"),),
             "cylindrical": (("angle", "rad"), ("displacement", "m")),
             "planar": (("u", "m"), ("v", "m"), ("angle", "rad"))}


def _joint_columns(res, joint):
    cols = {}
    particle_j = joint.body_j.is_particle
    if joint.kind in _ONE_AXIS:
        names = _ONE_AXIS[joint.kind]
        x = np.asarray(res.joint_coordinate(joint)).reshape(len(res.time), -1)
        xd = np.asarray(res.joint_velocity(joint)).reshape(len(res.time), -1)
        for k, (q, unit) in enumerate(names):
            if particle_j and unit == "rad":
                continue
            kk = min(k, x.shape[1] - 1)          # a cylindrical joint on a particle has its slide only
            cols[f"{joint.name}.{q} [{unit}]"] = x[:, kk]
            cols[f"{joint.name}.{q}_rate [{unit}/s]"] = xd[:, kk]
    elif not particle_j:                        # spherical, universal, fixed
        _vec(cols, f"{joint.name}.r", res.joint_coordinate(joint), "rad")
        _vec(cols, f"{joint.name}.w", res.joint_velocity(joint), "rad/s")
        if joint.kind == "universal":
            ang, rate = res.joint_coordinate(joint, kind="angles"), res.joint_velocity(joint, kind="angles")
            for k in range(2):
                cols[f"{joint.name}.angle{k + 1} [rad]"] = ang[:, k]
                cols[f"{joint.name}.angle{k + 1}_rate [rad/s]"] = rate[:, k]
    if res.lambda_ is not None:
        F, T = res._reaction(joint, None, None)   # noqa: SLF001 - force and torque in one pass
        _vec(cols, f"{joint.name}.F", F, "N")
        _vec(cols, f"{joint.name}.T", T, "N m")
    return cols


def _element_columns(res, el):
    from ..model.element_specs import Bushing, Stop, TorsionSpring
    from ..model.friction_path import JointFriction
    from ..system.force_elements import evaluator
    name = el.name
    if isinstance(el, Bushing):
        from ..system.force_elements.bushing import bushing_loads, bushing_state
        F, T = bushing_loads(el, *bushing_state(res.system, res.frames, el)[:4])
        cols = {}
        _vec(cols, f"{name}.F", F, "N")
        _vec(cols, f"{name}.T", T, "N m")
        return cols
    if isinstance(el, JointFriction):
        if res.lambda_ is None:
            return {}
        torque = el.joint.kind == "revolute"
        return {f"{name}.{'torque [N m]' if torque else 'force [N]'}": res.friction_force(el)}
    from ..model.contacts import ShapeContact
    if isinstance(el, ShapeContact):
        from .contacts import contact_columns
        return contact_columns(res, el)
    try:
        ev = evaluator(el)
    except TypeError:
        return {}
    if not hasattr(ev, "tension"):
        return {}
    torque = isinstance(el, TorsionSpring) or (isinstance(el, Stop) and el.dof == "rotation")
    return {f"{name}.{'torque [N m]' if torque else 'force [N]'}": res.spring_force(el)}


def marker_targets(bodies, markers, entity="to_dataframe"):
    """[(column prefix "<body>.<marker>", Marker)] that `markers` selects among the markers of `bodies`:
    none for False / None, all for True, else those named in a list (a name "B" or "coupler.B"; a bare
    name must be unique). ModelError naming `entity`.markers for an unknown or ambiguous name."""
    from ..errors import ModelError
    if markers is None or markers is False:
        return []
    every = [(f"{b.name}.{mk.name}", mk) for b in bodies if not getattr(b, "is_ground", False)
             for mk in b.markers.values()]
    if markers is True:
        return every
    names = [markers] if isinstance(markers, str) else markers
    try:
        names = list(names)
    except TypeError:
        raise ModelError(entity, "markers",
                         f"expected True, False or a list of marker names, got {markers!r}") from None
    out = []
    for name in names:
        hits = [t for t in every if isinstance(name, str) and (t[0] == name or t[1].name == name)]
        if len(hits) != 1:
            known = ", ".join(t[0] for t in every) or "none (the model has no markers)"
            why = "is ambiguous (give <body>.<marker>)" if hits else "names no marker"
            raise ModelError(entity, "markers", f"{name!r} {why}; markers: {known}")
        if hits[0] not in out:
            out.append(hits[0])
    return out


def to_dataframe(res, markers=False, euler=None):
    """Wide pandas DataFrame of a Result (columns: see the module docstring), SI units in the names.

    A Result without outputs (a run that failed before its first) raises ModelError("to_dataframe",
    "result") quoting the run's message: there is nothing to export."""
    import pandas as pd
    check_euler(euler)
    if len(res.time) == 0:
        raise ModelError("to_dataframe", "result", "the result has no outputs (the run failed before its "
                         f"first: {res.message}); there is nothing to export")
    return pd.DataFrame(columns(res, markers, euler))


def check_euler(euler) -> None:
    """ModelError("to_dataframe", "euler") unless euler is None or a scipy Euler sequence: three axes
    of "xyz" (extrinsic) or "XYZ" (intrinsic), no two consecutive axes the same ("ZYX", "zxz")."""
    if euler is None:
        return
    ok = isinstance(euler, str) and len(euler) == 3 and (set(euler) <= set("xyz") or set(euler) <= set("XYZ")) \
        and euler[0] != euler[1] and euler[1] != euler[2]
    if not ok:
        raise ModelError("to_dataframe", "euler", f"expected a sequence of three axes such as 'ZYX' (intrinsic, "
                         f"upper case) or 'zyx' (extrinsic), no axis twice in a row; got {euler!r}")


def columns(res, markers=False, euler=None):
    """The columns of `to_dataframe` as an ordered dict {name: 1-D float array per output time}, without
    pandas (the streamed writer builds its Parquet tables from it with pyarrow directly)."""
    check_euler(euler)
    cols = {"time [s]": np.asarray(res.time, dtype=float)}
    for body in res.system.bodies:
        cols.update(_frame_columns(res, body, body.name, not body.is_particle, euler))
    for prefix, mk in marker_targets(res.system.bodies, markers):
        cols.update(_frame_columns(res, mk, prefix, not mk.body.is_particle, euler))
    model = res.system.model
    for joint in model.joints.values():
        cols.update(_joint_columns(res, joint))
    if res.lambda_ is not None:
        for m in model.motions.values():
            cols[f"{m.name}.effort [{'N m' if m.dof == 'rotation' else 'N'}]"] = res.driver_effort(m)
    for el in model.forces.values():
        cols.update(_element_columns(res, el))
    return cols

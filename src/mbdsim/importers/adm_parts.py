"""UNITS, ACCGRAV, PART, MARKER and VARIABLE statements of an .adm dataset -> the Model's units, gravity,
bodies and markers (SI, ground frame at t=0).

PART/id: QG (origin of the part frame in ground), REULER (body-fixed 3-1-3 angles, rad; `D` for
degrees) or ZG/XG (points on its z axis and in its xz plane); MASS, CM (the centre-of-mass marker),
IP = Ixx, Iyy, Izz[, Ixy, Ixz, Iyz] about the IM marker (default CM) in its axes, products as positive
integrals (Adams' convention: the tensor holds -Ixy ...); VX VY VZ (the CM's velocity along the axes of
the VM marker, default ground) and WX WY WZ (angular velocity about the axes of the WM marker, default CM).  The mbdsim
body sits at the CM marker with that marker's axes (the inertia is rotated and shifted into them).
MARKER/id: PART, QP and REULER or ZP/XP (USEXP) in the part frame; FLOATING markers are kept on their
part at their given pose (mbdsim uses them as reaction points only).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ModelError
from .adm_context import SYSTEMS, UNIT_NAMES, Units, _si


def units(imp, st) -> None:
    """UNITS/FORCE=, MASS=, LENGTH=, TIME= or SYSTEM= (MKS, MMKS, CGS, IPS, FPS) -> SI factors."""
    a, _ = imp.args(st, ("FORCE", "MASS", "LENGTH", "TIME", "SYSTEM", "UCF"))
    names = {}
    if "SYSTEM" in a:
        sysname = a["SYSTEM"].values[0].upper() if a["SYSTEM"].values else ""
        if sysname not in SYSTEMS:
            imp.fail(st, "SYSTEM", f"unknown unit system {sysname!r} (known: {', '.join(SYSTEMS)})", a["SYSTEM"].line)
        names = dict(zip(("FORCE", "MASS", "LENGTH", "TIME"), SYSTEMS[sysname]))
    for key in ("FORCE", "MASS", "LENGTH", "TIME"):
        if key in a:
            val = a[key].values[0].upper() if a[key].values else ""
            if val not in UNIT_NAMES[key]:
                imp.fail(st, key, f"unknown {key.lower()} unit {val!r} (known: {', '.join(UNIT_NAMES[key])})",
                         a[key].line)
            names[key] = val
    if "UCF" in a and len(names) < 4:
        imp.fail(st, "UCF", "a units consistency factor without the four named units cannot be converted to SI; "
                 "give FORCE, MASS, LENGTH and TIME", a["UCF"].line)
    f = {k.lower(): _si(UNIT_NAMES[k][v]) for k, v in names.items()}
    imp.units = Units(**f)
    if "UCF" in a:
        imp.note(st, "UCF ignored: the named units define the conversion to SI")


def accgrav(imp, st) -> None:
    """ACCGRAV/IGRAVITY=, JGRAVITY=, KGRAVITY= (length/time^2, ground axes) -> Model.gravity."""
    a, _ = imp.args(st, ("IGRAVITY", "JGRAVITY", "KGRAVITY"))
    g = [imp.num(st, a, k, 0.0, "acceleration") for k in ("IGRAVITY", "JGRAVITY", "KGRAVITY")]
    imp.model.gravity = np.array(g, dtype=float)


def variable(imp, st) -> None:
    """VARIABLE/id, FUNCTION= : kept as text, inlined where VARVAL(id) reads it."""
    a, _ = imp.args(st, ("FUNCTION", "IC"), ignored=("ROUTINE",))
    if "FUNCTION" not in a:
        imp.fail(st, "FUNCTION", "is required (VARIABLE written by a user subroutine is not supported)")
    imp.variables[st.id] = (a["FUNCTION"].values[0], a["FUNCTION"].line)


def euler_313(angles) -> np.ndarray:
    """Rotation matrix (frame -> parent) of Adams body-fixed 3-1-3 angles [rad]."""
    return Rotation.from_euler("ZXZ", angles).as_matrix()


def _frame(imp, st, a, origin_key, euler_key, z_key, x_key, parent_R, parent_p, use_x=False):
    """(origin, R) in ground of a frame given by an origin and Euler angles or z/x points, in the
    coordinates of the parent frame (parent_R, parent_p)."""
    q = np.array(imp.nums(st, a, origin_key, 3, [0.0, 0.0, 0.0], "length"))
    if euler_key in a and (z_key in a or x_key in a):
        imp.fail(st, euler_key, f"give {euler_key} or {z_key}/{x_key}, not both", a[euler_key].line)
    if z_key in a or x_key in a:
        R = _points_frame(imp, st, a, q, z_key, x_key, use_x)
    else:
        R = euler_313(imp.nums(st, a, euler_key, 3, [0.0, 0.0, 0.0], "angle"))
    return parent_p + parent_R @ q, parent_R @ R


def _points_frame(imp, st, a, q, z_key, x_key, use_x):
    """Axes from a point on the z axis and a point in the xz plane (USEXP: the x axis exact)."""
    zp = np.array(imp.nums(st, a, z_key, 3, None, "length") or (q + [0, 0, 1]))
    z = zp - q
    if np.linalg.norm(z) == 0.0:
        imp.fail(st, z_key, "the point on the z axis coincides with the origin")
    z = z / np.linalg.norm(z)
    xp = imp.nums(st, a, x_key, 3, None, "length")
    if xp is None:
        from ..math.rotation import perpendicular_frame
        x = perpendicular_frame(z)[0]
    else:
        x = np.array(xp) - q
    if use_x:
        x = x / np.linalg.norm(x)
        z = z - (z @ x) * x
    else:
        x = x - (x @ z) * z
    if np.linalg.norm(x) < 1e-12 or np.linalg.norm(z) < 1e-12:
        imp.fail(st, x_key, "the point in the xz plane lies on the z axis")
    x, z = x / np.linalg.norm(x), z / np.linalg.norm(z)
    return np.column_stack([x, np.cross(z, x), z])


def parts_and_markers(imp, parts: dict, markers: dict) -> None:
    """Bodies from the PART statements and markers from the MARKER statements (see the module docstring)."""
    frames, ground = {}, None
    for pid, st in parts.items():
        a, fl = imp.args(st, ("MASS", "CM", "IM", "IP", "QG", "REULER", "ZG", "XG", "VX", "VY", "VZ", "WX", "WY",
                              "WZ", "VM", "WM", "EXACT"), ("GROUND",), ignored=("MATERIAL", "PLANAR"))
        if "GROUND" in fl:
            if ground is not None:
                imp.fail(st, "GROUND", f"a second ground part (PART/{ground} is ground)")
            ground = pid
            frames[pid] = (np.zeros(3), np.eye(3), a, st)
            continue
        p, R = _frame(imp, st, a, "QG", "REULER", "ZG", "XG", np.eye(3), np.zeros(3))
        frames[pid] = (p, R, a, st)
    if ground is None:
        imp.notes.append("no GROUND part: mbdsim's ground is the fixed frame")
    # marker poses in ground (a marker's QP/REULER are in its part's frame)
    poses = {}
    for mid, st in markers.items():
        a, fl = imp.args(st, ("PART", "QP", "REULER", "ZP", "XP", "FLEX_BODY", "NODE_ID"), ("FLOATING", "USEXP"))
        if "FLEX_BODY" in a:
            imp.fail(st, "FLEX_BODY", "flexible bodies are not supported by mbdsim")
        pid = imp.ident(st, a, "PART")
        if pid not in frames:
            imp.fail(st, "PART", f"no PART/{pid} in the dataset", a["PART"].line)
        pp, pR = frames[pid][:2]
        p, R = _frame(imp, st, a, "QP", "REULER", "ZP", "XP", pR, pp, "USEXP" in fl)
        poses[mid] = (pid, p, R, st, "FLOATING" in fl)
    for pid, (p, R, a, st) in frames.items():
        imp.parts[pid] = imp.model.ground if pid == ground else _body(imp, pid, st, a, p, R, poses)
    for mid, (pid, p, R, st, floating) in poses.items():
        body = imp.parts[pid]
        name = imp.marker_name(st, body, f"MARKER_{mid}")
        try:
            imp.markers[mid] = body.add_marker(name, p, R)
        except ModelError as exc:
            imp.model_error(st, exc)
        if floating:
            imp.floating.add(mid)


def _body(imp, pid, st, a, p, R, poses):
    """An mbdsim body for PART `pid` (frame p, R in ground): at the CM marker, in its axes."""
    def marker_pose(key):
        mid = imp.ident(st, a, key, required=False)
        if mid is None:
            return None
        if mid not in poses or poses[mid][0] != pid:
            imp.fail(st, key, f"MARKER/{mid} is not a marker of PART/{pid}", a[key].line)
        return poses[mid][1], poses[mid][2]

    cm = marker_pose("CM") or (p, R)
    im = marker_pose("IM") or cm
    mass = imp.num(st, a, "MASS", 0.0, "mass")
    ip = imp.nums(st, a, "IP", None, None, "inertia")
    if ip is not None and len(ip) not in (3, 6):
        imp.fail(st, "IP", f"expected 3 or 6 values (xx, yy, zz[, xy, xz, yz]), got {len(ip)}", a["IP"].line)
    if ip is not None and "MASS" not in a:
        imp.fail(st, "MASS", "IP is given without MASS")
    J = np.zeros((3, 3))
    if ip is not None:
        xx, yy, zz, xy, xz, yz = (list(ip) + [0.0, 0.0, 0.0])[:6]
        J_im = np.array([[xx, -xy, -xz], [-xy, yy, -yz], [-xz, -yz, zz]])
        J = im[1] @ J_im @ im[1].T                           # about the IM origin, ground axes
        r = im[0] - cm[0]                                    # shifted to the CM (parallel axes)
        J = J - mass * ((r @ r) * np.eye(3) - np.outer(r, r))
        J = cm[1].T @ J @ cm[1]                              # CM marker (body) axes
        J = 0.5 * (J + J.T)
    if mass == 0.0 and "MASS" not in a:
        imp.note(st, "no MASS: a massless part")
    v, w = _velocities(imp, st, a, cm, poses, pid)
    name = imp.name(st, f"PART_{pid}")
    try:
        return imp.model.add_body(name, mass=mass, inertia=J, position=cm[0], orientation=cm[1], velocity=v,
                                  angular_velocity=w)
    except ModelError as exc:
        imp.model_error(st, exc)


def _velocities(imp, st, a, cm, poses, pid):
    """(CM velocity, angular velocity) in ground, or None.  Adams' PART: VX VY VZ are the CM marker's velocity
    along the axes of the VM marker (default: ground axes); WX WY WZ the angular velocity about the axes of
    the WM marker (default: the CM marker)."""
    vs = [imp.num(st, a, k, None, "velocity") for k in ("VX", "VY", "VZ")]
    ws = [imp.num(st, a, k, None, "angular_velocity") for k in ("WX", "WY", "WZ")]
    if "EXACT" in a:
        imp.note(st, "EXACT ignored: the given velocities are held at assembly where consistent")

    def axes(key, default):
        if key not in a:
            return default
        mid = imp.ident(st, a, key)
        if mid not in poses:
            imp.fail(st, key, f"no MARKER/{mid} in the dataset", a[key].line)
        return poses[mid][2]
    w = v = None
    if any(x is not None for x in ws):
        w = axes("WM", cm[1]) @ np.array([0.0 if x is None else x for x in ws])
    if any(x is not None for x in vs):
        v = axes("VM", np.eye(3)) @ np.array([0.0 if x is None else x for x in vs])
    return v, w

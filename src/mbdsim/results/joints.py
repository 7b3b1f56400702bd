"""Joint coordinates of a Result, their rates and accelerations, continuous in time.

Coordinates are zero in the configuration the model was built in; axes are those of body_i.

- revolute: angle [rad] of body_j about the axis h_i (right-hand rule); translational: slide [m]
  h_i . (P_j - P_i); cylindrical: (angle, slide).
- planar: (u [m], v [m], angle [rad]): the joint point of body_j along the in-plane axes u, v of
  body_i (v = normal x u, see `Model.add_planar`) and the rotation about the normal.
- spherical, universal, fixed: the rotation vector [rad] (N, 3), in body_i axes, of body_j's attitude
  relative to its initial one; rates are the relative angular velocity in body_i axes [rad/s] (not the
  rotation vector's derivative) and accelerations its derivative taken in body_i [rad/s^2].
  A universal joint with `kind="angles"` gives its two yoke angles instead: (angle1, angle2) [rad],
  angle1 the rotation of the cross about axis_i relative to body_i, angle2 the rotation of body_j about
  axis_j relative to the cross, so that R_rel = Rot(axis_i, angle1) Rot(axis_j(t=0), angle2).

Angles continue beyond +-pi, with whole turns counted on the solver's own steps: the analyses record
the state at the start of each accepted step (`Result.steps`), the angle is continued step to step
(each step's increment the one nearest the trapezoidal prediction from the rates; a step turns a
joint by far less than pi), and each output sample is placed on the branch nearest the prediction from
the start of its step.  Revolute, cylindrical, planar and the universal joint's yoke angles are
therefore the same for any output_step, and at the same times from Result.at.  (Without a step record,
e.g. a Result built by hand, samples are continued sample to sample the same way.)  A rotation
vector theta = psi a keeps a continuous axis a (its sign follows the previous sample) and its angle psi
is continued the same way, i.e. past pi it becomes the equivalent vector (|theta| - 2 pi) theta / |theta|
instead of jumping.  (Through a full turn, |theta| = 2 pi, of a tumbling motion the axis itself is not
defined and may jump: no representation by rotation vectors avoids that.)  A Result from `at()` continues
its parent's history from the parent's nearest sample.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..model.joints import Joint
from ..system import measures as ms
from ..model.joint_kinds import has_slide, is_angle

ROTATION_JOINTS = ("spherical", "universal", "fixed", "constant_velocity")
_TWO_PI = 2.0 * np.pi


def joint_of(res, joint) -> Joint:
    """The Joint (or joint name) of the analysed model, else ModelError."""
    if isinstance(joint, str):
        joint = res.system.model.joints.get(joint, joint)
    if not isinstance(joint, Joint) or joint.name not in res.system.geoms:
        raise ModelError(f"joint {getattr(joint, 'name', joint)!r}", "joint", "is not a joint of the analysed model")
    if res.system.model.joints.get(joint.name) is not joint:   # same name, another model's object
        raise ModelError(f"joint '{joint.name}'", "joint", "is a joint of another model (same name, different "
                         f"object) than the analysed model '{res.system.model.name}'")
    return joint


def _check_kind(jt, kind):
    if jt.ncoord == 0 and jt.kind != "fixed":
        raise ModelError(f"joint '{jt.name}'", "joint", f"a {jt.kind} joint primitive has no joint coordinates; "
                         "measure its bodies (position, orientation) instead")
    if kind is None:
        return
    if kind != "angles" or jt.kind != "universal":
        raise ModelError(f"joint '{jt.name}'", "kind", f"{kind!r} is not available for a {jt.kind} joint "
                         "(kind=\"angles\" gives the two yoke angles of a universal joint)")


# ----------------------------------------------------------------------------- public entry points
def coordinate(res, joint, kind=None):
    """Joint coordinate(s), see the module docstring: (N,) or (N, k)."""
    return _values(res, joint, kind)[0]


def velocity(res, joint, kind=None):
    """Rate(s) of the joint coordinate(s) [rad/s, m/s]; relative angular velocity for rotation joints."""
    return _values(res, joint, kind)[1]


def _values(res, joint, kind):
    jt = joint_of(res, joint)
    _check_kind(jt, kind)
    if kind == "angles":
        return yoke_angles(res, jt)
    if jt.kind in ROTATION_JOINTS:
        psi, axis, _ = rotation_coordinate(res, jt)
        return psi[:, None] * axis, ms.relative_angular_velocity(res.system, res.frames, jt)[0]
    if jt.kind == "planar":
        return planar(res, jt)
    ang, angd, sl, sld = one_axis(res, jt)
    return _pick(ang, sl), _pick(angd, sld)


def acceleration(res, joint, kind=None):
    """Second time derivative(s) of the joint coordinate(s) [rad/s^2, m/s^2] (see the module docstring)."""
    jt = joint_of(res, joint)
    _check_kind(jt, kind)
    sys, fr = res.system, res.frames
    if kind == "angles":
        return yoke_accelerations(res, jt)
    if jt.kind in ROTATION_JOINTS:
        return ms.relative_angular_velocity(sys, fr, jt)[1]
    g = sys.geoms[jt.name]
    axes = [np.einsum("nij,j->ni", fr.A[:, g.bi], a) for a in (g.f_i, g.g_i, g.h_i)]
    if jt.kind == "planar":
        ang = np.zeros(len(res.time)) if g.particle_j else _spin_acc(g, fr, axes[2])
        return np.stack([_slide_acc(g, fr, axes[0]), _slide_acc(g, fr, axes[1]), ang], -1)
    ang = sl = None
    if is_angle(jt.kind) and not g.particle_j:
        ang = _spin_acc(g, fr, axes[2])
    if has_slide(jt.kind):
        sl = _slide_acc(g, fr, axes[2])
    return _pick(ang, sl)


# ----------------------------------------------------------------------------- coordinates by joint kind
def one_axis(res, jt):
    """(angle, angle rate, slide, slide rate) of a revolute / translational / cylindrical joint, each
    (N,) or None; the angle continued in time."""
    ang, angd, sl, sld = ms.joint_coordinate(res.system, res.frames, jt)
    if ang is not None:
        anchor = _angle_anchor(res.system, jt, res.time) if res._parent is None else None
        ang = continued(res, ang, angd, lambda p: one_axis(p, jt)[:2], anchor)
    return ang, angd, sl, sld


def planar(res, jt):
    """[u, v, angle] (N, 3) of a planar joint (angle continued) and their rates (N, 3)."""
    x, xd = ms.planar_coordinates(res.system, res.frames, jt)
    if not jt.body_j.is_particle:
        x = x.copy()
        x[:, 2] = continued(res, x[:, 2], xd[:, 2], lambda p: tuple(a[:, 2] for a in planar(p, jt)))
    return x, xd


def yoke_angles(res, jt):
    """(angle1, angle2) (N, 2) [rad] of a universal joint and their rates (N, 2) [rad/s]."""
    sys, fr = res.system, res.frames
    g = sys.geoms[jt.name]
    Ai, Aj = fr.A[:, g.bi], fr.A[:, g.bj]
    Rij = np.einsum("nji,njk->nik", Ai, Aj)                                  # body_j -> body_i axes
    c0_i = jt.body_i.orientation.T @ jt.axis_j                               # axis_j at t=0, body_i axes
    e0_j = jt.body_j.orientation.T @ jt.axis                                 # axis_i at t=0, body_j axes
    c_i = Rij @ g.extra                                                      # axis_j now, body_i axes
    e_j = np.einsum("nji,j->ni", Rij, g.h_i)                                 # axis_i now, body_j axes
    a1 = np.arctan2(np.cross(c0_i, c_i) @ g.h_i, c_i @ c0_i)
    a2 = np.arctan2(np.cross(e_j, e0_j) @ g.extra, e_j @ e0_j)
    w_rel = ms.relative_angular_velocity(sys, fr, jt)[0]
    r1, r2 = w_rel @ g.h_i, np.einsum("ni,ni->n", w_rel, c_i)
    a1 = continued(res, a1, r1, lambda p: tuple(a[:, 0] for a in yoke_angles(p, jt)))
    a2 = continued(res, a2, r2, lambda p: tuple(a[:, 1] for a in yoke_angles(p, jt)))
    return np.stack([a1, a2], -1), np.stack([r1, r2], -1)


def yoke_accelerations(res, jt):
    """Second derivatives (N, 2) [rad/s^2] of the yoke angles of a universal joint."""
    sys, fr = res.system, res.frames
    g = sys.geoms[jt.name]
    w_rel, dw_rel = ms.relative_angular_velocity(sys, fr, jt)
    if dw_rel is None:
        raise ValueError("joint_acceleration is not available: this result holds no accelerations")
    c_i = np.einsum("nji,njk,k->ni", fr.A[:, g.bi], fr.A[:, g.bj], g.extra)
    r1 = w_rel @ g.h_i
    c_dot = np.cross(r1[:, None] * g.h_i, c_i)               # the cross turns about axis_i at rate r1
    acc2 = np.einsum("ni,ni->n", dw_rel, c_i) + np.einsum("ni,ni->n", w_rel, c_dot)
    return np.stack([dw_rel @ g.h_i, acc2], -1)


def rotation_coordinate(res, jt):
    """Rotation vector of a spherical / universal / fixed joint as (psi (N,) [rad], unit axis (N, 3) in
    body_i axes, psi rate (N,) [rad/s]), continuous in time (see the module docstring)."""
    sys, fr = res.system, res.frames
    th = ms.relative_rotation_vector(sys, fr, jt)
    w_rel = ms.relative_angular_velocity(sys, fr, jt)[0]
    th_dot = rotvec_rate(th, w_rel)
    phi = np.linalg.norm(th, axis=1)
    axis = _fill_axes(th, phi)
    if res._parent is None:
        sign = np.sign(np.einsum("ni,ni->n", axis[1:], axis[:-1]))
        sign = np.cumprod(np.concatenate([[1.0], np.where(sign == 0, 1.0, sign)]))
        parent = None
    else:   # the axis sign of the parent's nearest sample
        parent = rotation_coordinate(res._parent, jt)
        sign = np.sign(np.einsum("ni,ni->n", axis, parent[1][_nearest(res._parent.time, res.time)]))
        sign = np.where(sign == 0, 1.0, sign)
    axis = axis * sign[:, None]
    psi0, rate = phi * sign, np.einsum("ni,ni->n", axis, th_dot)
    psi = continued(res, psi0, rate, lambda p: (parent[0], parent[2]), steps=False)
    return psi, axis, rate


def rotvec_rate(th, w):
    """Time derivative (N, 3) of rotation vectors th (|th| <= pi) whose rotation R has R' R^T = [w]x:
    th' = J_l(th)^-1 w = w - th x w / 2 + c th x (th x w), c = (1 - (phi/2) cot(phi/2)) / phi^2."""
    phi = np.linalg.norm(th, axis=-1)
    small = phi < 1e-4
    half = np.where(small, 1.0, 0.5 * phi)
    c = np.where(small, 1.0 / 12.0 + phi**2 / 720.0,
                 (1.0 - half * np.cos(half) / np.where(small, 1.0, np.sin(half))) / np.where(small, 1.0, phi**2))
    txw = np.cross(th, w)
    return w - 0.5 * txw + c[:, None] * np.cross(th, txw)


def _fill_axes(th, phi, tiny=1e-12):
    """Unit axes th / |th|; where |th| ~ 0 the nearest previous defined axis (else the next, else z)."""
    ok = phi > tiny
    axis = np.zeros_like(th)
    axis[ok] = th[ok] / phi[ok, None]
    if not ok.any():
        axis[:, 2] = 1.0
        return axis
    idx = np.where(ok, np.arange(len(phi)), -1)
    idx = np.maximum.accumulate(idx)
    idx[idx < 0] = int(np.argmax(ok))
    return axis[idx]


# ----------------------------------------------------------------------------- continuity of angles
def continued(res, raw, rate, parent_values, anchor=None, steps=True):
    """Continue wrapped angles raw (N,) [rad] with rates (N,) [rad/s] past +-pi.

    When the analysis recorded its own steps (`step_track`), the angle is continued along the solver's
    steps and each sample is placed on the branch nearest the trapezoidal prediction from the start of
    the step containing it: the same for any output_step, dense output and Result.at.  Otherwise a
    Result without parent continues sample to sample (from `anchor` (N,), a reference recorded during
    the run, when given); a Result from `at()` continues `parent_values(parent) -> (angles, rates)` from
    the parent's nearest sample."""
    track = step_track(res) if steps else None
    if track is not None:
        s_ang, s_rate = parent_values(track)
        k = np.clip(np.searchsorted(track.time, res.time, side="right") - 1, 0, len(track.time) - 1)
        ref = s_ang[k] + 0.5 * (s_rate[k] + rate) * (res.time - track.time[k])
        return raw + _TWO_PI * np.round((ref - raw) / _TWO_PI)   # the raw values, shifted by whole turns
    if res._parent is None:
        if anchor is not None:   # a torsion spring / stop on the joint continued the angle in the run
            raw = anchor + _wrap(raw - anchor)
        return _unwrap_with_rate(res.time, raw, rate)
    p = res._parent
    p_ang, p_rate = parent_values(p)
    k = _nearest(p.time, res.time)
    ref = p_ang[k] + 0.5 * (p_rate[k] + rate) * (res.time - p.time[k])
    return ref + _wrap(raw - ref)


def step_track(res):
    """A Result (no output sampling) holding the states at the start of every accepted solver step and at
    the end of the run, from the analysis' `steps` record ((t, q, v) or a callable giving it); None when
    the analysis kept none, or for that Result itself."""
    root = res._parent or res
    st = getattr(root, "steps", None)
    if st is None:
        return None
    track = root.__dict__.get("_step_track")
    if track is None:
        st = st() if callable(st) else st
        if st is None or len(st[0]) < 2:
            root.steps = None
            return None
        track = type(root)(root.system, *st, None, None)
        root._step_track = track
    return None if track is res else track


def _wrap(x):
    return (x + np.pi) % _TWO_PI - np.pi


def _nearest(times, t):
    """Index of the sample of `times` nearest each t."""
    k = np.clip(np.searchsorted(times, t), 0, len(times) - 1)
    prev = np.maximum(k - 1, 0)
    return np.where(np.abs(times[prev] - t) < np.abs(times[k] - t), prev, k)


def _unwrap_with_rate(t, ang, rate):
    """Continue wrapped angles (N,) beyond +-pi: each increment is the one closest to the trapezoidal
    prediction from the rates, so more than pi per output step is followed (np.unwrap is not)."""
    if len(ang) < 2:
        return ang
    pred = 0.5 * (rate[1:] + rate[:-1]) * np.diff(t)
    inc = pred + _wrap(np.diff(ang) - pred)
    cont = ang[0] + np.concatenate([[0.0], np.cumsum(inc)])
    return ang + _TWO_PI * np.round((cont - ang) / _TWO_PI)   # the raw values, shifted by whole turns


def _angle_anchor(system, joint, times):
    """The angle references (N,) recorded during the analysis by a force element on `joint` (torsion
    spring, rotational stop), or None."""
    from ..system.force_elements._common import _ref, element_state
    for e in system.model.forces.values():
        if getattr(e, "joint", None) is joint and element_state(system, e.name).get("angle_ref"):
            return _ref(system, e.name, times)
    return None


# ----------------------------------------------------------------------------- driver effort
def driver_effort(res, motion):
    """Torque [N m] about (rotation) or force [N] along (translation) the driven joint axis that the motion
    driver `motion` (a Motion or its name) applies to body_j, (N,)."""
    from ..system.reactions import joint_reaction
    motions = res.system.model.motions
    name = motion if isinstance(motion, str) else getattr(motion, "name", None)
    if name not in motions or name not in res.system.owner_rows:
        raise ModelError(f"motion {name!r}", "motion", "is not a motion driver of the analysed model")
    m = motions[name]
    if not isinstance(motion, str) and m is not motion:   # same name, another model's object
        raise ModelError(f"motion {name!r}", "motion", "is a motion of another model (same name, different "
                         "object) than the analysed model")
    g = res.system.geoms[m.joint.name]
    F, T = joint_reaction(res.system, res.q, res.lambda_, name)
    h = np.einsum("nij,j->ni", res.frames.A[:, g.bi], g.h_i)
    return np.einsum("ni,ni->n", T if m.dof == "rotation" else F, h)


# ----------------------------------------------------------------------------- accelerations
def _spin_acc(g, fr, h):
    """d/dt (h . (w_j - w_i)) = h . (alpha_j - alpha_i) + (w_i x h) . (w_j - w_i) [rad/s^2], h on body_i."""
    dw = fr.w[:, g.bj] - fr.w[:, g.bi]
    dalpha = fr.alpha[:, g.bj] - fr.alpha[:, g.bi]
    return np.einsum("ni,ni->n", h, dalpha) + np.einsum("ni,ni->n", np.cross(fr.w[:, g.bi], h), dw)


def _slide_acc(g, fr, h):
    """d^2/dt^2 of h . (P_j - P_i) [m/s^2] for an axis h (N, 3, ground) fixed on body_i."""
    si = np.einsum("nij,j->ni", fr.A[:, g.bi], g.s_i)
    sj = np.einsum("nij,j->ni", fr.A[:, g.bj], g.s_j)
    wi, wj = fr.w[:, g.bi], fr.w[:, g.bj]
    d = fr.r[:, g.bj] + sj - fr.r[:, g.bi] - si
    dd = fr.rd[:, g.bj] + np.cross(wj, sj) - fr.rd[:, g.bi] - np.cross(wi, si)
    ddd = (fr.rdd[:, g.bj] + np.cross(fr.alpha[:, g.bj], sj) + np.cross(wj, np.cross(wj, sj))
           - fr.rdd[:, g.bi] - np.cross(fr.alpha[:, g.bi], si) - np.cross(wi, np.cross(wi, si)))
    hd = np.cross(wi, h)
    hdd = np.cross(fr.alpha[:, g.bi], h) + np.cross(wi, hd)
    dot = lambda a, b: np.einsum("ni,ni->n", a, b)  # noqa: E731
    return dot(hdd, d) + 2 * dot(hd, dd) + dot(h, ddd)


def _pick(ang, sl):
    if ang is not None and sl is not None:
        return np.stack([ang, sl], -1)
    return ang if ang is not None else sl

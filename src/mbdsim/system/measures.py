"""Pure measure functions of (system, frames): positions, velocities, joint coordinates, energies.

Frames carry a leading time axis (N, nframes, ...).  Vectors are in ground axes unless `frame`
names a Body or Marker, in which case they are expressed in that frame's axes (positions are then
measured from the frame's origin; velocities/accelerations stay absolute, i.e. relative to ground).
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..model.body import Body, Marker
from .constraints import primitives as pr
from .frames import Frames, cross
from ..model.joint_kinds import has_slide, is_angle


def resolve(sys, target, field="target"):
    """The Body or Marker that `target` names: a Body, a Marker, a body name or a "body.marker" name
    (else ModelError naming the argument `field`)."""
    if isinstance(target, (Body, Marker)):
        return target
    if isinstance(target, str):
        bodies = sys.model.bodies
        if target in bodies:
            return bodies[target]
        body, dot, marker = target.rpartition(".")
        if dot and body in bodies and marker in bodies[body].markers:
            return bodies[body].markers[marker]
        raise ModelError(f"measure target {target!r}", field, "no body or \"body.marker\" of this name in "
                         "the model")
    raise ModelError(f"measure target {target!r}", field, "expected a Body, particle or Marker of the model, "
                     "or the name of one (\"rod\", \"rod.tip\")")


def resolve_body(sys, target, field="target"):
    """The Body of a Body, Marker or name (a marker stands for the body it is fixed on)."""
    x = resolve(sys, target, field)
    return x.body if isinstance(x, Marker) else x


def locate(sys, target, field="target"):
    """(frame index, s_B, R_BM) of a Body (its CM) or Marker, or of the body / "body.marker" so named."""
    target = resolve(sys, target, field)
    if isinstance(target, Marker):
        return sys.fid[_known(sys, target.body)], target.s_B, target.R_BM
    return sys.fid[_known(sys, target)], np.zeros(3), np.eye(3)


def _known(sys, body):
    if body not in sys.fid:
        raise ModelError(f"body '{body.name}'", "body", "is not part of the analysed model")
    return body


def frame_rotation(sys, fr: Frames, frame):
    """Rotation (N, 3, 3) frame->ground of a Body/Marker (identity for None)."""
    if frame is None:
        return None
    fid, _, R_BM = locate(sys, frame, "frame")
    return fr.A[:, fid] @ R_BM


def express(sys, fr, vec, frame):
    """Express ground vectors (N, 3) in the axes of `frame`."""
    R = frame_rotation(sys, fr, frame)
    return vec if R is None else np.einsum("nji,nj->ni", R, vec)


def point_kinematics(sys, fr, target, with_acc=True):
    """Ground position, velocity, acceleration (N, 3) of a body CM or marker origin (acceleration None
    when the frames hold none, or with_acc=False: then a result's lazy accelerations stay uncomputed)."""
    fid, s_B, _ = locate(sys, target)
    A = fr.A[:, fid]
    s = A @ s_B
    w = fr.w[:, fid]
    pos = fr.r[:, fid] + s
    vel = fr.rd[:, fid] + cross(w, s)
    acc = None
    if with_acc and fr.rdd is not None:
        acc = fr.rdd[:, fid] + cross(fr.alpha[:, fid], s) + cross(w, cross(w, s))
    return pos, vel, acc


def position(sys, fr, target, frame=None):
    """Position [m] of target, in ground or relative to `frame` in its axes."""
    pos = point_kinematics(sys, fr, target, False)[0]
    if frame is None:
        return pos
    return express(sys, fr, pos - point_kinematics(sys, fr, frame, False)[0], frame)


def flat(fr: Frames, bi, bj):
    """Flatten time into the frame axis so per-row primitives run over all samples at once."""
    N, nf = fr.r.shape[:2]
    out = Frames(fr.r.reshape(-1, 3), fr.A.reshape(-1, 3, 3), fr.rd.reshape(-1, 3), fr.w.reshape(-1, 3))
    base = np.arange(N) * nf
    return out, base + bi, base + bj


def joint_coordinate(sys, fr, joint, dof=None):
    """Joint coordinate samples: angle [rad] of j about the axis (wrapped) and/or slide [m].

    Returns (angle (N,) or None, angle_rate (N,) or None, slide (N,) or None, slide_rate (N,) or None)."""
    g = sys.geoms[joint.name]
    N = fr.r.shape[0]
    ff, bi, bj = flat(fr, g.bi, g.bj)
    rep = lambda x: np.broadcast_to(x, (N, 3))  # noqa: E731
    ang = angd = sl = sld = None
    if is_angle(joint.kind) and not g.particle_j:
        ang, _, angd = pr.angle(ff, bi, bj, rep(g.f_i), rep(g.g_i), rep(g.f_j))
    if has_slide(joint.kind):
        rows = pr.dot2(ff, bi, bj, rep(g.h_i), rep(g.s_i), rep(g.s_j))
        sl, sld = rows.phi, rows.rate
    return ang, angd, sl, sld


def kinetic_energy(sys, v) -> np.ndarray:
    """Total kinetic energy (N,) [J] straight from the velocity variables v (N, nv): CM velocities [m/s,
    ground axes] and body-axes angular velocities [rad/s] (no rotation matrices needed)."""
    v = np.atleast_2d(np.asarray(v, dtype=float))
    rd = v[:, sys.rd_idx]
    T = 0.5 * np.einsum("b,nbi,nbi->n", sys.mass[1:], rd, rd)
    if len(sys.rigid_fid):
        w_B = v[:, sys.w_idx]
        T += 0.5 * np.einsum("nri,rij,nrj->n", w_B, sys.inertia_B[sys.rigid_fid], w_B)
    return T


def gravity_potential(sys, q) -> np.ndarray:
    """Gravity potential energy (N,) [J] from the coordinates q (N, nq), zero at the ground origin."""
    r = np.atleast_2d(np.asarray(q, dtype=float))[:, sys.r_idx]
    return -np.einsum("b,nbi,i->n", sys.mass[1:], r, np.asarray(sys.model.gravity, dtype=float))


def relative_rotation_vector(sys, fr, joint):
    """Rotation vector [rad] (N, 3) of body_j relative to its initial attitude w.r.t. body_i, in body_i axes."""
    from scipy.spatial.transform import Rotation
    g = sys.geoms[joint.name]
    R0 = joint.body_i.orientation.T @ joint.body_j.orientation
    Ai, Aj = fr.A[:, g.bi], fr.A[:, g.bj]
    R = np.einsum("nji,njk->nik", Ai, Aj) @ R0.T
    return Rotation.from_matrix(R).as_rotvec()


def relative_angular_velocity(sys, fr, joint):
    """Angular velocity [rad/s] of j relative to i and its derivative [rad/s^2] (N, 3), body_i axes."""
    g = sys.geoms[joint.name]
    Ai = fr.A[:, g.bi]
    dw = fr.w[:, g.bj] - fr.w[:, g.bi]
    w_rel = np.einsum("nji,nj->ni", Ai, dw)
    acc = None
    if fr.alpha is not None:
        w_iB = np.einsum("nji,nj->ni", Ai, fr.w[:, g.bi])
        acc = np.einsum("nji,nj->ni", Ai, fr.alpha[:, g.bj] - fr.alpha[:, g.bi]) - np.cross(w_iB, w_rel)
    return w_rel, acc


def planar_coordinates(sys, fr, joint):
    """[u, v, angle] (N, 3) of a planar joint (u, v along f_i, g_i [m]; angle about h_i [rad], wrapped)
    and their rates (N, 3)."""
    g = sys.geoms[joint.name]
    N = fr.r.shape[0]
    ff, bi, bj = flat(fr, g.bi, g.bj)
    rep = lambda x: np.broadcast_to(x, (N, 3))  # noqa: E731
    U = pr.dot2(ff, bi, bj, rep(g.f_i), rep(g.s_i), rep(g.s_j))
    V = pr.dot2(ff, bi, bj, rep(g.g_i), rep(g.s_i), rep(g.s_j))
    u, v, ud, vd = U.phi, V.phi, U.rate, V.rate
    if g.particle_j:
        z = np.zeros(N)
        return np.stack([u, v, z], -1), np.stack([ud, vd, z], -1)
    ang, _, angd = pr.angle(ff, bi, bj, rep(g.f_i), rep(g.g_i), rep(g.f_j))
    return np.stack([u, v, np.unwrap(ang)], -1), np.stack([ud, vd, angd], -1)

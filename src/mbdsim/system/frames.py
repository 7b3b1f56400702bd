"""Body frames from coordinates: positions, rotations, velocities of every body (ground = index 0).

All arrays carry optional leading axes (time samples).  Frame index k+1 is system body k.
r: CM position [m]; A: body->ground rotation; rd: CM velocity [m/s]; w: angular velocity in ground
axes [rad/s]; rdd [m/s^2] and alpha [rad/s^2] (ground axes) when accelerations are given.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import kernels


@dataclass
class Frames:
    """Kinematic state of every body frame, ground at index 0."""

    r: np.ndarray
    A: np.ndarray
    rd: np.ndarray
    w: np.ndarray
    rdd: np.ndarray | None = None
    alpha: np.ndarray | None = None
    # context some evaluators need, set by the caller when known: time(s) [s], the state the frames
    # come from, and the auxiliary (path-parameter) coordinates and rates
    t: np.ndarray | float | None = None
    q: np.ndarray | None = None
    v: np.ndarray | None = None
    aux_q: np.ndarray | None = None
    aux_v: np.ndarray | None = None
    # a Result's frames: angle(joint) -> the joint's angle [rad] at these samples, continued in time by
    # the Result (force-element measures take it instead of the anchors a run's events left)
    angle: object = None


def body_frames(sys, q, v=None, vd=None) -> Frames:
    """Frames of all bodies from q (..., nq), v (..., nv) and optionally vd (..., nv)."""
    q = np.asarray(q, dtype=float)
    if q.ndim == 1 and vd is None:   # one state: compiled; time axes: numpy below
        vv = np.zeros(sys.nv) if v is None else np.asarray(v, dtype=float)
        return Frames(*kernels.frames_kernel(q, vv, sys.r_idx, sys.p_idx, sys.rd_idx, sys.w_idx,
                                             sys.rigid_fid, sys.nbody + 1))
    lead = q.shape[:-1]
    n = sys.nbody + 1
    r = np.zeros(lead + (n, 3))
    rd = np.zeros(lead + (n, 3))
    w = np.zeros(lead + (n, 3))
    r[..., 1:, :] = q[..., sys.r_idx]
    rig = sys.rigid_fid
    all_rigid = _all_rigid(sys)
    A = np.zeros(lead + (n, 3, 3))
    A[..., 0, 0], A[..., 1, 1], A[..., 2, 2] = 1.0, 1.0, 1.0
    R = None
    if len(rig):
        R = _rotations(q[..., sys.p_idx])
        if all_rigid:
            A[..., 1:, :, :] = R
        else:
            A[..., rig, :, :] = R
    fr = Frames(r, A, rd, w)
    if v is not None:
        v = np.asarray(v, dtype=float)
        rd[..., 1:, :] = v[..., sys.rd_idx]
        if R is not None:
            if all_rigid:
                w[..., 1:, :] = _rotate(R, v[..., sys.w_idx])
            else:
                w[..., rig, :] = _rotate(R, v[..., sys.w_idx])
    if vd is not None:
        fr.rdd, fr.alpha = acceleration_terms(sys, A, vd)
    return fr


def acceleration_terms(sys, A, vd):
    """(rdd, alpha) (..., nbody + 1, 3) [m/s^2, rad/s^2], ground axes, of every frame from the rotations
    A (..., nbody + 1, 3, 3) and the accelerations of the velocity variables vd (..., nv)."""
    vd = np.asarray(vd, dtype=float)
    lead, n = A.shape[:-3], A.shape[-3]
    rdd, alpha = np.zeros(lead + (n, 3)), np.zeros(lead + (n, 3))
    rdd[..., 1:, :] = vd[..., sys.rd_idx]
    rig = sys.rigid_fid
    if len(rig) and _all_rigid(sys):
        alpha[..., 1:, :] = _rotate(A[..., 1:, :, :], vd[..., sys.w_idx])
    elif len(rig):
        alpha[..., rig, :] = _rotate(A[..., rig, :, :], vd[..., sys.w_idx])
    return rdd, alpha


def _all_rigid(sys) -> bool:
    """Whether every body is rigid, in frame order (rigid_fid = 1..nbody): slices instead of fancy
    indexing (cached in sys.derived)."""
    flag = sys.derived.get("all rigid")
    if flag is None:
        rig = np.asarray(sys.rigid_fid)
        flag = sys.derived["all rigid"] = bool(np.array_equal(rig, np.arange(1, sys.nbody + 1)))
    return flag


def _rotations(p):
    """Rotation matrices (..., 3, 3), body -> ground, of the Euler parameters p (..., 4) normalised first
    (the arithmetic of math.rotation.quat_to_matrix, written into one array)."""
    p = p / np.sqrt(np.add.reduce(p * p, axis=-1, keepdims=True))   # = np.linalg.norm(p, axis=-1)
    e0, e1, e2, e3 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    s0, s1, s2, s3 = e0 * e0, e1 * e1, e2 * e2, e3 * e3
    e12, e03, e13, e02, e23, e01 = e1 * e2, e0 * e3, e1 * e3, e0 * e2, e2 * e3, e0 * e1
    R = np.empty(p.shape[:-1] + (3, 3))
    R[..., 0, 0] = s0 + s1 - s2 - s3
    R[..., 0, 1] = 2 * (e12 - e03)
    R[..., 0, 2] = 2 * (e13 + e02)
    R[..., 1, 0] = 2 * (e12 + e03)
    R[..., 1, 1] = s0 - s1 + s2 - s3
    R[..., 1, 2] = 2 * (e23 - e01)
    R[..., 2, 0] = 2 * (e13 - e02)
    R[..., 2, 1] = 2 * (e23 + e01)
    R[..., 2, 2] = s0 - s1 - s2 + s3
    return R


def _rotate(R, x):
    """R x for stacks of matrices R (..., 3, 3) and vectors x (..., 3)."""
    return np.einsum("...ij,...j->...i", R, x)


def cross(a, b):
    """Cross products a x b of stacks of 3-vectors (..., 3) (np.cross's arithmetic, without its axis
    handling: several times faster on the short stacks of a Result)."""
    if a.ndim == 1 and b.ndim == 1:   # two 3-vectors (the loads of one state): float arithmetic
        a0, a1, a2 = a.tolist()
        b0, b1, b2 = b.tolist()
        return np.array((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(a.shape if a.shape == b.shape else np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def point_state(fr: Frames, fid, s_B, acceleration=True):
    """Ground position, velocity and (if available, and asked for) acceleration of points s_B [m] fixed on
    frames fid (acceleration=False: None, without computing a Result's accelerations for lazy frames)."""
    A = fr.A[..., fid, :, :]
    # (one state and one point: .dot, a fraction of einsum's cost on a 3x3)
    s = A.dot(s_B) if A.ndim == 2 and np.ndim(s_B) == 1 else np.einsum("...ij,...j->...i", A, s_B)
    w = fr.w[..., fid, :]
    pos = fr.r[..., fid, :] + s
    vel = fr.rd[..., fid, :] + cross(w, s)
    acc = None
    if acceleration and fr.rdd is not None:
        acc = fr.rdd[..., fid, :] + cross(fr.alpha[..., fid, :], s) + cross(w, cross(w, s))
    return pos, vel, acc

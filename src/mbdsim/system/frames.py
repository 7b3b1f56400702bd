"""Body frames from coordinates: positions, rotations, velocities of every body (ground = index 0).

All arrays carry optional leading axes (time samples).  Frame index k+1 is system body k.
r: CM position [m]; A: body->ground rotation; rd: CM velocity [m/s]; w: angular velocity in ground
axes [rad/s]; rdd [m/s^2] and alpha [rad/s^2] (ground axes) when accelerations are given.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..math.rotation import quat_to_matrix
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
    A = np.broadcast_to(np.eye(3), lead + (n, 3, 3)).copy()
    rd = np.zeros(lead + (n, 3))
    w = np.zeros(lead + (n, 3))
    r[..., 1:, :] = q[..., sys.r_idx]
    rig = sys.rigid_fid
    if len(rig):
        p = q[..., sys.p_idx]
        p = p / np.linalg.norm(p, axis=-1, keepdims=True)
        A[..., rig, :, :] = quat_to_matrix(p)
    if v is not None:
        v = np.asarray(v, dtype=float)
        rd[..., 1:, :] = v[..., sys.rd_idx]
        if len(rig):
            w[..., rig, :] = np.einsum("...ij,...j->...i", A[..., rig, :, :], v[..., sys.w_idx])
    fr = Frames(r, A, rd, w)
    if vd is not None:
        vd = np.asarray(vd, dtype=float)
        fr.rdd = np.zeros(lead + (n, 3))
        fr.alpha = np.zeros(lead + (n, 3))
        fr.rdd[..., 1:, :] = vd[..., sys.rd_idx]
        if len(rig):
            fr.alpha[..., rig, :] = np.einsum("...ij,...j->...i", A[..., rig, :, :], vd[..., sys.w_idx])
    return fr


def point_state(fr: Frames, fid, s_B):
    """Ground position, velocity and (if available) acceleration of points s_B [m] fixed on frames fid."""
    A = fr.A[..., fid, :, :]
    s = np.einsum("...ij,...j->...i", A, s_B)
    w = fr.w[..., fid, :]
    pos = fr.r[..., fid, :] + s
    vel = fr.rd[..., fid, :] + np.cross(w, s)
    acc = None
    if fr.rdd is not None:
        acc = fr.rdd[..., fid, :] + np.cross(fr.alpha[..., fid, :], s) + np.cross(w, np.cross(w, s))
    return pos, vel, acc

"""Euler parameters (unit quaternions, scalar first) and rotation helpers.

Convention: p = (e0, e1, e2, e3) maps body vectors to ground, v_G = A(p) v_B, and
pdot = 1/2 p (x) (0, w_B) with w_B the angular velocity expressed in body axes [rad/s].
"""
from __future__ import annotations

import math

import numpy as np


def skew(a: np.ndarray) -> np.ndarray:
    """Skew matrices a~ with a~ b = a x b; a of shape (..., 3) -> (..., 3, 3)."""
    a = np.asarray(a, dtype=float)
    z = np.zeros(a.shape[:-1])
    return np.stack([
        np.stack([z, -a[..., 2], a[..., 1]], -1),
        np.stack([a[..., 2], z, -a[..., 0]], -1),
        np.stack([-a[..., 1], a[..., 0], z], -1),
    ], -2)


def quat_to_matrix(p: np.ndarray) -> np.ndarray:
    """Rotation matrices A(p), body -> ground, from Euler parameters (..., 4) -> (..., 3, 3)."""
    p = np.asarray(p, dtype=float)
    e0, e1, e2, e3 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    return np.stack([
        np.stack([e0*e0 + e1*e1 - e2*e2 - e3*e3, 2*(e1*e2 - e0*e3), 2*(e1*e3 + e0*e2)], -1),
        np.stack([2*(e1*e2 + e0*e3), e0*e0 - e1*e1 + e2*e2 - e3*e3, 2*(e2*e3 - e0*e1)], -1),
        np.stack([2*(e1*e3 - e0*e2), 2*(e2*e3 + e0*e1), e0*e0 - e1*e1 - e2*e2 + e3*e3], -1),
    ], -2)


def matrix_to_quat(A: np.ndarray) -> np.ndarray:
    """Euler parameters (scalar first, e0 >= 0) of a rotation matrix (3, 3) (Shepperd's method: the
    largest of the four squared components first, so no division by a small number)."""
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = np.asarray(A, dtype=float).tolist()
    tr = a00 + a11 + a22
    k = max(range(4), key=(tr, a00, a11, a22).__getitem__)
    if k == 0:
        s = 2.0 * math.sqrt(max(1.0 + tr, 0.0))
        p = (0.25 * s, (a21 - a12) / s, (a02 - a20) / s, (a10 - a01) / s)
    elif k == 1:
        s = 2.0 * math.sqrt(max(1.0 + a00 - a11 - a22, 0.0))
        p = ((a21 - a12) / s, 0.25 * s, (a01 + a10) / s, (a02 + a20) / s)
    elif k == 2:
        s = 2.0 * math.sqrt(max(1.0 + a11 - a00 - a22, 0.0))
        p = ((a02 - a20) / s, (a01 + a10) / s, 0.25 * s, (a12 + a21) / s)
    else:
        s = 2.0 * math.sqrt(max(1.0 + a22 - a00 - a11, 0.0))
        p = ((a10 - a01) / s, (a02 + a20) / s, (a12 + a21) / s, 0.25 * s)
    p = np.array(p)
    p /= np.linalg.norm(p)
    return p if p[0] >= 0 else -p


def cross3(a, b) -> np.ndarray:
    """Cross product of two 3-vectors (a few times faster than np.cross on single vectors)."""
    a0, a1, a2 = a
    b0, b1, b2 = b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Quaternion products a (x) b, scalar first, broadcasting over leading axes."""
    a0, av = a[..., :1], a[..., 1:]
    b0, bv = b[..., :1], b[..., 1:]
    s = a0 * b0 - np.sum(av * bv, -1, keepdims=True)
    v = a0 * bv + b0 * av + np.cross(av, bv)
    return np.concatenate([s, v], -1)


def quat_exp(theta: np.ndarray) -> np.ndarray:
    """Unit quaternion of the rotation vector theta (..., 3) [rad]."""
    theta = np.asarray(theta, dtype=float)
    ang = np.linalg.norm(theta, axis=-1, keepdims=True)
    half = 0.5 * ang
    # sin(x/2)/x with a series near zero
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(ang > 1e-8, np.sin(half) / np.where(ang > 0, ang, 1.0), 0.5 - ang**2 / 48.0)
    return np.concatenate([np.cos(half), k * theta], -1)


def quat_rate(p: np.ndarray, w_B: np.ndarray) -> np.ndarray:
    """Time derivative of Euler parameters, pdot = 1/2 p (x) (0, w_B) [1/s]."""
    w4 = np.concatenate([np.zeros(w_B.shape[:-1] + (1,)), w_B], -1)
    return 0.5 * quat_mul(p, w4)


def as_matrix(orientation) -> np.ndarray:
    """Accept None, a 3x3 matrix or a scipy Rotation; return a proper orthonormal 3x3 matrix."""
    if orientation is None:
        return np.eye(3)
    if type(orientation).__module__.startswith("scipy.spatial"):   # a scipy Rotation (not imported here)
        return orientation.as_matrix()
    A = np.asarray(orientation, dtype=float)
    if A.shape != (3, 3):
        raise ValueError(f"orientation must be a 3x3 matrix or scipy Rotation, got shape {A.shape}")
    if not np.allclose(A @ A.T, np.eye(3), atol=1e-9) or np.linalg.det(A) < 0:
        raise ValueError("orientation matrix is not a proper rotation (orthonormal, det = +1)")
    return A


def perpendicular_frame(h: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Right-handed orthonormal (f, g, h) with h the given unit axis (deterministic choice of f)."""
    h = np.asarray(h, dtype=float)
    h = h / math.sqrt(h.dot(h))          # as np.linalg.norm
    a0, a1, a2 = (abs(x) for x in h.tolist())
    trial = _UNIT[0 if a0 <= a1 and a0 <= a2 else (1 if a1 <= a2 else 2)]   # np.argmin: the first least
    f = cross3(trial, h)
    f /= math.sqrt(f.dot(f))
    g = cross3(h, f)
    return f, g, h


_UNIT = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

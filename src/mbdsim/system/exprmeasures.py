"""Values of load-expression measures (mbdsim.model.loadexpr) from frames, numpy (reference path).

Frames carry a leading time axis (N, nframes, ...); `measure_values` returns (N,). The compiled
kernel (system.exprloads_kernel) computes the same quantities one state at a time; the tests check
that both agree and that the measures are the derivatives of one another (finite differences).
"""
from __future__ import annotations

import numpy as np

from ..model.loadexpr import ACCEL, ANGLES, ANGULAR, POSITION, TIME_NAMES, VELOCITY
from .measures import locate


def _axes(sys, fr, target):
    """Rotation (N, 3, 3) target axes -> ground (identity for ground)."""
    N = fr.r.shape[0]
    if target is None:
        return np.broadcast_to(np.eye(3), (N, 3, 3))
    f, _, R = locate(sys, target)
    return fr.A[:, f] @ R


def _point(sys, fr, target, acc=False):
    """Ground position, velocity (and acceleration) (N, 3) of a target's origin (zeros for ground)."""
    N = fr.r.shape[0]
    if target is None:
        z = np.zeros((N, 3))
        return z, z, z
    f, s_B, _ = locate(sys, target)
    s = fr.A[:, f] @ s_B
    w = fr.w[:, f]
    a = None
    if acc:
        if getattr(fr, "rdd", None) is None:
            raise ValueError("accelerations are not available for these frames")
        a = fr.rdd[:, f] + np.cross(fr.alpha[:, f], s) + np.cross(w, np.cross(w, s))
    return fr.r[:, f] + s, fr.rd[:, f] + np.cross(w, s), a


def _omega(sys, fr, target):
    N = fr.r.shape[0]
    if target is None:
        return np.zeros((N, 3))
    return fr.w[:, locate(sys, target)[0]]


def _component(sys, fr, vec, k, comp):
    return np.einsum("ni,ni->n", _axes(sys, fr, k)[:, :, comp], vec)


def measure_values(sys, fr, m, joint_value=None) -> np.ndarray:
    """Values (N,) of Measure m on time-axis Frames; `joint_value(joint, dof, rate)` gives joint
    coordinates and rates (N,) for joint measures."""
    name = m.name
    if name == "input":   # a model input (Model.add_input): its value, constant here
        return np.full(fr.r.shape[0], float(sys.model.inputs[m.i].value))
    if m.joint is not None:
        return np.asarray(joint_value(m.joint, m.dof, m.rate), dtype=float)
    if name in POSITION or name in VELOCITY:
        pi, vi, _ = _point(sys, fr, m.i)
        pj, vj, _ = _point(sys, fr, m.j)
        d, dv = pi - pj, vi - vj
        if name == "DM":
            return np.linalg.norm(d, axis=-1)
        if name == "VM":
            return np.linalg.norm(dv, axis=-1)
        if name == "VR":
            L = np.linalg.norm(d, axis=-1)
            return np.einsum("ni,ni->n", d, dv) / np.where(L > 0, L, np.inf)
        comp = (POSITION.get(name, 0) if name in POSITION else VELOCITY[name] - 4)
        return _component(sys, fr, d if name in POSITION else dv, m.k, comp)
    if name in ANGULAR:
        dw = _omega(sys, fr, m.i) - _omega(sys, fr, m.j)
        if name == "WM":
            return np.linalg.norm(dw, axis=-1)
        return _component(sys, fr, dw, m.k, ANGULAR[name] - 9)
    if name in ACCEL:
        da = _point(sys, fr, m.i, True)[2] - _point(sys, fr, m.j, True)[2]
        return _component(sys, fr, da, m.k, ACCEL[name] - 16)
    Ri, Rj = _axes(sys, fr, m.i), _axes(sys, fr, m.j)
    dot = lambda a, b: np.einsum("ni,ni->n", Ri[:, :, a], Rj[:, :, b])  # noqa: E731
    if name == "AX":
        return np.arctan2(-dot(2, 1), dot(2, 2))
    if name == "AY":
        return np.arctan2(dot(2, 0), dot(2, 2))
    assert name in ANGLES
    return np.arctan2(dot(0, 1), dot(0, 0))


def evaluate(sys, fr, le, t, joint_value=None) -> np.ndarray:
    """Values (N,) of LoadExpr `le` at times t (N,) or a scalar t on time-axis Frames."""
    N = fr.r.shape[0]
    env = {name: np.broadcast_to(np.asarray(t, dtype=float), (N,)) for name in TIME_NAMES
           if le.expr.depends_on(name)}
    for var, m in le.measures.items():
        env[var] = measure_values(sys, fr, m, joint_value)
    with np.errstate(all="ignore"):
        return _eval_env(le.expr, env, N)


def _eval_env(expr, env, N):
    from .._exprtree import _eval
    out = _eval(expr.node, env)
    return np.array(np.broadcast_to(np.asarray(out, dtype=float), (N,)))

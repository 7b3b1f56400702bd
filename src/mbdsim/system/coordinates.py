"""Coordinate-level helpers of a System's state q (nq,) / v (nv,): Euler-parameter normalisation and
dq/dt from the velocity variables (layout: docs/theory.md section 1)."""
from __future__ import annotations

import numpy as np

from . import kernels


def normalize(sys, q):
    """Unit-normalise the Euler parameters of q (copy)."""
    q = q.copy()
    if len(sys.p_idx):
        p = q[sys.p_idx]
        q[sys.p_idx] = p / np.linalg.norm(p, axis=-1, keepdims=True)
    return q


def qdot(sys, q, v):
    """dq/dt from velocity variables: rd for positions [m/s], 1/2 p (x) (0, w_B) for Euler parameters
    [1/s] (w_B: angular velocity [rad/s] in body axes)."""
    qd = kernels.qdot_kernel(np.asarray(q, dtype=float), np.asarray(v, dtype=float), sys.r_idx,
                             sys.rd_idx, sys.p_idx, sys.w_idx, sys.nq)
    qd[sys.aux_q_idx] = v[sys.aux_v_idx]
    return qd

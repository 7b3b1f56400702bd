"""Determinate and indeterminate reaction components of redundant constraint sets (Wojtyra & Fraczek).

For rigid bodies the equations of motion fix only the generalized constraint load Q_c = phi_q^T lambda_;
with redundant constraints (phi_q rank-deficient) every lambda_ + N a, N a basis of the left null space of
phi_q (phi_q^T N = 0), gives the same motion. A reaction component r = c^T lambda_ (a force or torque
component of one joint, linear in lambda_) is *determinate* when it takes the same value for all of them,
i.e. c^T N = 0 (M. Wojtyra, J. Fraczek, "Joint reactions in rigid or flexible body mechanisms with
redundant constraints", Bull. Pol. Acad. Sci. Tech. Sci. 60(3), 2012: a reaction is unique iff it is
orthogonal to the null space of the constraint Jacobian transpose); otherwise it is *indeterminate*: the
rigid model cannot tell its value, and the number mbdsim reports (the minimum-norm lambda_) is one
arbitrary split among infinitely many.

Components are those of `Result.reaction_force` / `reaction_torque` (ground axes, or the axes of
`frame`), torque about the joint point; evaluated per output sample (the null space changes with the
configuration).
"""
from __future__ import annotations

import numpy as np

from .equations import jacobians
from .frames import body_frames
from .reactions import joint_reaction

REL_TOL = 1e-8


class IndeterminateReactionWarning(UserWarning):
    """Reaction components asked for are indeterminate (redundant constraints)."""


class ReactionArray(np.ndarray):
    """A reaction force or torque array (N, 3) with `indeterminate` (N, 3) booleans (None once reshaped)."""

    def __new__(cls, value, indeterminate):
        obj = np.asarray(value).view(cls)
        obj.indeterminate = np.asarray(indeterminate, dtype=bool)
        return obj

    def __array_finalize__(self, obj):
        ind = getattr(obj, "indeterminate", None)
        self.indeterminate = ind if ind is not None and ind.shape == self.shape else None


def left_null_space(J: np.ndarray) -> np.ndarray:
    """(N, nc, nc) columns spanning the left null space of each J (N, nc, nv) (zero columns beyond its
    dimension), by SVD with the rank tolerance of numpy.linalg.matrix_rank."""
    N_, nc, nv = J.shape
    if nc == 0:
        return np.zeros((N_, 0, 0))
    U, s, _ = np.linalg.svd(J, full_matrices=True)
    smax = s[:, :1] if s.shape[1] else np.zeros((N_, 1))
    tol = smax * max(nc, nv) * np.finfo(float).eps * 1e3
    rank = np.sum(s > tol, axis=1)
    mask = np.arange(nc)[None, :] >= rank[:, None]        # columns of U beyond the rank
    return U * mask[:, None, :]


def indeterminate_components(sys, q, joint, on=None, express=None) -> np.ndarray:
    """(N, 6) booleans: which of (Fx, Fy, Fz, Tx, Ty, Tz) of the reaction of `joint` on `on` (default body_j)
    are indeterminate at each position sample q (N, nq). `express(vec (N, 3)) -> (N, 3)` maps ground axes to
    the axes the components are reported in (Result._express with a frame)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    n = len(q)
    out = np.zeros((n, 6), dtype=bool)
    if sys.nc == 0:
        return out
    J = jacobians(sys, q)
    Nl = left_null_space(J)                                    # (n, nc, nc)
    d = int(np.max(np.count_nonzero(np.any(np.abs(Nl) > 0, axis=1), axis=1), initial=0))
    if d == 0:
        return out
    scale = np.max(np.abs(J), axis=(1, 2)) + 1e-300            # a unit multiplier's load, per sample
    A = body_frames(sys, q).A                                  # the geometry once for every direction
    for k in np.flatnonzero(np.any(Nl != 0, axis=(0, 1))):    # one null direction at a time, all samples
        lam = Nl[:, :, k]
        F, T = joint_reaction(sys, q, lam, joint, on, A=A, J=J)
        if express is not None:
            F, T = express(F), express(T)
        comp = np.abs(np.concatenate([F, T], axis=1))
        out |= comp > REL_TOL * scale[:, None] * np.maximum(1.0, _lever(sys, joint))
    return out


def _lever(sys, joint):
    """A length scale [m] for torques about the joint point (size of the mechanism's joint geometry)."""
    g = sys.geoms.get(joint if isinstance(joint, str) else joint.name)
    if g is None:
        return 1.0
    return float(max(np.linalg.norm(g.s_i), np.linalg.norm(g.s_j), 1.0))


def determinacy_report(sys, q, t=0.0) -> list:
    """[(joint name, determinate components, indeterminate components)] at the configuration q (nq,) for the
    joints of redundant constraint sets (empty when no constraint is redundant); components named
    "Fx".."Tz" in ground axes, reactions on body_j."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    J = jacobians(sys, q)
    Nl = left_null_space(J)[0]
    if not np.any(Nl):
        return []
    rows_in = np.flatnonzero(np.any(np.abs(Nl) > 1e-10, axis=1))
    owners = list(dict.fromkeys(sys.row_owner[r] for r in rows_in))
    names = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
    out = []
    for name in owners:
        if name not in sys.model.joints:
            continue
        ind = indeterminate_components(sys, q, name)[0]
        out.append((name, [c for c, b in zip(names, ind) if not b], [c for c, b in zip(names, ind) if b]))
    return out

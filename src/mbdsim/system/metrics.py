"""Scales and metrics of a System: its characteristic length, the diagonal weights of a position
increment and a positive-definite kinetic metric (memoised per System in sys.derived)."""
from __future__ import annotations

import numpy as np


def _cached(name):
    """Memoise a function of the System alone in sys.derived (arrays returned read-only)."""
    def deco(fn):
        def wrapper(sys):
            out = sys.derived.get(name)
            if out is None:
                out = fn(sys)
                if isinstance(out, np.ndarray):
                    out.setflags(write=False)
                sys.derived[name] = out
            return out
        wrapper.__name__, wrapper.__doc__ = fn.__name__, fn.__doc__
        return wrapper
    return deco


@_cached("length_scale")
def length_scale(sys) -> float:
    """Characteristic length of the model [m]: the largest distance of a joint point or marker from
    its body's CM, else the largest CM distance from the origin, else 1."""
    pts = [g.s_i for g in sys.geoms.values() if hasattr(g, "s_i")]
    pts += [g.s_j for g in sys.geoms.values() if hasattr(g, "s_j")]
    pts += [b.position for b in sys.bodies]
    if not pts:
        return 1.0
    d = np.sqrt(np.einsum("ij,ij->i", *(np.array(pts, dtype=float).reshape(-1, 3),) * 2))
    d = d[np.isfinite(d) & (d > 0)]
    return float(d.max()) if len(d) else 1.0


@_cached("position_metric")
def position_metric(sys) -> np.ndarray:
    """Diagonal weights (nv,) of a position increment: each body's mass for its CM shift [kg] and its
    principal-axis moments (floored at 1e-2 m L^2) for its rotation [kg m^2]; massless bodies weigh
    as the mean body.  Lengths and angles are so weighed by size and inertia, not raw coordinates."""
    L = length_scale(sys)
    masses = [b.mass for b in sys.bodies if b.mass > 0]
    mref = float(np.mean(masses)) if masses else 1.0
    D = np.full(sys.nv, mref)
    for k, b in enumerate(sys.bodies):
        a = sys.frame_v_adr[k + 1]
        m = b.mass if b.mass > 0 else mref
        D[a:a + 3] = m
        if not b.is_particle:
            D[a + 3:a + 6] = np.maximum(np.diag(b.inertia), 1e-2 * m * L * L)
    return D


@_cached("kinetic_metric")
def kinetic_metric(sys) -> np.ndarray:
    """The mass matrix, with the position weights standing in where it has no mass (massless bodies,
    zero moments of slender rods, curve parameters), so that it is positive definite (dense (nv, nv);
    `kinetic_parts` gives it without dense matrices)."""
    adr, blocks, extra = kinetic_parts(sys)
    M = np.diag(extra)
    for a, b in zip(adr.tolist(), blocks):
        M[a:a + 3, a:a + 3] += b
    return M


def kinetic_parts(sys):
    """The kinetic metric as (first columns (nb,), 3x3 blocks (nb, 3, 3), diagonal added (nv,)): the mass
    matrix's blocks (system.assemble.mass_blocks) plus the position weights on the diagonal entries where
    it has no mass (see kinetic_metric); O(N), kept in sys.derived."""
    out = sys.derived.get("kinetic_parts")
    if out is None:
        from .assemble import mass_blocks
        adr, blocks = mass_blocks(sys)
        diag = np.zeros(sys.nv)
        diag[(adr[:, None] + np.arange(3)).ravel()] = np.einsum("bii->bi", blocks).ravel()
        empty = diag <= 1e-12 * max(float(diag.max(initial=0.0)), 1e-300)
        extra = np.where(empty, position_metric(sys), 0.0)
        out = sys.derived["kinetic_parts"] = (adr, blocks, extra)
    return out


@_cached("geometric_scale")
def geometric_scale(sys) -> np.ndarray:
    """Column scales (nv,) that make a position increment dimensionless by the mechanism's geometry
    alone: the model's length L [m] for each CM shift [m] (dx = L dz) and for the auxiliary coordinates
    (curve parameters), 1 for each rotation [rad].  With the constraint rows normalised, the conditioning
    of J * scale is that of the mechanism's geometry, independent of the bodies' masses and inertias
    (a Stewart platform with legs of 1e-6 kg conditions as with heavy legs); used by the kinematic
    singularity test (solvers.kinematic)."""
    L = length_scale(sys)
    S = np.full(sys.nv, L)
    for k, b in enumerate(sys.bodies):
        if not b.is_particle:
            a = sys.frame_v_adr[k + 1]
            S[a + 3:a + 6] = 1.0
    return S

"""The fast paths of assembly and compilation give exactly what the general routines give: LAPACK called
directly (math.lapack) as scipy's wrappers, the vectorised row packing (system.packing) as the row-by-row
reference packing, the topology of a row subset restricted from that of all rows as computed afresh,
and Systems of the same structure sharing their topologies."""
from __future__ import annotations

import glob
import os
import warnings

import numpy as np
import pytest
import scipy.linalg as sla

from mbdsim.io import load_model
from mbdsim.math import lapack
from mbdsim.studies.models import slider_crank
from mbdsim.system import kernels, topology
from mbdsim.system.assemble import assemble_system, single_use

EXAMPLES = sorted(glob.glob(os.path.join(os.path.dirname(__file__), "..", "examples", "*.yaml")))


def _systems():
    out = []
    for path in EXAMPLES:
        try:
            model = load_model(path)
        except Exception:   # not a model file (a study description)
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out.append(assemble_system(model))
    return out + [assemble_system(slider_crank()), assemble_system(_screw_and_cv())]


def _screw_and_cv():
    """Rows of kinds 7 and 8 (screw, constant velocity) beside the others."""
    import mbdsim as mb
    m = mb.Model("screw and cv")
    m.add_body("nut", 1.0, inertia=(0.05, 0.05, 0.01), position=(0, 0, 0.1))
    m.add_screw("s", "ground", "nut", (0, 0, 0), (0, 0, 1), lead=0.01)
    m.add_body("a", 1.0, inertia=(0.1, 0.1, 0.1), position=(1, 0, 0))
    m.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1), position=(2, 0, 0.5))
    m.add_revolute("ra", "ground", "a", (1, 0, 0), (1, 0, 0))
    m.add_constant_velocity("cv", "a", "b", (1.5, 0, 0), (1, 0, 0), (2, 0, 1))
    return m


@pytest.mark.parametrize("shape", [(18, 21), (21, 18), (6, 5), (3, 7), (0, 4), (4, 0)])
def test_lapack_as_scipy(shape):
    rng = np.random.default_rng(1)
    A = rng.standard_normal(shape)
    if A.size:
        A[:, -1] = A[:, 0] + A[:, 1]   # rank deficient
    _, R, piv = sla.qr(A, mode="economic", pivoting=True)
    d, piv2 = lapack.pivoted_qr(A)
    assert np.array_equal(np.abs(np.diag(R)), d) and np.array_equal(piv, piv2)
    assert np.array_equal(sla.null_space(A), lapack.null_space(A))
    assert np.array_equal(sla.null_space(A.T), lapack.null_space(A.T))
    S = A @ A.T + np.eye(shape[0])
    b = rng.standard_normal(shape[0])
    if shape[0]:
        x = lapack.cho_solve_spd(S, b)
        assert np.allclose(x, sla.cho_solve(sla.cho_factor(S), b), rtol=1e-12, atol=0)
        assert np.allclose(S @ x, b, rtol=0, atol=1e-12 * np.abs(S).max() * np.abs(x).max())
        X = lapack.cho_solve_spd(S, np.column_stack([b, 2 * b]))
        assert np.allclose(X[:, 1], 2 * x, rtol=1e-12, atol=0)
        with pytest.raises(np.linalg.LinAlgError):
            lapack.cho_solve_spd(-S, b)
    with pytest.raises(ValueError):
        lapack.pivoted_qr(np.full((2, 2), np.nan))


def _pack_rows_loop(sys):
    """Reference for system.packing.pack_rows: the rows packed one by one (the former kernels.pack_rows).

    A point-on-curve group packs as spherical rows with V[row, 1] = the marker point s_j (body-j axes)
    and V[row, 0] = 0: the caller writes the curve point c(s) (body-i axes) there at each evaluation.
    A screw row's parameter is its lead / 2 pi.  Rows of the groups the kernel does not evaluate
    (couplers) stay ground-ground spherical rows (all zero) for the caller to overwrite."""
    nc = sys.nc
    kind = np.zeros(nc, np.int64)
    bi = np.zeros(nc, np.int64)
    bj = np.zeros(nc, np.int64)
    V = np.zeros((nc, 6, 3))
    par = np.zeros(nc)
    drv = -np.ones(nc, np.int64)
    fns = []
    for g in sys.groups:
        if g.kind not in kernels.KIND and g.kind not in ("sph", "curve"):
            continue
        three = g.kind in ("sph", "curve")
        first = 1 if g.kind == "curve" else 0      # curve: vecs[0] is the marker point s_j
        for k in range(len(g.bi)):
            r0 = g.row_adr[k]
            rows = [r0, r0 + 1, r0 + 2] if three else [r0]
            for c, r in enumerate(rows):
                kind[r] = c if three else kernels.KIND[g.kind]
                bi[r], bj[r] = g.bi[k], g.bj[k]
                for m, vec in enumerate(g.vecs):
                    V[r, first + m] = vec[k]
                if g.kind == "screw":
                    par[r] = g.fns[k] / (2 * np.pi)
                if g.kind in ("angle", "slide"):
                    drv[r] = len(fns)
                    fns.append(g.fns[k])
    return kind, bi, bj, V, par, drv, fns


def test_packing_and_topology_as_reference():
    rng = np.random.default_rng(0)
    for s in _systems():
        fast, ref = s.derived["packed"], _pack_rows_loop(s)
        for x, y in zip(fast[:6], ref[:6]):
            assert x.dtype == y.dtype and np.array_equal(x, y)
        assert all(f is g for f, g in zip(fast[6], ref[6])) and len(fast[6]) == len(ref[6])
        for _ in range(50):
            rows = np.sort(rng.choice(s.nc, rng.integers(0, s.nc + 1), replace=False))
            s.derived.pop("topologies", None)
            a, b = topology.system_topology(s, rows), topology._system_topology(s, rows)
            for k in a.__dict__:
                assert getattr(a, k).dtype == getattr(b, k).dtype and np.array_equal(getattr(a, k), getattr(b, k))


def test_structure_shared_between_variants():
    with single_use():
        s1 = assemble_system(slider_crank(crank=0.2, rod=0.5))
        s2 = assemble_system(slider_crank(crank=0.25, rod=0.45, speed=3.0))
        s3 = assemble_system(slider_crank(crank=0.2, rod=0.5).__class__("other"))   # an empty model
    assert topology.structure_key(s1) == topology.structure_key(s2) != topology.structure_key(s3)
    assert topology._full_topology(s1) is topology._full_topology(s2)
    t1 = topology.system_topology(s1, np.arange(s1.nc))
    assert t1.blk_rows is not topology._full_topology(s1).blk_rows   # handed out as copies


def test_joint_kinds_in_the_structure_key():
    """Joints of different kinds with as many rows (cylindrical and universal: 4 each) between the same
    bodies, under the same names, are different structures: nothing is shared between them."""
    import mbdsim as mb

    def model(kind):
        m = mb.Model("k", gravity=(0, -9.81, 0))
        b = m.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.0, -0.5, 0.0))
        if kind == "cylindrical":
            m.add_cylindrical("j", m.ground, b, point=(0, 0, 0), axis=(0, 0, 1))
        else:
            m.add_universal("j", m.ground, b, point=(0, 0, 0), axis_i=(0, 0, 1), axis_j=(1, 0, 0))
        return m
    with single_use():
        a, b = assemble_system(model("cylindrical")), assemble_system(model("universal"))
    assert a.nc == b.nc and list(a.row_owner) == list(b.row_owner)
    assert topology.structure_key(a) != topology.structure_key(b)

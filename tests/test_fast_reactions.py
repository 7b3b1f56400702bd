"""Cheap reaction measures (issue 12 throughput): the minimum-norm multipliers of redundant constraint sets
in one compiled call (mbdsim.solvers.minnorm) against the SVD pseudo-inverse computed here, change points
falling back to it, and reactions / determinacy with the geometry computed once equal to recomputing it."""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers.compiled_run import _full_multipliers
from mbdsim.solvers.minnorm import min_norm_multipliers
from mbdsim.studies.models import slider_crank
from mbdsim.system.equations import jacobians
from mbdsim.system.frames import body_frames
from mbdsim.system.reactions import joint_reaction


def door(revolute=False):
    """A door on two hinges 1 m apart on the vertical z axis, CM 0.5 m off it, pushed to swing; gravity -z.
    Spherical hinges leave the axial forces indeterminate; revolute ones several more components."""
    m = mb.Model("door", gravity=(0.0, 0.0, -9.81))
    d = m.add_body("door", 10.0, inertia=(1.0, 1.2, 0.8), position=(0.5, 0.0, 0.5), angular_velocity=(0, 0, 1.0))
    add = (lambda n, p: m.add_revolute(n, m.ground, d, p, (0, 0, 1))) if revolute else \
        (lambda n, p: m.add_spherical(n, m.ground, d, p))
    add("top", (0, 0, 1))
    add("bottom", (0, 0, 0))
    return m


def four_bar_tilted():
    """A planar four-bar of 3D revolutes (three redundant rows) with gravity out of its plane, so that the
    indeterminate out-of-plane loads are not zero."""
    m = mb.Model("fourbar", gravity=(0.0, -9.81, -4.0))
    a = m.add_body("a", 1.0, inertia=(1e-3, 0.01, 0.01), position=(0.0, 0.1, 0.0))
    b = m.add_body("b", 2.0, inertia=(1e-3, 0.03, 0.03), position=(0.2, 0.2, 0.0))
    c = m.add_body("c", 1.5, inertia=(1e-3, 0.02, 0.02), position=(0.4, 0.15, 0.0))
    m.add_revolute("ga", m.ground, a, (0, 0, 0), (0, 0, 1))
    m.add_revolute("ab", a, b, (0, 0.2, 0), (0, 0, 1))
    m.add_revolute("bc", b, c, (0.4, 0.2, 0), (0, 0, 1))
    m.add_revolute("cg", c, m.ground, (0.4, 0.1, 0), (0, 0, 1))
    return m


MODELS = {"slider_crank": lambda: slider_crank(speed=9.0), "door_spherical": door,
          "door_revolute": lambda: door(True), "four_bar": four_bar_tilted}


def _run(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mb.simulate(MODELS[name](), 0.4, 0.01, rtol=1e-6)


def _solved(res):
    """The multipliers as the integrator solves them: its independent rows, zero on the others."""
    rows = np.asarray(res.stats["assembly"].rows)
    run = next(c.cell_contents for c in res._evaluate.__closure__ if hasattr(c.cell_contents, "outputs"))
    return rows, run.outputs(res.time, np.hstack([res.q, res.v]))[1]


@pytest.mark.parametrize("name", sorted(MODELS))
def test_min_norm_multipliers_equal_pseudo_inverse(name):
    res = _run(name)
    rows, LAM = _solved(res)
    assert len(rows) < res.system.nc                       # the models are redundant
    J = jacobians(res.system, res.q)
    load = np.einsum("nri,nr->ni", J[:, rows], LAM[:, rows])
    ref = np.einsum("nij,nj->ni", np.linalg.pinv(np.transpose(J, (0, 2, 1)), rcond=1e-10), load)   # by SVD
    out = _full_multipliers(res.system, rows, res.time, np.hstack([res.q, res.v]), None, LAM)
    scale = np.abs(ref).max()
    assert scale > 1.0 and np.abs(out - ref).max() <= 1e-11 * scale
    assert np.allclose(np.einsum("nci,nc->ni", J, out), load, rtol=0, atol=1e-10 * scale)   # same constraint load
    if name in ("door_spherical", "four_bar"):             # the split of the indeterminate rows is not trivial
        dep = np.setdiff1d(np.arange(res.system.nc), rows)
        assert np.abs(out[:, dep]).max() > 1e-3 * scale


def test_dependent_independent_rows_are_flagged():
    """A sample where the 'independent' rows are dependent (a change point) is flagged for the SVD fallback,
    and _full_multipliers then still gives the minimum-norm solution."""
    res = _run("door_spherical")
    rows, LAM = _solved(res)
    nc = res.system.nc
    J = np.ascontiguousarray(jacobians(res.system, res.q[:3]))
    J[1, rows[1]] = J[1, rows[0]]                          # sample 1: two of the rows coincide
    dep = np.setdiff1d(np.arange(nc), rows).astype(np.int64)
    out, bad = np.zeros((3, nc)), np.zeros(3, dtype=np.bool_)
    min_norm_multipliers(J, np.ascontiguousarray(LAM[:3]), rows.astype(np.int64), dep, out, bad)
    assert bad.tolist() == [False, True, False]
    ref = np.linalg.pinv(J[0].T, rcond=1e-10) @ (J[0, rows].T @ LAM[0, rows])
    assert np.allclose(out[0], ref, rtol=0, atol=1e-11 * np.abs(ref).max())


@pytest.mark.parametrize("name", sorted(MODELS))
def test_reactions_with_shared_geometry_are_identical(name):
    res = _run(name)
    sys_, lam = res.system, res.lambda_
    A, J = body_frames(sys_, res.q).A, jacobians(sys_, res.q)
    for joint in sys_.model.joints:
        F0, T0 = joint_reaction(sys_, res.q, lam, joint)
        F1, T1 = joint_reaction(sys_, res.q, lam, joint, A=A, J=J)
        assert np.array_equal(F0, F1) and np.array_equal(T0, T1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert np.array_equal(res.reaction_force(joint), F0)


def test_door_determinacy_and_newton():
    """Revolute hinges on one axis: the split of the loads between the hinges is arbitrary (every force
    component is flagged indeterminate: a couple of opposite forces trades against the hinges' moments),
    but their sum is physics: F_top + F_bottom = m (a_cm - g) at every sample."""
    res = _run("door_revolute")
    flags = res.reaction_determinacy("top")
    assert flags[:, :3].all()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        F = res.reaction_force("top") + res.reaction_force("bottom")
    expected = 10.0 * (res.acceleration("door") - np.array([0.0, 0.0, -9.81]))
    assert np.allclose(F, expected, rtol=0, atol=1e-9 * 98.1)


@pytest.mark.parametrize("name", ["slider_crank", "door_spherical"])
def test_lazy_frames_accelerations_equal_body_frames(name):
    """A compiled Result's frames get their acceleration terms on first use, on the rotation matrices
    already computed: the same arrays as body_frames with the accelerations."""
    res = _run(name)
    fr = res.frames
    full = body_frames(res.system, res.q, res.v, res.vd)
    for key in ("r", "A", "rd", "w", "rdd", "alpha"):
        assert np.array_equal(getattr(fr, key), getattr(full, key)), key
    assert np.abs(full.alpha).max() > 0 and np.abs(full.rdd).max() > 0


@pytest.mark.parametrize("name", sorted(MODELS))
def test_min_norm_kernel_per_sample_equals_pseudo_inverse(name):
    """The kernel (products over each column's nonzero rows, as _full_multipliers calls it) gives, sample
    by sample, the SVD pseudo-inverse's minimum-norm multipliers computed here; sample 1, where two of the
    independent rows coincide, is left alone (flagged for the SVD fallback, or ill-conditioned round-off
    that passes the kernel's residual check: test_dependent_independent_rows_are_flagged holds the flag)."""
    res = _run(name)
    rows, LAM = _solved(res)
    nc = res.system.nc
    J = np.ascontiguousarray(jacobians(res.system, res.q))
    J[1, rows[1]] = J[1, rows[0]]
    dep = np.setdiff1d(np.arange(nc), rows).astype(np.int64)
    LAM = np.ascontiguousarray(LAM)
    out, bad = np.zeros_like(LAM), np.zeros(len(LAM), dtype=np.bool_)
    min_norm_multipliers(J, LAM, rows.astype(np.int64), dep, out, bad)
    assert not bad[0] and not bad[2:].any()
    for k in (0, *range(2, len(LAM), max(1, len(LAM) // 7))):
        ref = np.linalg.pinv(J[k].T, rcond=1e-10) @ (J[k, rows].T @ LAM[k, rows])
        assert np.abs(out[k] - ref).max() <= 1e-11 * max(np.abs(ref).max(), 1e-300)


def test_reactions_of_one_result_build_no_dense_jacobian(monkeypatch):
    """Every reaction (and driver effort) read from a Result's multipliers needs the Jacobian rows of its
    joint at the samples: only those rows are evaluated at the Result's frames (equations.jacobian_blocks,
    O(N) per joint, issue 35), never the dense (N, nc, nv) Jacobians, also on the dense-output grids a
    refinement evaluates; the values are those of the dense computation exactly."""
    import mbdsim.system.reactions as rx
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(slider_crank(crank=0.2, rod=0.5, crank_mass=1.0, rod_mass=2.0, slider_mass=1.5,
                                       speed=6.0), 1.0, 0.01)
    fresh = {j: joint_reaction(res.system, res.q, res.lambda_, j, J=jacobians(res.system, res.q))
             for j in res.system.model.joints}
    calls = []
    monkeypatch.setattr(rx, "jacobians", lambda sys_, q: calls.append(len(q)) or jacobians(sys_, q))
    res.system.run_state.clear()
    for j in res.system.model.joints:
        F, T = res._reaction(j, None, None)
        assert np.array_equal(F, fresh[j][0]) and np.array_equal(T, fresh[j][1])
    grid = res.at(np.linspace(0.2, 0.3, 17))
    grid._reaction("crank_rod", None, None)
    effort = res.driver_effort("drive")
    assert calls == []                              # no dense Jacobian at all
    assert np.array_equal(effort, res.driver_effort("drive"))

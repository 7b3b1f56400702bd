"""Zero-DOF models solved through the LU of the square Jacobian (solvers.kkt_square): the same
accelerations, multipliers, Newton and velocity steps as the tree elimination of kkt_tree (an independent
factorisation of the same equations), the tree taking over near a change point, and the size limit."""
import warnings

import numpy as np

import mbdsim as mb
from mbdsim.solvers import common, fastdyn
from mbdsim.solvers.compiled_run import _full_multipliers
from mbdsim.system.equations import jacobians
from mbdsim.solvers.assembly import assemble_state
from mbdsim.system.assemble import assemble_system
from mbdsim.system.compiled import SQUARE_MAX, Work, compile_system
from mbdsim.studies.models import slider_crank

from test_compiled_core import _parallelogram, random_consistent_state


def _both(model, seed=0):
    """The compiled model, a random consistent state (q, v) and the arrays of the square and tree modes."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        sys, rep, q, v = random_consistent_state(model, seed)
    cm = compile_system(sys, rep.rows)
    assert rep.dof == 0 and cm.dims[4] == 2
    square = cm.arrays()
    dims = cm.dims.copy()
    dims[4] = 0
    tree = square.replace(31, dims)   # (Slots: the same kernel argument types as square)
    return sys, rep, cm, q, v, square, tree


def _sliding_particle():
    """A driven crank carrying a particle on a spherical joint at its tip: 9 velocity variables (the
    particle has translational slots only), revolute 5 + driver 1 + spherical 3 rows."""
    m = mb.Model("tip", gravity=(0, -9.81, 0))
    crank = m.add_body("crank", 2.0, (0.01, 0.02, 0.03), position=(0.15, 0.0, 0.0))
    tip = m.add_particle("tip", 0.7, position=(0.3, 0.0, 0.0))
    m.add_revolute("pivot", m.ground, crank, (0, 0, 0), (0.3, 0.2, 1.0))
    m.add_spherical("hold", crank, tip, (0.3, 0, 0))
    m.add_motion("drive", m.joints["pivot"], displacement="3*t + 0.4*sin(5*t)")
    return m


def _check_same_solves(model, seed):
    sys, rep, cm, q, v, square, tree = _both(model, seed)
    out = {}
    for name, a in (("square", square), ("tree", tree)):
        w = Work.for_model(cm).arrays()
        vd, lam = np.zeros(sys.nv), np.zeros(sys.nc)
        assert fastdyn.accelerations(a, w, 0.3, q, v, q, vd, lam, True) == fastdyn.OK
        assert (w[33][sys.nv] == 1) == (name == "square")       # which factorisation is in the work arrays
        qn = common.increment(sys, q, 1e-3 * np.random.default_rng(seed + 1).standard_normal(sys.nv))
        status, _, _ = fastdyn.newton_positions(a, w, 0.3, qn, v, 1e-13)
        assert status == fastdyn.OK
        vp = v + 0.1
        assert fastdyn.project_velocities(a, w, vp, True) == fastdyn.OK
        out[name] = (vd, lam, qn, vp)
    vd_ref, lam_ref = common.accelerations(sys, q, v, 0.3, rep.rows)   # the dense reference solve
    for vd, lam, qn, vp in out.values():
        assert np.max(np.abs(vd - vd_ref)) <= 1e-10 * (1 + np.max(np.abs(vd_ref)))
        assert np.max(np.abs(lam[rep.rows] - lam_ref[rep.rows])) <= 1e-10 * (1 + np.max(np.abs(lam_ref)))
    (_, _, q_s, v_s), (_, _, q_t, v_t) = out["square"], out["tree"]
    assert np.max(np.abs(q_s - q_t)) < 1e-12          # the same configuration (zero DOF: unique nearby)
    assert np.max(np.abs(v_s - v_t)) < 1e-10 * (1 + np.max(np.abs(v_t)))


def test_slider_crank_square_and_tree_solves_agree():
    """Redundant planar loop of 3D revolutes (21 rows, 18 independent): accelerations and the
    independent rows' multipliers against the dense reference solve; Newton and velocity projection
    give the same state through either factorisation."""
    m = slider_crank(crank=0.2, rod=0.55, crank_mass=1.2, rod_mass=2.1, slider_mass=1.4, speed=7.0)
    _check_same_solves(m, 0)
    _check_same_solves(m, 4)


def test_particle_slots_in_the_square_jacobian():
    _check_same_solves(_sliding_particle(), 2)


def test_kinematic_sweep_square_against_tree():
    """A whole driven run: the sweep through the square LU against the same sweep with the tree."""
    from mbdsim.solvers.kinsweep import KinematicRun
    m = slider_crank(crank=0.25, rod=0.45, crank_mass=0.8, rod_mass=2.5, slider_mass=1.9, speed=8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(m, 1.0, 0.01)
    sys, rep = res.system, res.stats["assembly"]
    assert res.stats["method"] == "auto: kinematic (0 DOF)"
    y0, times = np.concatenate([rep.q, rep.v]), np.linspace(0, 1, 101)
    runs = {}
    for mode in (2, 0):
        run = KinematicRun(sys, rep)
        run.cm.dims[4] = mode
        try:
            runs[mode] = run.sweep(0.0, y0, times)
        finally:
            run.cm.dims[4] = 2
    (Y2, VD2, L2, M2, n2, s2, *_), (Y0, VD0, L0, M0, n0, s0, *_) = runs[2], runs[0]
    assert n2 == n0 == 101 and s2 == s0 == fastdyn.OK
    assert np.max(np.abs(Y2 - Y0)) < 1e-11 * (1 + np.max(np.abs(Y0)))
    assert np.max(np.abs(VD2 - VD0)) < 1e-10 * (1 + np.max(np.abs(VD0)))
    assert np.array_equal(res.q, Y2[:, :sys.nq])      # simulate ran the square mode
    # the square sweep stores the minimum-norm multipliers of all 21 rows itself; the tree sweep those of
    # the 18 independent rows, completed afterwards by solvers.minnorm (Cholesky of J_r J_r^T per sample)
    assert M2.all() and not M0.any() and np.all(L0[:, np.setdiff1d(np.arange(sys.nc), rep.rows)] == 0)
    full = _full_multipliers(sys, rep.rows, times, Y0, VD0, L0)
    assert np.max(np.abs(L2 - full)) < 1e-10 * np.max(np.abs(full))
    load = lambda L: np.einsum("nri,nr->ni", jacobians(sys, Y2[:, :sys.nq]), L)  # noqa: E731 - J^T lambda_
    assert np.max(np.abs(load(L2) - load(L0))) < 1e-10 * np.max(np.abs(load(L0)))
    assert np.all(np.linalg.norm(L2, axis=1) <= np.linalg.norm(L0, axis=1) + 1e-12)  # least norm
    # outputs where the LU was not held (MN unset) are completed afterwards, the others kept as stored
    mask = np.arange(len(times)) % 3 == 0
    mixed = run.multipliers(times, Y2, VD2, np.where(mask[:, None], L2, L0), mask)
    assert np.max(np.abs(mixed - L2)) < 1e-10 * np.max(np.abs(L2))
    assert np.array_equal(mixed[mask], L2[mask])
    # the dense output (refinement grids) gives them too, and reactions read them
    mid = res.at(np.array([0.123, 0.5, 0.777]))
    for k, t in enumerate(mid.time):
        J = jacobians(sys, mid.q[k:k + 1])[0]
        _, lam_ref = common.accelerations(sys, mid.q[k], mid.v[k], t, rep.rows)   # reference solve
        lam = mid.lambda_[k]
        assert np.max(np.abs(J.T @ lam - J[rep.rows].T @ lam_ref[rep.rows])) < 1e-9 * np.max(np.abs(lam_ref))
        assert np.max(np.abs(lam - J @ np.linalg.pinv(J) @ lam)) < 1e-9 * np.max(np.abs(lam))   # least norm


def test_change_point_hands_the_factorisation_to_the_tree():
    """A driven parallelogram with its links collinear: the square Jacobian is singular there, the LU
    declines and the tree's pivoted factorisation drops the dependent loop rows."""
    m = _parallelogram(2 * np.pi)
    m.add_motion("drive", m.joints["A"], displacement="2*pi*t")
    sys, rep, cm, q, v, square, tree = _both(m)
    w = Work.for_model(cm).arrays()
    fastdyn._constraints(square, w, 0.0, rep.q, rep.v)        # assembled, crank up: regular
    assert fastdyn._factor(square, w) and w[33][sys.nv] == 1 and not fastdyn.rows_dropped(square, w)
    # a quarter turn later (t = 0.25 s) every link lies on the x axis: the run's own sample there
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(m, 0.3, 0.01)
    k = int(np.argmin(np.abs(res.time - 0.25)))
    assert abs(res.time[k] - 0.25) < 1e-12 and abs(res.position("crank")[k, 1]) < 1e-9   # collinear
    flat = res.q[k]
    fastdyn._constraints(square, w, 0.25, flat, rep.v)
    assert np.max(np.abs(w[4][rep.rows])) < 1e-12                   # on the constraints
    fastdyn._factor(square, w)
    assert w[33][sys.nv] == 0 and fastdyn.rows_dropped(square, w)


def test_only_small_zero_dof_models():
    """Above SQUARE_MAX velocity variables the tree elimination stays (the LU grows as nv^3)."""
    m = mb.Model("bolted")
    n = SQUARE_MAX // 6 + 1
    for k in range(n):
        b = m.add_body(f"b{k}", 1.0, (0.1, 0.1, 0.1), position=(k, 0, 0))
        m.add_fixed(f"f{k}", m.ground, b, (k, 0, 0))
    sys = assemble_system(m)
    rep = assemble_state(sys, sys.q0, sys.v0, 0.0)
    assert rep.dof == 0 and sys.nv > SQUARE_MAX
    assert compile_system(sys, rep.rows).dims[4] == 0

"""The compiled O(N) formulation against the reference dense KKT solve and against closed forms.

Accelerations, multipliers and reactions of the spanning-tree solve (and of its loop-row Schur
complement and dense fallback) must equal the dense augmented solve of `solvers.common` to 1e-10 on
every joint type, on trees, on closed loops with redundant joints, and through the compiled DOP853.
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers import common, dynamic, fastdyn
from mbdsim.solvers.assembly import assemble_state
from mbdsim.system.assemble import assemble_system
from mbdsim.system.compiled import NotCompiled, Work, compile_system
from mbdsim.system.topology import spanning_tree

G = (0.0, -9.81, 0.0)


def _body(m, name, pos, inertia=(0.02, 0.03, 0.04)):
    R = np.linalg.qr(np.random.default_rng(len(name)).standard_normal((3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    return m.add_body(name, mass=1.3, inertia=inertia, position=pos, orientation=R)


def _joint(m, kind, a, b, point):
    axis = np.array([0.3, -0.5, 0.8])
    if kind == "revolute":
        return m.add_revolute(kind, a, b, point, axis)
    if kind == "translational":
        return m.add_translational(kind, a, b, point, axis)
    if kind == "cylindrical":
        return m.add_cylindrical(kind, a, b, point, axis)
    if kind == "spherical":
        return m.add_spherical(kind, a, b, point)
    if kind == "universal":
        return m.add_universal(kind, a, b, point, axis, np.cross(axis, (1.0, 0, 0)))
    if kind == "planar":
        return m.add_planar(kind, a, b, point, axis)
    return m.add_fixed(kind, a, b, point)


def random_consistent_state(model, seed=0):
    """(System, AssemblyReport, q, v): the model assembled at t = 0, and a random state near the assembled
    one projected onto the constraints (positions, then velocities)."""
    sys = assemble_system(model)
    rep = assemble_state(sys, sys.q0, sys.v0, 0.0)
    rng = np.random.default_rng(seed)
    q = common.project_positions(sys, common.increment(sys, rep.q, 0.05 * rng.standard_normal(sys.nv)),
                                 0.0, rep.rows)[0]
    v = common.project_velocities(sys, q, rng.standard_normal(sys.nv), 0.0, rep.rows)
    return sys, rep, q, v


def _compare(model, seed=0, tol=1e-10):
    """Compiled vs reference accelerations and multipliers at a random consistent state."""
    sys, rep, q, v = random_consistent_state(model, seed)
    vd_ref, lam_ref = common.accelerations(sys, q, v, 0.0, rep.rows)
    cm = compile_system(sys, rep.rows)
    vd, lam = np.zeros(sys.nv), np.zeros(sys.nc)
    assert fastdyn.accelerations(cm.arrays(), Work.for_model(cm).arrays(), 0.0, q, v, q, vd, lam, True) == 0
    scale = 1.0 + np.max(np.abs(vd_ref))
    assert np.max(np.abs(vd - vd_ref)) <= tol * scale
    if len(rep.rows) == sys.nc:   # unique multipliers
        assert np.max(np.abs(lam - lam_ref)) <= tol * (1.0 + np.max(np.abs(lam_ref)))
    return cm


@pytest.mark.parametrize("kind", ["revolute", "translational", "cylindrical", "spherical", "universal",
                                  "planar", "fixed"])
@pytest.mark.parametrize("to_ground", [True, False])
def test_every_joint_type_matches_dense_solve(kind, to_ground):
    m = mb.Model("j", gravity=G)
    base = m.ground if to_ground else _body(m, "base", (0.1, 0.2, 0.3))
    b = _body(m, "b", (0.4, -0.3, 0.2))
    _joint(m, kind, base, b, (0.2, 0.1, -0.1))
    m.add_force("push", b, (1.0, -2.0, 0.5))
    m.add_spring_damper("k", m.ground, b, 40.0, 0.7, 0.3)
    cm = _compare(m)
    # no loop rows, not the dense path; a body fixed to ground has no DOF: the square Jacobian's LU
    # (kkt_square)
    assert len(cm.topo.loop_rows) == 0 and cm.dims[4] == (2 if kind == "fixed" and to_ground else 0)


def test_bushings_match_dense_solve():
    """Two bodies on a six-component bushing (rotated markers, rotated relative pose, moving): the
    compiled loads against the Python evaluator through the same equations of motion."""
    m = mb.Model("bushing", gravity=G)
    a = _body(m, "a", (0.1, 0.2, 0.3))
    b = _body(m, "b", (0.5, -0.1, 0.2))
    m.add_spherical("hold", m.ground, a, (0.0, 0.2, 0.3))
    R = np.linalg.qr(np.random.default_rng(5).standard_normal((3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    mi = a.add_marker("mi", point=(0.3, 0.0, 0.25), orientation=R)
    mj = b.add_marker("mj", point=(0.35, 0.05, 0.2), orientation=R)
    m.add_bushing("bush", mi, mj, stiffness=(1e3, 2e3, 3e3, 40.0, 50.0, 60.0), damping=(5, 6, 7, 0.1, 0.2, 0.3),
                  preload=(1.0, -2.0, 0.5, 0.1, 0.0, -0.2))
    cm = _compare(m, seed=3)
    assert len(cm.bushings[0]) == 1


def test_particles_and_free_bodies():
    m = mb.Model("p", gravity=G)
    p = m.add_particle("p", 0.7, position=(0.5, 0, 0))
    m.add_spherical("s", m.ground, p, (0.5, 0, 0))
    q = m.add_particle("q", 0.4, position=(0.9, 0.1, 0))
    m.add_translational("tr", p, q, (0.9, 0.1, 0), (1, 1, 0))
    free = _body(m, "free", (0, 1, 0))
    m.add_spring_damper("k", q, free, 10.0, 0.1, 0.5)
    _compare(m)


def four_bar(redundant: bool):
    """Planar four-bar; with 3D revolutes everywhere it has 3 redundant constraint rows."""
    m = mb.Model("fourbar", gravity=G)
    crank = _body(m, "crank", (0.0, 0.5, 0.0))
    coupler = _body(m, "coupler", (1.0, 1.0, 0.0))
    rocker = _body(m, "rocker", (2.0, 0.5, 0.0))
    z = (0, 0, 1)
    m.add_revolute("A", m.ground, crank, (0, 0, 0), z)
    m.add_revolute("B", crank, coupler, (0, 1, 0), z)
    if redundant:
        m.add_revolute("C", coupler, rocker, (2, 1, 0), z)
    else:
        m.add_spherical("C", coupler, rocker, (2, 1, 0))
    m.add_revolute("D", rocker, m.ground, (2, 0, 0), z)
    m.add_torque("drive", crank, (0, 0, 3.0))
    return m


@pytest.mark.parametrize("redundant", [False, True])
def test_closed_loop_four_bar(redundant):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        cm = _compare(four_bar(redundant))
    assert len(cm.topo.loop_rows) > 0


def test_dense_fallback_for_massless_links():
    m = mb.Model("massless", gravity=G)
    link = m.add_body("link", mass=0.0, inertia=(0, 0, 0), position=(0.5, 0, 0))
    bob = m.add_body("bob", mass=2.0, inertia=(0.01, 0.01, 0.01), position=(1.0, 0, 0))
    m.add_revolute("O", m.ground, link, (0, 0, 0), (0, 0, 1))
    m.add_fixed("weld", link, bob, (1.0, 0, 0))
    cm = _compare(m)
    assert cm.dims[4] == 1


def test_tree_with_branches_topology():
    # ground - 1 - 2, 1 - 3 - 4, plus a loop joint 4 - 2 and a floating body 5
    edges = [("a", 0, 1), ("b", 1, 2), ("c", 1, 3), ("d", 3, 4), ("loop", 4, 2)]
    rows = {"a": [0, 1], "b": [2], "c": [3], "d": [4, 5], "loop": [6, 7]}
    topo = spanning_tree(6, edges, rows)
    assert sorted(topo.order) == [1, 2, 3, 4, 5] and topo.pblk[5] == -1
    assert all(topo.pblk[f] >= 0 for f in (1, 2, 3, 4))
    assert list(topo.loop_rows) in ([6, 7], [4, 5])          # one joint of the loop closes it
    assert sorted(list(topo.blk_rows) + list(topo.loop_rows)) == list(range(8))
    pos = {f: i for i, f in enumerate(topo.order)}            # parents come before children
    assert all(topo.blk_parent[b] == 0 or pos[topo.blk_parent[b]] < pos[topo.blk_child[b]]
               for b in range(len(topo.blk_child)))


def _pendulum_chain(n, L=0.1):
    m = mb.Model("chain", gravity=G)
    prev = m.ground
    for k in range(n):
        b = m.add_body(f"rod{k}", mass=1.0, inertia=(1e-4, L * L / 12, L * L / 12), position=((k + 0.5) * L, 0, 0))
        m.add_revolute(f"j{k}", prev, b, (k * L, 0, 0), (0, 0, 1))
        prev = b
    return m


def test_compiled_simulation_matches_reference_path():
    model = _pendulum_chain(4)
    runs = {}
    for flag in (True, False):
        dynamic.USE_COMPILED = flag
        try:
            runs[flag] = mb.simulate(model, 0.5, output_step=0.05, method="dop853", rtol=1e-11, atol=1e-13)
        finally:
            dynamic.USE_COMPILED = True
    a, b = runs[True], runs[False]
    assert a.stats["method"].endswith("(compiled)") and a.success
    assert np.max(np.abs(a.q - b.q)) < 1e-8
    assert np.max(np.abs(a.reaction_force("j0") - b.reaction_force("j0"))) < 1e-6
    # dense output on demand between samples agrees with the reference's interpolant
    assert np.max(np.abs(a.at(0.123).q - b.at(0.123).q)) < 1e-8


def test_compiled_pendulum_period_and_energy():
    """Uniform rod on a pin, released horizontally: period from the complete elliptic integral."""
    from scipy.special import ellipk
    L, g = 1.0, 9.81
    m = mb.Model("rod", gravity=(0, -g, 0))
    rod = m.add_body("rod", mass=2.0, inertia=(1e-3, 2 * L * L / 12, 2 * L * L / 12), position=(L / 2, 0, 0))
    pin = m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
    res = mb.simulate(m, 2.5, output_step=0.01, method="dop853", rtol=1e-10)
    assert res.stats["method"].endswith("(compiled)")
    w0 = np.sqrt(g / (2 * L / 3))
    period = 4 * ellipk(np.sin(np.pi / 4) ** 2) / w0
    t_low = res.crossings(lambda r: r.joint_coordinate(pin), -np.pi / 2, direction=-1)
    assert abs((t_low[1] - t_low[0]) - period) < 1e-8
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E - E[0])) < 1e-8


def test_dense_output_on_demand_from_step_checkpoints():
    """Result.at between samples (the run's own steps redone from their checkpoints) agrees with a run at
    tight tolerance; at output times it gives the stored samples bit for bit; accelerations and
    multipliers, computed lazily, satisfy M vd + phi_q^T lambda = Q (rod pendulum: the pin force equals
    m (a_cm - g))."""
    L, g, mass = 1.0, 9.81, 2.0
    def model():
        m = mb.Model("rod", gravity=(0, -g, 0))
        rod = m.add_body("rod", mass=mass, inertia=(1e-3, mass * L * L / 12, mass * L * L / 12),
                         position=(L / 2, 0, 0))
        m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1))
        return m, rod
    m, rod = model()
    res = mb.simulate(m, 2.0, output_step=0.1, rtol=1e-7)
    assert res._vd is None                                # nothing computed for positions
    m2, rod2 = model()
    ref = mb.simulate(m2, 2.0, output_step=0.001, rtol=1e-12)
    tq = np.array([0.0137, 0.4321, 1.2345, 1.9999])
    got = res.at(tq)
    assert np.max(np.abs(got.position(rod) - ref.at(tq).position(rod2))) < 1e-6
    assert np.array_equal(res.at(res.time[[3, 7]]).q, res.q[[3, 7]])
    F = res.reaction_force("pin")
    a = res.acceleration(rod)
    assert np.allclose(F, mass * (a - np.array([0, -g, 0])), atol=1e-9)
    Fq = got.reaction_force("pin")
    assert np.allclose(Fq, mass * (got.acceleration(rod) - np.array([0, -g, 0])), atol=1e-9)
    assert np.max(np.abs(Fq - ref.at(tq).reaction_force("pin"))) < 1e-4 * np.max(np.abs(Fq))


def test_callable_loads_are_called_back_from_the_compiled_core():
    """A Python-callable load is not packed: the compiled model lists it for the callback
    (solvers.pyloads) and the run stays compiled."""
    m = _pendulum_chain(1)
    m.add_torque("motor", "rod0", lambda t, s: (0, 0, 0.1))
    sys = assemble_system(m)
    cm = compile_system(sys, np.arange(sys.nc))
    assert cm.python_loads == ("motor",) and len(cm.pf_f) == 0
    assert mb.simulate(m, 0.1, method="dop853").stats["method"].endswith("(compiled)")


def _parallelogram(w0, a=1.0, b=0.4):
    """Parallelogram four-bar (ground and coupler a, crank and rocker b) spinning freely at w0 [rad/s];
    every half turn it passes a change point (all links collinear), where its loop rows are dependent."""
    m = mb.Model("parallelogram")
    up = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    rod = lambda L: (1e-4, L * L / 12, L * L / 12)  # noqa: E731
    crank = m.add_body("crank", 1.0, rod(b), position=(0, b / 2, 0), orientation=up,
                       velocity=(-w0 * b / 2, 0, 0), angular_velocity=(0, 0, w0))
    coupler = m.add_body("coupler", 1.0, rod(a), position=(a / 2, b, 0), velocity=(-w0 * b, 0, 0))
    rocker = m.add_body("rocker", 1.0, rod(b), position=(a, b / 2, 0), orientation=up,
                        velocity=(-w0 * b / 2, 0, 0), angular_velocity=(0, 0, w0))
    z = (0, 0, 1)
    m.add_revolute("A", m.ground, crank, (0, 0, 0), z)
    m.add_revolute("B", crank, coupler, (0, b, 0), z)
    m.add_revolute("C", coupler, rocker, (a, b, 0), z)
    m.add_revolute("D", rocker, m.ground, (a, 0, 0), z)
    return m


def test_default_method_runs_through_change_points():
    """Free parallelogram: with no gravity its inertia is constant, so it turns at constant rate w0 and the
    coupler translates on a circle of radius b; four change points in two turns, default settings."""
    w0, b = 2 * np.pi, 0.4
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(_parallelogram(w0, b=b), 2.0, output_step=0.01)
    assert res.success and res.stats["method"].startswith("auto: DOP853")
    t = res.time
    assert np.max(np.abs(res.angular_velocity("crank")[:, 2] - w0)) < 1e-5
    assert np.max(np.abs(res.angular_velocity("rocker")[:, 2] - w0)) < 1e-5   # parallelogram branch kept
    centre = res.position("coupler")
    expected = np.stack([0.5 + b * np.cos(np.pi / 2 + w0 * t), b * np.sin(np.pi / 2 + w0 * t)], axis=1)
    assert np.max(np.abs(centre[:, :2] - expected)) < 1e-6


def test_default_method_switches_to_implicit_when_stiff():
    """An overdamped 1e9 N/m spring with 1e5 N s/m (eigenvalues near -1e4 and -1e5 1/s) under gravity:
    the explicit method is limited by stability, the automatic method hands over to HHT and the mass
    settles at the static deflection m g / k."""
    m = mb.Model("stiff", gravity=(-9.81, 0, 0))
    p = m.add_particle("p", 1.0, position=(1.0, 0, 0))
    m.add_translational("slide", m.ground, p, (1.0, 0, 0), (1, 0, 0))
    m.add_spring_damper("k", m.ground, p, 1e9, 1e5, 1.0)
    res = mb.simulate(m, 0.05, output_step=0.01)
    assert res.success and "stiffness detected" in res.stats["method"]
    assert abs(res.position(p)[-1, 0] - (1.0 - 9.81 / 1e9)) < 1e-10


def test_sparse_assembly_paths_match_dense():
    """Above DENSE_LIMIT unknowns, the row selection and minimum-norm corrections use sparse
    factorisations: same rank as the dense QR, same minimum-norm step as lstsq."""
    from mbdsim.solvers.common import DENSE_LIMIT, independent_rows, min_norm_solve
    from mbdsim.system.equations import constraint_terms
    n = DENSE_LIMIT // 6 + 10
    m = _pendulum_chain(n)
    m.add_revolute("close", "rod%d" % (n - 1), m.ground, (n * 0.1, 0, 0), (0, 0, 1))   # planar loop: redundant
    sys = assemble_system(m)
    _, J, _, _ = constraint_terms(sys, sys.q0, sys.v0, 0.0)
    sparse_rows = independent_rows(J, sys=sys)
    dense_rows = independent_rows(J)
    assert len(sparse_rows) == len(dense_rows) == np.linalg.matrix_rank(J)
    assert np.linalg.matrix_rank(J[sparse_rows]) == len(sparse_rows)
    r = J[sparse_rows] @ np.random.default_rng(0).standard_normal(sys.nv)
    x = min_norm_solve(J[sparse_rows], r)
    assert np.allclose(x, np.linalg.lstsq(J[sparse_rows], r, rcond=None)[0], atol=1e-10)


def test_expression_drivers_run_compiled_and_match_reference():
    """A slider-crank whose crank angle is driven by an expression: compiled (drivers evaluated by the
    expression interpreter) against the scipy path, and the slider against the loop-closure formula."""
    r, L = 0.1, 0.3
    m = mb.Model("slider_crank", gravity=G)
    crank = m.add_body("crank", 1.0, (1e-4, r * r / 12, r * r / 12), position=(r / 2, 0, 0))
    rod = m.add_body("rod", 1.0, (1e-4, L * L / 12, L * L / 12), position=(r + L / 2, 0, 0))
    slider = m.add_body("slider", 1.0, (1e-3, 1e-3, 1e-3), position=(r + L, 0, 0))
    pin = m.add_revolute("pin", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_revolute("crank_rod", crank, rod, (r, 0, 0), (0, 0, 1))
    m.add_revolute("rod_slider", rod, slider, (r + L, 0, 0), (0, 0, 1))
    m.add_translational("guide", m.ground, slider, (r + L, 0, 0), (1, 0, 0))
    m.add_motion("drive", pin, displacement="3*t + STEP(t, 0, 0, 0.5, 1)")
    runs = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        for flag in (True, False):
            dynamic.USE_COMPILED = flag
            try:
                runs[flag] = mb.simulate(m, 1.0, output_step=0.05, method="dop853", rtol=1e-10)
            finally:
                dynamic.USE_COMPILED = True
    a, b = runs[True], runs[False]
    assert a.stats["method"] == "DOP853 (compiled)" and a.success
    th = 3 * a.time + np.array([mb.STEP(t, 0, 0, 0.5, 1) for t in a.time])
    x = r * np.cos(th) + np.sqrt(L * L - (r * np.sin(th)) ** 2)
    assert np.max(np.abs(a.position(slider)[:, 0] - x)) < 1e-9
    assert np.max(np.abs(a.reaction_force("guide") - b.reaction_force("guide"))) < 1e-6


def _slider_crank_reference(r, L, m, g, th0, w0, times):
    """Crank angle of a free slider-crank (uniform crank and rod of mass m, slider m) from its one-DOF
    Lagrange equation J(th) th'' + J'(th) th'^2 / 2 + V'(th) = 0, derived here independently of mbdsim
    (J' and V' by complex step); integrated by scipy's DOP853 at rtol 1e-12."""
    from scipy.integrate import solve_ivp

    def kin(th):
        s = np.sqrt(L * L - (r * np.sin(th)) ** 2)
        ds = -r * r * np.sin(th) * np.cos(th) / s
        dx = -r * np.sin(th) + ds
        dphi = (s * (-r * np.cos(th)) - (-r * np.sin(th)) * ds) / (L * L)
        dG = (0.5 * (-r * np.sin(th) + dx), 0.5 * r * np.cos(th))
        return dx, dphi, dG

    def J(th):
        dx, dphi, dG = kin(th)
        crank = m * r * r / 12 + m * r * r / 4
        return crank + m * (dG[0] ** 2 + dG[1] ** 2) + m * L * L / 12 * dphi ** 2 + m * dx ** 2

    V = lambda th: g * m * (0.5 * r * np.sin(th) + 0.5 * r * np.sin(th))  # noqa: E731
    cs = lambda f, th: (f(th + 1e-30j)).imag / 1e-30  # noqa: E731

    def rhs(t, y):
        th, w = y
        return [w, -(0.5 * cs(J, th) * w * w + cs(V, th)) / J(th)]

    sol = solve_ivp(rhs, (times[0], times[-1]), [th0, w0], t_eval=times, rtol=1e-12, atol=1e-12, method="DOP853")
    return sol.y[0], kin


def test_free_slider_crank_through_dead_centres_at_default_settings():
    r, L, mass, g = 0.1, 0.3, 1.0, 9.81
    th0, w0 = np.pi / 3, 12.0
    times = np.linspace(0.0, 2.0, 201)
    ref, kin = _slider_crank_reference(r, L, mass, g, th0, w0, times)
    assert ref[-1] - ref[0] > 4 * np.pi              # at least two turns: four dead centres
    c, s = np.cos(th0), np.sin(th0)
    dx, dphi, dG = kin(th0)
    x0 = r * c + np.sqrt(L * L - (r * s) ** 2)
    phi0 = np.arctan2(-r * s, x0 - r * c)
    Rz = lambda a: [[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]  # noqa: E731
    m = mb.Model("free slider-crank", gravity=(0, -g, 0))
    rod_I = lambda l: (1e-4, mass * l * l / 12, mass * l * l / 12)  # noqa: E731
    crank = m.add_body("crank", mass, rod_I(r), position=(r / 2 * c, r / 2 * s, 0), orientation=Rz(th0),
                       velocity=(-r / 2 * s * w0, r / 2 * c * w0, 0), angular_velocity=(0, 0, w0))
    rod = m.add_body("rod", mass, rod_I(L), position=((r * c + x0) / 2, r * s / 2, 0), orientation=Rz(phi0),
                     velocity=(dG[0] * w0, dG[1] * w0, 0), angular_velocity=(0, 0, dphi * w0))
    slider = m.add_body("slider", mass, (1e-3, 1e-3, 1e-3), position=(x0, 0, 0), velocity=(dx * w0, 0, 0))
    pin = m.add_revolute("pin", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_revolute("A", crank, rod, (r * c, r * s, 0), (0, 0, 1))
    m.add_revolute("B", rod, slider, (x0, 0, 0), (0, 0, 1))
    m.add_translational("guide", m.ground, slider, (x0, 0, 0), (1, 0, 0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        res = mb.simulate(m, 2.0, output_step=0.01)
    assert res.success and res.stats["method"].startswith("auto: DOP853")
    assert res.stats.get("assembly").velocity_changed == {}            # the given velocities were consistent
    th = th0 + res.joint_coordinate(pin)
    assert np.max(np.abs(th - ref)) < 1e-6


def test_progress_callback_and_interrupt_keep_the_outputs():
    model = _pendulum_chain(3)
    seen = []
    res = mb.simulate(model, 20.0, output_step=0.01, progress=seen.append)
    assert res.success and seen == sorted(seen) and seen[-1] == pytest.approx(20.0)

    def stop(t):
        if t > 5.0:
            raise KeyboardInterrupt
    part = mb.simulate(model, 20.0, output_step=0.01, progress=stop)
    assert not part.success and "interrupted" in part.message
    n = len(part.time)
    assert 500 <= n < 2001 and np.allclose(part.q, res.q[:n], atol=1e-12)


@pytest.mark.parametrize("kwargs, field", [
    (dict(rtol=1e-30), "rtol"), (dict(start_time=float("nan")), "start_time"), (dict(start_time="a"), "start_time"),
    (dict(end_time=1e6, output_step=1e-6), "output_step")])
def test_simulate_refuses_settings_that_cannot_work(kwargs, field):
    """Issue 10 items: no hang on an impossible tolerance, no multi-terabyte allocation, named fields."""
    m = _pendulum_chain(1)
    end = kwargs.pop("end_time", 0.2)
    with pytest.raises(mb.ModelError) as err:
        mb.simulate(m, end, **kwargs)
    assert err.value.field == field

"""Couplers, gears, rack-and-pinion and user constraints between joint coordinates (issue 11).

Closed forms: a gear pair driven by a torque T (theta_1'' = T / (J_1 + J_2 ratio^2), tooth force
J_2 |theta_2''| / r_2), a three-gear train's speed ratio, a rack and pinion ((J + m R^2) theta'' = T),
a user constraint reproducing a coupler and a nonlinear one (sin(a) = 0.5 b) followed exactly over
several turns; Jacobians, nu and gamma against finite differences (the coupled angles counted past
+-pi through their auxiliary coordinates).
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelError
from mbdsim.solvers.common import increment
from mbdsim.system import assemble_system, equations
from test_core_jacobians import check_equations, fd, make_body

J1, J2, R1, R2, T = 0.02, 0.08, 0.05, 0.1, 0.3


def gear_pair(ratio=-R1 / R2):
    m = mb.Model("gears")
    m.add_body("g1", 1.0, inertia=(0.02, 0.02, J1))
    m.add_body("g2", 1.0, inertia=(0.05, 0.05, J2), position=(R1 + R2, 0, 0))
    m.add_revolute("p1", "ground", "g1", (0, 0, 0), (0, 0, 1))
    m.add_revolute("p2", "ground", "g2", (R1 + R2, 0, 0), (0, 0, 1))
    m.add_gear("mesh", "p1", "p2", ratio)
    return m


@pytest.mark.parametrize("method", ["auto", "dop853"])
def test_gear_pair_speed_ratio_and_tooth_force(method):
    m = gear_pair()
    m.add_torque("T", "g1", (0, 0, T))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = mb.simulate(m, 3.0, 0.05, method=method)
    assert "(compiled)" in res.stats["method"], res.stats["method"]   # a tree: joint coordinates (issue 29)
    r = -R1 / R2
    a1 = T / (J1 + J2 * r * r)
    t = res.time
    assert np.allclose(res.joint_coordinate("p1"), 0.5 * a1 * t**2, rtol=1e-7, atol=1e-9)   # 10 turns
    assert np.allclose(res.joint_coordinate("p2"), r * 0.5 * a1 * t**2, rtol=1e-7, atol=1e-9)
    assert np.allclose(res.joint_velocity("p2") / np.where(t > 0, res.joint_velocity("p1"), 1)[:], 
                       np.where(t > 0, r, 0), atol=1e-9)
    load = res.coupler_load("mesh")          # torques on g1 and g2 about +z
    assert np.allclose(load[:, 1], J2 * r * a1, rtol=1e-8)
    assert np.allclose(load[:, 0], -J2 * r * r * a1, rtol=1e-8)
    tooth = np.abs(load[:, 1]) / R2
    assert np.allclose(tooth, np.abs(load[:, 0]) / R1, rtol=1e-9)   # one force at the pitch point
    assert np.allclose(tooth, T * J2 / R2 * abs(r) / (J1 + J2 * r * r), rtol=1e-8)


def test_gear_train_speed_ratio_driven():
    m = gear_pair()
    m.add_body("g3", 1.0, inertia=(0.02, 0.02, 0.03), position=(R1 + 2 * R2 + 0.03, 0, 0))
    m.add_revolute("p3", "ground", "g3", (R1 + 2 * R2 + 0.03, 0, 0), (0, 0, 1))
    m.add_coupler("mesh2", "p2", "p3", -R2 / 0.03)
    m.add_motion("motor", "p1", velocity=7.0)
    res = mb.simulate(m, 2.0, 0.1, method="dop853")
    ratio = (-R1 / R2) * (-R2 / 0.03)
    assert np.allclose(res.joint_velocity("p3"), 7.0 * ratio, rtol=1e-9)
    assert np.allclose(res.joint_coordinate("p3"), 7.0 * ratio * res.time, rtol=1e-9, atol=1e-9)
    # steady speeds: no torque anywhere
    assert np.allclose(res.driver_effort("motor"), 0.0, atol=1e-9)


def test_rack_and_pinion():
    Rp, mr, Jp = 0.04, 2.5, 0.01
    m = mb.Model("rack")
    m.add_body("pinion", 1.0, inertia=(0.01, 0.01, Jp))
    m.add_body("rack", mr, inertia=(0.1, 0.1, 0.1), position=(0, -Rp, 0))
    m.add_revolute("pin", "ground", "pinion", (0, 0, 0), (0, 0, 1))
    m.add_translational("slide", "ground", "rack", (0, -Rp, 0), (-1, 0, 0))
    m.add_coupler("mesh", "pin", "slide", Rp)
    m.add_torque("T", "pinion", (0, 0, T))
    res = mb.simulate(m, 1.5, 0.05, method="dop853")
    a = T / (Jp + mr * Rp**2)
    assert np.allclose(res.joint_coordinate("pin"), 0.5 * a * res.time**2, rtol=1e-8, atol=1e-10)
    assert np.allclose(res.position("rack")[:, 0], -Rp * 0.5 * a * res.time**2, rtol=1e-8, atol=1e-10)
    load = res.coupler_load("mesh")
    assert np.allclose(load[:, 1], mr * Rp * a, rtol=1e-8)       # force pushing the rack [N]
    assert np.allclose(load[:, 0], -Rp * mr * Rp * a, rtol=1e-8)  # torque resisting the pinion [N m]


def test_user_constraint_equals_the_coupler():
    out = []
    for user in (False, True):
        m = mb.Model("g")
        m.add_body("g1", 1.0, inertia=(0.02, 0.02, J1))
        m.add_body("g2", 1.0, inertia=(0.05, 0.05, J2), position=(1, 0, 0))
        m.add_revolute("crank", "ground", "g1", (0, 0, 0), (0, 0, 1))
        m.add_revolute("rocker", "ground", "g2", (1, 0, 0), (0, 0, 1))
        if user:
            m.add_user_constraint("c", "crank - 2*rocker")
        else:
            m.add_coupler("c", "crank", "rocker", 0.5)
        m.add_torque("T", "g1", (0, 0, T))
        out.append(mb.simulate(m, 2.0, 0.1, method="dop853"))
    assert np.allclose(out[0].q, out[1].q, atol=1e-10)
    assert np.allclose(out[1].joint_coordinate("rocker"), 0.5 * out[1].joint_coordinate("crank"), atol=1e-9)
    # a user row scaled by 2 (crank - 2 rocker vs rocker - crank/2): loads are the same physical torques
    assert np.allclose(out[0].coupler_load("c"), out[1].coupler_load("c"), rtol=1e-7, atol=1e-10)


def test_nonlinear_user_constraint_followed_over_several_turns():
    """sin(a) - 0.5*b = 0 with a driven at 5 rad/s (4 turns): b = 2 sin(5 t) exactly."""
    m = mb.Model("u")
    m.add_body("A", 1.0, inertia=(0.02, 0.02, 0.03))
    m.add_body("B", 1.0, inertia=(0.1, 0.1, 0.1), position=(1, 0, 0))
    m.add_revolute("a", "ground", "A", (0, 0, 0), (0, 0, 1))
    m.add_translational("b", "ground", "B", (1, 0, 0), (0, 1, 0))
    m.add_user_constraint("link", "sin(a) - 0.5*b")
    m.add_motion("drive", "a", velocity=5.0)
    res = mb.simulate(m, 5.0, 0.05, method="dop853")
    t = res.time
    assert np.allclose(res.joint_coordinate("b"), 2 * np.sin(5 * t), atol=1e-8)
    # force on B: its mass times the acceleration -50 sin(5t) (no gravity)
    assert np.allclose(res.coupler_load("link")[:, 1], -50 * np.sin(5 * t), atol=1e-6)


def test_rheonomic_user_constraint():
    m = mb.Model("u")
    m.add_body("A", 1.0, inertia=(0.02, 0.02, 0.03))
    m.add_revolute("a", "ground", "A", (0, 0, 0), (0, 0, 1))
    m.add_user_constraint("prog", "a - 0.3*t**2")
    res = mb.simulate(m, 2.0, 0.1, method="dop853")
    assert np.allclose(res.joint_coordinate("a"), 0.3 * res.time**2, atol=1e-9)
    assert np.allclose(res.coupler_load("prog")[:, 0], 0.03 * 0.6, rtol=1e-8)


@pytest.mark.parametrize("impl", ["dispatch", "numpy"])
@pytest.mark.parametrize("case", ["gear", "rack", "user", "user_t", "cyl"])
def test_coupler_rows_against_finite_differences(case, impl):
    m = mb.Model("fd")
    b = [m.ground] + [make_body(m, f"b{k}", False, 30 + k) for k in range(3)]
    ax = np.array([0.2, -0.3, 0.9]) / np.linalg.norm([0.2, -0.3, 0.9])
    m.add_revolute("r1", b[0], b[1], (0.1, 0.2, 0.3), ax)
    m.add_revolute("r2", b[1], b[2], (0.4, -0.1, 0.2), (0, 1, 0))
    m.add_translational("s3", b[2], b[3], (0.3, 0.3, 0.3), ax)
    m.add_cylindrical("c4", b[0], b[3], (0.2, 0.2, 0.1), (1, 0, 0))
    if case == "gear":
        m.add_gear("c", "r1", "r2", -0.4)
    elif case == "rack":
        m.add_coupler("c", "r2", "s3", 0.07)
    elif case == "user":
        m.add_user_constraint("c", "sin(r1)*s3 + r2**2 - 0.1*r1")
    elif case == "user_t":
        m.add_user_constraint("c", "sin(r1)*s3 + r2**2 - 0.1*t*r1 + cos(t)")
    else:
        m.add_coupler("c", "c4", "r1", 1.5, dof_1="translation")
    sys = check_equations(m, impl=impl) if case != "user_t" else _check_rheonomic(m)
    assert sys.nc == 5 + 5 + 5 + 4 + {"gear": 3, "rack": 2, "user": 3, "user_t": 3, "cyl": 2}[case]


def _check_rheonomic(model, t0=0.7):
    """phi_q, nu, gamma against finite differences along q(s) = q (+) (s v + s^2/2 vd), t = t0 + s."""
    sys = assemble_system(model)
    rng = np.random.default_rng(3)
    q = increment(sys, sys.q0, 0.2 * rng.normal(size=sys.nv))
    v, vd = rng.normal(size=sys.nv), rng.normal(size=sys.nv)
    _, J, nu, gamma = equations.constraint_terms(sys, q, v, t0)
    phi_of = lambda qq, t: equations.constraint_terms(sys, qq, np.zeros(sys.nv), t, False)[0]  # noqa: E731
    J_fd = np.stack([fd(lambda s: phi_of(increment(sys, q, s * np.eye(sys.nv)[k]), t0), 1e-3, 1)
                     for k in range(sys.nv)], -1)
    assert np.allclose(J, J_fd, atol=1e-8)
    curve = lambda s: phi_of(increment(sys, q, s * v + 0.5 * s * s * vd), t0 + s)  # noqa: E731
    assert np.allclose(fd(curve, 1e-3, 1), J @ v - nu, atol=1e-8)
    assert np.allclose(fd(curve, 2e-3, 2), J @ vd - gamma, atol=2e-7)
    assert abs(nu[-1]) > 0.01   # the time terms are exercised
    return sys


def test_errors_name_the_coupler_and_field():
    m = gear_pair()
    m.add_spherical("ball", "ground", "g1", (0, 0, 0))
    for call, match in [
        (lambda: m.add_coupler("k", "p1", "ball", 1.0), "coupler 'k'.*joint_2.*spherical"),
        (lambda: m.add_coupler("k", "p1", "p2", 0.0), "coupler 'k'.*ratio"),
        (lambda: m.add_coupler("k", "p1", "p1", 2.0), "coupler 'k'.*joint_2.*itself"),
        (lambda: m.add_coupler("k", "p1", "nope", 2.0), "coupler 'k'.*joint_2.*nope"),
        (lambda: m.add_coupler("k", "p1", "p2", 2.0, dof_2="translation"), "coupler 'k'.*dof_2"),
        (lambda: m.add_user_constraint("k", "p1 - __import__('os')"), "user constraint 'k'.*expression"),
        (lambda: m.add_user_constraint("k", "3*t"), "user constraint 'k'.*no joint coordinate"),
        (lambda: m.add_user_constraint("k", "p1 - ball"), "user constraint 'k'.*ball.*spherical"),
    ]:
        with pytest.raises(ModelError, match=match):
            call()
        assert "k" not in m.__dict__.get("coord_constraints", {})
    with pytest.raises(ModelError, match="gear 'k'.*joint_2"):
        m.add_gear("k", "p1", "ball", -1.0)

"""Couplers, gears, rack and pinion and user coordinate constraints on the compiled joint-coordinate tree
(issue 29): every model here must report a compiled method at default settings and match its closed form
or an independent ODE of its own (scipy's solve_ivp on the reduced one-degree-of-freedom equation).

Closed forms (motion drivers of tree joints are rows of the same path: the last test):
- two-stage gear train theta_2 = r1 theta_1, theta_3 = r2 theta_2 with a torsion spring k on the output
  shaft (free angle a): T = 1/2 J_eff theta_3'^2 with J_eff = J3 + J2 / r2^2 + J1 / (r1 r2)^2, so
  theta_3 = a (1 - cos(w t)), w = sqrt(k / J_eff), from rest at theta_3 = 0;
- rack and pinion (slide x = R theta) with a vertical rack of mass m under gravity g: the reduced inertia
  J + m R^2 and the gravity torque -m g R give x'' = -m g R^2 / (J + m R^2), uniform; the rack's coupler
  load is m (x'' + g);
- a nonlinear user constraint b = c sin(a) (a revolute shaft, a slider along y under gravity -g y, a
  torsion spring k on the shaft): (J + m c^2 cos^2 a) a'' - m c^2 sin a cos a a'^2 + m g c cos a + k a = 0.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbdsim as mb

ARM = Path(__file__).parent / "import_files" / "arm.urdf"
MIMIC = '<mimic joint="finger_a_joint" multiplier="0.5" offset="0"/>'


def _compiled(res):
    assert res.success, res.message
    assert "compiled" in res.stats["method"], res.stats["method"]
    assert res.stats["formulation"].startswith("joint coordinates"), res.stats["formulation"]


def gear_train(J=(0.02, 0.05, 0.03), r1=-2.5, r2=-0.4, k=3.0, free_angle=0.4, reversed_joint=False):
    """Three shafts on revolutes about z; gears theta_2 = r1 theta_1, theta_3 = r2 theta_2; spring on shaft 3."""
    m = mb.Model("train")
    for n, (Jz, x) in enumerate(zip(J, (0.0, 0.3, 0.5)), start=1):
        m.add_body(f"s{n}", 1.0 + n, inertia=(0.03, 0.03, Jz), position=(x, 0, 0))
        if n == 2 and reversed_joint:   # body_i the shaft, body_j ground: the tree's child is body_i
            m.add_revolute(f"p{n}", f"s{n}", "ground", (x, 0, 0), (0, 0, 1))
        else:
            m.add_revolute(f"p{n}", "ground", f"s{n}", (x, 0, 0), (0, 0, 1))
    m.add_gear("mesh1", "p1", "p2", r1)
    m.add_coupler("mesh2", "p2", "p3", r2)
    m.add_torsion_spring("k", "p3", k, free_angle=free_angle)
    return m


@pytest.mark.parametrize("reversed_joint", [False, True])
def test_two_stage_gear_train_oscillates_with_the_reflected_inertia(reversed_joint):
    J1, J2, J3 = J = (0.02, 0.05, 0.03)
    r1, r2, k, a = -2.5, -0.4, 3.0, 0.4
    res = mb.simulate(gear_train(J, r1, r2, k, a, reversed_joint), 4.0, 0.01)
    _compiled(res)
    J_eff = J3 + J2 / r2**2 + J1 / (r1 * r2) ** 2
    w = np.sqrt(k / J_eff)
    t = res.time
    th1, th2, th3 = (res.joint_coordinate(f"p{n}") for n in (1, 2, 3))
    # (reversed: p2's coordinate is ground's angle about s2, so s2 turns the other way; J_eff is the same)
    exact = a * (1 - np.cos(w * t))
    assert np.max(np.abs(th3 - exact)) <= 1e-6 * a
    assert np.max(np.abs(th2 - r1 * th1)) <= 1e-9 * np.max(np.abs(th1))
    assert np.max(np.abs(th3 - r2 * th2)) <= 1e-9 * np.max(np.abs(th2))
    # the multipliers reach the Result: the output shaft's torque balance J3 theta_3'' = spring + mesh2
    load = res.coupler_load("mesh2")
    acc3 = a * w**2 * np.cos(w * t)
    assert np.allclose(J3 * acc3, -k * (th3 - a) + load[:, 1], rtol=0, atol=1e-6 * k * a)


def test_gear_train_and_single_shaft_agree_on_the_output():
    """The same output motion from one shaft carrying the reflected inertia (the bench's baseline)."""
    J1, J2, J3 = J = (0.02, 0.05, 0.03)
    r1, r2 = -2.5, -0.4
    res = mb.simulate(gear_train(J, r1, r2), 2.0, 0.05)
    _compiled(res)
    m = mb.Model("shaft")
    m.add_body("s", 1.0, inertia=(0.2, 0.2, J3 + J2 / r2**2 + J1 / (r1 * r2) ** 2))
    m.add_revolute("p", "ground", "s", (0, 0, 0), (0, 0, 1))
    m.add_torsion_spring("k", "p", 3.0, free_angle=0.4)
    one = mb.simulate(m, 2.0, 0.05)
    assert np.max(np.abs(res.joint_coordinate("p3") - one.joint_coordinate("p"))) <= 1e-6 * 0.4


def test_rack_and_pinion_under_gravity():
    R, J, mr, g = 0.05, 0.004, 2.0, 9.81
    m = mb.Model("rack", gravity=(0, -g, 0))
    m.add_body("pinion", 1.0, inertia=(0.002, 0.002, J))
    m.add_body("rack", mr, inertia=(0.1, 0.1, 0.1), position=(R, 0, 0))
    m.add_revolute("pin", "ground", "pinion", (0, 0, 0), (0, 0, 1))
    m.add_translational("slide", "ground", "rack", (R, 0, 0), (0, 1, 0))
    m.add_coupler("mesh", "pin", "slide", R)   # the rack moves with the pinion's rim: x = R theta
    res = mb.simulate(m, 1.0, 0.02)
    _compiled(res)
    acc = -mr * g * R**2 / (J + mr * R**2)
    t = res.time
    x = res.joint_coordinate("slide")
    assert np.max(np.abs(x - 0.5 * acc * t**2)) <= 1e-6 * abs(0.5 * acc)
    assert np.max(np.abs(res.position("rack")[:, 1] - 0.5 * acc * t**2)) <= 1e-6 * abs(0.5 * acc)
    assert np.max(np.abs(x - R * res.joint_coordinate("pin"))) <= 1e-12
    load = res.coupler_load("mesh")
    assert np.allclose(load[:, 1], mr * (acc + g), rtol=1e-8)       # force on the rack along its slide [N]
    assert np.allclose(load[:, 0], -R * mr * (acc + g), rtol=1e-8)  # torque on the pinion [N m]


def test_urdf_mimic_with_offset_runs_compiled(tmp_path):
    path = tmp_path / "arm_mimic.urdf"
    path.write_text(ARM.read_text().replace(MIMIC, '<mimic joint="finger_a_joint" multiplier="-2" offset="0.005"/>'))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.ImportApproximationWarning)
        model = mb.from_urdf(path, initial_displacement={"finger_a_joint": 0.002},
                             initial_velocity={"finger_a_joint": 0.3, "elbow": 1.0})
    res = mb.simulate(model, 0.3, output_step=0.01)
    _compiled(res)
    a, b = res.joint_coordinate("finger_a_joint"), res.joint_coordinate("finger_b_joint")
    assert np.ptp(a) > 1e-3
    assert np.abs(b - (-2 * a + 0.005)).max() < 1e-9
    assert b[0] == pytest.approx(-2 * 0.002 + 0.005, abs=1e-12)


def test_nonlinear_user_constraint_against_the_reduced_ode():
    Ja, mb_, c, g, k, w0 = 0.05, 1.5, 0.2, 9.81, 2.0, 3.0
    m = mb.Model("sine", gravity=(0, -g, 0))
    m.add_body("A", 1.0, inertia=(0.03, 0.03, Ja), angular_velocity=(0, 0, w0))
    m.add_body("B", mb_, inertia=(0.1, 0.1, 0.1), position=(1, 0, 0), velocity=(0, c * w0, 0))
    m.add_revolute("a", "ground", "A", (0, 0, 0), (0, 0, 1))
    m.add_translational("b", "ground", "B", (1, 0, 0), (0, 1, 0))
    m.add_user_constraint("cam", f"b - {c}*sin(a)")
    m.add_torsion_spring("k", "a", k)
    res = mb.simulate(m, 3.0, 0.01)
    _compiled(res)

    def f(t, y):
        a, ad = y
        ca, sa = np.cos(a), np.sin(a)
        return [ad, (mb_ * c * c * sa * ca * ad * ad - mb_ * g * c * ca - k * a) / (Ja + mb_ * c * c * ca * ca)]

    ref = solve_ivp(f, (0, 3.0), [0.0, w0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=res.time).y[0]
    a = res.joint_coordinate("a")
    assert np.max(np.abs(a - ref)) <= 1e-6 * np.max(np.abs(ref))
    assert np.max(np.abs(res.joint_coordinate("b") - c * np.sin(a))) <= 1e-10


@pytest.mark.parametrize("drive", ["velocity", "displacement", "acceleration", "callable"])
def test_driven_turntable_bead_on_a_rod(drive):
    """A turntable driven at Omega about z carries a bead sliding freely along a radial rod (no gravity in
    the plane): r'' = Omega^2 r, r = r0 cosh(Omega t); the drive's torque d/dt(m r^2 Omega) =
    m r0^2 Omega^2 sinh(2 Omega t). Drivers of tree joints are rows of the joint-coordinate path."""
    W, r0, mass = 2.0, 0.1, 0.5
    m = mb.Model("bead")
    m.add_body("table", 2.0, inertia=(0.05, 0.05, 0.1))
    m.add_body("bead", mass, inertia=(1e-4, 1e-4, 1e-4), position=(r0, 0, 0), velocity=(0, W * r0, 0),
               angular_velocity=(0, 0, W))
    hub = m.add_revolute("hub", "ground", "table", (0, 0, 0), (0, 0, 1))
    m.add_translational("rod", "table", "bead", (r0, 0, 0), (1, 0, 0))
    kw = {"velocity": dict(velocity=str(W)), "displacement": dict(displacement=f"{W}*t"),
          "acceleration": dict(acceleration="0", initial_velocity=W),
          "callable": dict(displacement=mb.expressions.time_function(lambda t: W * t, d1=lambda t: W,
                                                                     d2=lambda t: 0.0))}[drive]
    m.add_motion("spin", hub, **kw)
    res = mb.simulate(m, 1.5, 0.01)
    _compiled(res)
    t = res.time
    r = r0 + res.joint_coordinate("rod")
    assert np.max(np.abs(r - r0 * np.cosh(W * t))) <= 1e-6 * r0 * np.cosh(W * 1.5)
    assert np.max(np.abs(res.joint_coordinate("hub") - W * t)) <= 1e-12
    torque = mass * r0**2 * W**2 * np.sinh(2 * W * t)
    assert np.max(np.abs(np.abs(res.driver_effort("spin")) - torque)) <= 1e-6 * torque.max()

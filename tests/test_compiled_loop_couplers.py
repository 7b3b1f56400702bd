"""Issue 29: coordinate constraints, screws and torsion springs inside closed loops (absolute coordinates).

References: energy conservation (a conservative four-bar with a torsion spring on a fully turning crank:
the spring's potential 0.5 k theta^2 jumps if the angle is not continued beyond +-pi), the closed form of
a nut on a vertical screw under gravity (z'' = -g m / (m + J (2 pi / lead)^2)), and the gear kinematics
of a flywheel geared to a four-bar crank (angle_F = ratio x angle_O).
"""
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdsim as mb

sys.path.insert(0, str(Path(__file__).parent))
from test_core_four_bar import four_bar  # noqa: E402

G = 9.81


def _quiet(fn, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*a, **k)


def test_torsion_spring_on_a_four_bar_crank_through_two_turns_conserves_energy():
    model, _ = four_bar()
    model.joints["O"].initial_velocity = np.array([40.0])
    model.add_torsion_spring("ts", "O", stiffness=0.002)
    res = _quiet(mb.simulate, model, 0.35, output_step=0.005, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert "compiled" in res.stats["method"]
    th = res.joint_coordinate("O")
    assert th[-1] - th[0] > 2 * 2 * np.pi          # the crank turns more than twice
    assert np.all(np.diff(th) > 0)                   # continued, not wrapped to +-pi
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) / E[0] < 1e-8


def _screw_in_a_loop(lead=0.05, m=2.0, J=0.004):
    model = mb.Model("screw_loop", gravity=(0.0, 0.0, -G))
    nut = model.add_body("nut", m, inertia=(J, J, J), position=(0.0, 0.0, 0.0))
    model.add_screw("S", model.ground, nut, (0, 0, 0), (0, 0, 1), lead=lead)
    model.add_cylindrical("C", model.ground, nut, (0, 0, 0), (0, 0, 1))   # a second path: a loop
    return model, lead, m, J


def test_screw_joint_in_a_loop_against_its_closed_form():
    model, lead, m, J = _screw_in_a_loop()
    res = _quiet(mb.simulate, model, 0.5, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert "compiled" in res.stats["method"]
    k = 2 * np.pi / lead
    z = np.asarray(res.position("nut"))[:, 2]
    a = -G * m / (m + J * k**2)
    assert np.max(np.abs(z - 0.5 * a * res.time**2)) < 1e-9
    th = res.joint_coordinate("C")[:, 0]
    assert np.max(np.abs(th - k * z)) < 1e-8


def test_four_bar_crank_geared_to_a_flywheel_runs_compiled():
    model, _ = four_bar()
    fly = model.add_body("fly", 1.0, inertia=(0.01, 0.01, 0.02), position=(0.0, 0.0, 0.1))
    model.add_revolute("F", model.ground, fly, (0, 0, 0.1), (0, 0, 1))
    r = -2.0
    model.add_gear("g", "O", "F", r)
    res = _quiet(mb.simulate, model, 0.3, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert np.max(np.abs(res.joint_coordinate("F") - r * res.joint_coordinate("O"))) < 1e-9
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) / abs(E[0]) < 1e-8
    assert "compiled" in res.stats["method"] and "not compiled" not in res.stats["method"]


def _shafts_in_a_loop(J1=0.004, J2=0.01):
    """Shaft 1 on a revolute and a coaxial cylindrical joint (two paths to ground: a closed loop, absolute
    coordinates), shaft 2 on a revolute; both axial inertias about z, no gravity."""
    model = mb.Model("shafts_loop", gravity=(0.0, 0.0, 0.0))
    s1 = model.add_body("s1", 1.0, inertia=(J1, J1, J1), position=(0.0, 0.0, 0.0))
    s2 = model.add_body("s2", 1.0, inertia=(J2, J2, J2), position=(0.2, 0.0, 0.0))
    model.add_revolute("R1", model.ground, s1, (0, 0, 0), (0, 0, 1))
    model.add_cylindrical("C1", model.ground, s1, (0, 0, 0), (0, 0, 1))
    model.add_revolute("R2", model.ground, s2, (0.2, 0, 0), (0, 0, 1))
    return model


def test_gear_in_a_loop_driven_by_a_torque_against_its_closed_form():
    # (J1 + r^2 J2) theta_1'' = T (torque T on shaft 1, theta_2 = r theta_1): uniform angular acceleration,
    # both angles pass +-pi (continued from their auxiliary coordinates); the gear transmits J2 r theta_1''
    J1, J2, r, T, w0 = 0.004, 0.01, -2.0, 0.2, -1.0
    model = _shafts_in_a_loop(J1, J2)
    model.add_gear("g", "R1", "R2", r)
    model.add_torque("T", "s1", (0.0, 0.0, T))
    model.joints["R1"].initial_velocity = np.array([w0])
    res = _quiet(mb.simulate, model, 1.5, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert "compiled" in res.stats["method"] and "not compiled" not in res.stats["method"]
    a = T / (J1 + r**2 * J2)
    th1 = res.joint_coordinate("R1")
    assert th1.max() > np.pi and res.joint_coordinate("R2").min() < -2 * np.pi
    assert np.max(np.abs(th1 - (w0 * res.time + 0.5 * a * res.time**2))) < 1e-9
    assert np.max(np.abs(res.joint_coordinate("R2") - r * th1)) < 1e-9
    tau = res.coupler_load("g")                        # torques on shafts 1 and 2 through the mesh
    assert np.max(np.abs(tau[:, 1] - J2 * r * a)) < 1e-9
    assert np.max(np.abs(tau[:, 0] + J2 * r**2 * a)) < 1e-9


def test_rack_and_pinion_in_a_loop_against_its_closed_form():
    # rack of mass m falling along -y, driven back through a pinion (radius rp) of axial inertia J:
    # x'' = -g m / (m + J / rp^2), x = rp theta
    J, m, rp = 0.004, 0.8, 0.05
    model = _shafts_in_a_loop(J1=J)
    model.gravity = np.array([0.0, -G, 0.0])
    rack = model.add_body("rack", m, inertia=(1e-3, 1e-3, 1e-3), position=(0.0, 0.3, 0.0))
    model.add_translational("T", model.ground, rack, (0.0, 0.3, 0.0), (0, 1, 0))
    model.add_coupler("rp", "R1", "T", rp)
    res = _quiet(mb.simulate, model, 0.8, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert "compiled" in res.stats["method"] and "not compiled" not in res.stats["method"]
    a = -G * m / (m + J / rp**2)
    x = res.joint_coordinate("T")
    assert np.max(np.abs(x - 0.5 * a * res.time**2)) < 1e-9
    th = res.joint_coordinate("R1")
    assert th.min() < -np.pi                             # the pinion turns past -pi
    assert np.max(np.abs(x - rp * th)) < 1e-9


def test_nonlinear_user_constraint_in_a_loop_against_a_scipy_reduced_ode():
    # f = R2 - 0.5 R1^2 = 0, no loads: (J1 + J2 x^2) x'' + J2 x x'^2 = 0 in x = theta_1 (reduced model)
    from scipy.integrate import solve_ivp
    J1, J2, w0 = 0.004, 0.001, 6.0
    model = _shafts_in_a_loop(J1, J2)
    model.add_user_constraint("u", "R2 - 0.5*R1**2")
    model.joints["R1"].initial_velocity = np.array([w0])
    res = _quiet(mb.simulate, model, 1.0, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert "compiled" in res.stats["method"] and "not compiled" not in res.stats["method"]
    ref = solve_ivp(lambda t, y: [y[1], -J2 * y[0] * y[1] ** 2 / (J1 + J2 * y[0] ** 2)], (0, 1.0), [0.0, w0],
                    t_eval=res.time, rtol=1e-12, atol=1e-12, method="DOP853")
    th1, th2 = res.joint_coordinate("R1"), res.joint_coordinate("R2")
    assert th2.max() > 2 * np.pi                       # the second shaft turns more than once
    assert np.max(np.abs(th1 - ref.y[0])) < 1e-7
    assert np.max(np.abs(th2 - 0.5 * th1**2)) < 1e-9


def test_driven_shaft_geared_in_a_loop_kinematics_runs_compiled_through_turns():
    model = _shafts_in_a_loop()
    model.add_gear("g", "R1", "R2", -2.0)
    model.add_motion("d", "R1", displacement="3*t")
    res = _quiet(mb.kinematics, model, 3.0, output_step=0.01)
    assert res.success, res.message
    assert "compiled" in res.stats["method"]
    assert np.max(np.abs(res.joint_coordinate("R2") + 6.0 * res.time)) < 1e-9   # 18 rad: several turns


"""Issue 29: coordinate constraints whose terms move three or more bodies, in closed loops, on the compiled
core (wide rows bordered on the KKT solve: solvers.loopcoord, docs/theory.md).

References: the planetary gear set's reflected inertia (carrier angle as the one coordinate: sun
theta_s = n theta_c, n = 1 + r_r / r_s; planet about its pin phi = -(r_r / r_p) theta_c; kinetic energy
1/2 J_eff theta_c'^2, J_eff = n^2 J_s + J_c + m_p a^2 + J_p (1 - r_r / r_p)^2), a differential's 2 x 2
reduced mass matrix, and energy conservation of a conservative four-bar with a three-joint coupler.
"""
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbdsim as mb

sys.path.insert(0, str(Path(__file__).parent))
from test_core_four_bar import four_bar  # noqa: E402

RS, RP = 0.03, 0.015            # sun, planet pitch radii [m]; fixed ring r_r = r_s + 2 r_p
RR = RS + 2 * RP
A_PIN = RS + RP                 # planet pin radius on the carrier [m]
JS, JC, JP, MP = 2e-4, 5e-4, 3e-5, 0.2


def _quiet(fn, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*a, **k)


def _compiled(res):
    m = res.stats["method"]
    return "compiled" in m and "not compiled" not in m


def planetary(torque_sun=0.02, torque_carrier=-0.05):
    """Sun on a revolute and a coaxial cylindrical joint (a closed loop: absolute coordinates), carrier on a
    revolute, planet pinned on the carrier, fixed ring; sun mesh r_s (theta_s - theta_c) + r_p phi = 0 (sun,
    carrier, planet: three bodies), ring mesh r_p phi + r_r theta_c = 0; no gravity."""
    model = mb.Model("planetary", gravity=(0.0, 0.0, 0.0))
    z = (0, 0, 1)
    sun = model.add_body("sun", 0.3, inertia=(JS, JS, JS), position=(0.0, 0.0, 0.0))
    car = model.add_body("carrier", 0.5, inertia=(JC, JC, JC), position=(0.0, 0.0, 0.01))
    pl = model.add_body("planet", MP, inertia=(JP, JP, JP), position=(A_PIN, 0.0, 0.0))
    model.add_revolute("Rs", model.ground, sun, (0, 0, 0), z)
    model.add_cylindrical("Cs", model.ground, sun, (0, 0, 0), z)
    model.add_revolute("Rc", model.ground, car, (0, 0, 0.01), z)
    model.add_revolute("Rp", car, pl, (A_PIN, 0, 0), z)
    model.add_user_constraint("sun_mesh", f"{RS}*(Rs - Rc) + {RP}*Rp")
    model.add_user_constraint("ring_mesh", f"{RP}*Rp + {RR}*Rc")
    model.add_torque("Ts", "sun", (0.0, 0.0, torque_sun))
    model.add_torque("Tc", "carrier", (0.0, 0.0, torque_carrier))
    return model


def test_planetary_carrier_acceleration_from_its_reflected_inertia():
    Ts, Tc = 0.03, -0.05
    res = _quiet(mb.simulate, planetary(Ts, Tc), 1.0, output_step=0.01)   # default settings
    assert res.success, res.message
    assert _compiled(res), res.stats["method"]
    n = 1 + RR / RS
    J = n**2 * JS + JC + MP * A_PIN**2 + JP * (1 - RR / RP) ** 2
    a = (n * Ts + Tc) / J
    thc = res.joint_coordinate("Rc")
    ths = res.joint_coordinate("Rs")
    assert ths.max() > 2 * np.pi                         # the sun turns more than once (continued angles)
    assert np.max(np.abs(np.ravel(res.joint_acceleration("Rc")) - a)) < 1e-8 * abs(a)
    assert np.max(np.abs(thc - 0.5 * a * res.time**2)) < 1e-8 * np.max(np.abs(thc))
    assert np.max(np.abs(ths - n * thc)) < 1e-8
    assert np.max(np.abs(res.joint_coordinate("Rp") + RR / RP * thc)) < 1e-8
    # the sun mesh's load on the sun's coordinate (terms Rs, Rc, Rp): J_s theta_s'' = T_s + tau_s
    tau = res.coupler_load("sun_mesh")
    assert np.max(np.abs(tau[:, 0] - (JS * n * a - Ts))) < 1e-8


def test_planetary_kinematics_driven_sun_runs_compiled():
    model = planetary(0.0, 0.0)
    model.add_motion("d", "Rs", displacement="2*t")
    res = _quiet(mb.kinematics, model, 2.0, output_step=0.02)
    assert res.success, res.message
    assert "compiled" in res.stats["method"]
    n = 1 + RR / RS
    assert np.max(np.abs(res.joint_coordinate("Rc") - 2.0 * res.time / n)) < 1e-9


J1, J2, J3, T = 0.004, 0.01, 0.006, 0.3


def differential():
    """X1 + X2 + X3 = 0 between three shafts (shaft 1 on a revolute and a cylindrical joint: a loop), torque
    T on shaft 1; from rest."""
    model = mb.Model("differential", gravity=(0.0, 0.0, 0.0))
    z = (0, 0, 1)
    s = [model.add_body(f"s{k}", 1.0, inertia=(J, J, J), position=(0.2 * k, 0.0, 0.0))
         for k, J in ((1, J1), (2, J2), (3, J3))]
    model.add_revolute("R1", model.ground, s[0], (0.2, 0, 0), z)
    model.add_cylindrical("C1", model.ground, s[0], (0.2, 0, 0), z)
    model.add_revolute("R2", model.ground, s[1], (0.4, 0, 0), z)
    model.add_revolute("R3", model.ground, s[2], (0.6, 0, 0), z)
    model.add_user_constraint("u", "R1 + R2 + R3")
    model.add_torque("T", "s1", (0.0, 0.0, T))
    return model


@pytest.mark.parametrize("method", ["auto", "radau", "hht"])
def test_differential_of_three_shafts_against_its_reduced_mass_matrix(method):
    # theta_3 = -theta_1 - theta_2: [[J1 + J3, J3], [J3, J2 + J3]] [theta_1'', theta_2''] = [T, 0]
    res = _quiet(mb.simulate, differential(), 1.0, output_step=0.01, method=method)
    assert res.success, res.message
    assert _compiled(res) and method[:3] in res.stats["method"].lower(), res.stats["method"]
    a1, a2 = np.linalg.solve([[J1 + J3, J3], [J3, J2 + J3]], [T, 0.0])
    th1, th2 = res.joint_coordinate("R1"), res.joint_coordinate("R2")
    tol = 1e-5 if method == "hht" else 1e-8   # HHT at its defaults: second order, measured 2e-6
    assert np.max(np.abs(th1 - 0.5 * a1 * res.time**2)) < tol * np.max(np.abs(th1))
    assert np.max(np.abs(th2 - 0.5 * a2 * res.time**2)) < tol * np.max(np.abs(th1))
    X = th1 + th2 + res.joint_coordinate("R3")
    assert np.max(np.abs(X)) < 1e-9


def test_three_joint_coupler_in_a_four_bar_conserves_energy():
    # flywheel F = 2 O + A: its terms move the flywheel, the crank and the coupler link (three bodies)
    model, _ = four_bar()
    fly = model.add_body("fly", 0.5, inertia=(0.002, 0.002, 0.004), position=(0.0, 0.0, 0.1))
    model.add_revolute("F", model.ground, fly, (0, 0, 0.1), (0, 0, 1))
    model.add_user_constraint("u3", "F - 2*O - A")
    model.joints["O"].initial_velocity = np.array([3.0])
    res = _quiet(mb.simulate, model, 1.0, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert res.success, res.message
    assert _compiled(res), res.stats["method"]
    F = res.joint_coordinate("F")
    assert np.max(np.abs(F - 2 * res.joint_coordinate("O") - res.joint_coordinate("A"))) < 1e-9
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) / np.max(np.abs(res.kinetic_energy())) < 1e-9

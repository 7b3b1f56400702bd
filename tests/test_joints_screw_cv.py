"""Screw and constant-velocity joints against closed forms (issue 11).

Screw (lead L, c = L / 2 pi): a nut of mass m and axial moment J turned by a torque T against gravity
along the axis accelerates as theta'' = (T - m g c) / (J + m c^2) and rises by c theta; driven at a
constant rate against an axial load F the drive torque is F c and the joint carries F axially.
Constant-velocity joint: shafts bent by beta, input driven at omega: the output turns at exactly omega
(a Cardan joint would not: its output speed varies between omega cos(beta) and omega / cos(beta)).
"""
import numpy as np
import pytest

import mbdsim as mb

L, M, J, T, G = 0.012, 3.0, 0.02, 0.8, 9.81
C = L / (2 * np.pi)


def screw_model(torque=True):
    m = mb.Model("screw", gravity=(0, 0, -G))
    m.add_body("nut", M, inertia=(0.05, 0.05, J), position=(0, 0, 0.1))
    m.add_screw("s", "ground", "nut", (0, 0, 0), (0, 0, 1), lead=L)
    if torque:
        m.add_torque("T", "nut", (0, 0, T))
    return m


@pytest.mark.parametrize("method", ["auto", "dop853"])
def test_screw_torque_lifts_the_nut_as_the_closed_form(method):
    res = mb.simulate(screw_model(), 2.0, 0.05, method=method)
    assert res.stats["method"].endswith("(compiled)")   # screw rows: kernels.row_terms kind 7
    t = res.time
    acc = (T - M * G * C) / (J + M * C**2)
    th = 0.5 * acc * t**2
    assert np.allclose(res.joint_coordinate("s"), th, rtol=1e-6, atol=1e-8)   # 5.6 turns, continued
    assert np.allclose(res.position("nut")[:, 2] - 0.1, C * th, rtol=1e-6, atol=1e-10)
    assert np.allclose(res.joint_velocity("s"), acc * t, rtol=1e-6, atol=1e-8)


def test_screw_driven_against_an_axial_load():
    """Constant turning rate, axial load F (gravity) : drive torque F c, axial reaction F, power balance."""
    m = screw_model(torque=False)
    m.add_motion("drive", "s", velocity=3.0)
    res = mb.simulate(m, 1.0, 0.05, method="dop853")
    F = M * G
    assert np.allclose(res.driver_effort("drive"), F * C, rtol=1e-9)
    R = res.reaction_force("s")
    assert np.allclose(R[:, 2], F, rtol=1e-9)
    assert np.allclose(R[:, :2], 0.0, atol=1e-9)
    assert np.allclose(res.position("nut")[:, 2] - 0.1, C * 3.0 * res.time, atol=1e-10)


def test_screw_driven_in_translation():
    m = screw_model(torque=False)
    m.add_motion("push", "s", displacement="0.01*t", dof="translation")
    res = mb.simulate(m, 1.0, 0.1, method="dop853")
    assert np.allclose(res.joint_coordinate("s"), 0.01 * res.time / C, rtol=1e-9)


def cv_model(kind, beta):
    m = mb.Model("driveline")
    a_j = np.array([0.0, -np.sin(beta), np.cos(beta)])
    m.add_body("shaft1", 1.0, inertia=(0.1, 0.1, 0.02), position=(0, 0, -0.5))
    m.add_body("shaft2", 1.0, inertia=(0.1, 0.1, 0.02), position=0.5 * a_j)
    m.add_revolute("bearing1", "ground", "shaft1", (0, 0, -0.5), (0, 0, 1))
    if kind == "cv":
        m.add_constant_velocity("cv", "shaft1", "shaft2", (0, 0, 0), (0, 0, 1), a_j)
        m.add_parallel_axes("bearing2", "ground", "shaft2", a_j)      # 11 rows: no redundancy
    else:
        m.add_universal("cv", "shaft1", "shaft2", (0, 0, 0), (1, 0, 0), (0, np.cos(beta), np.sin(beta)))
        m.add_revolute("bearing2", "ground", "shaft2", 0.5 * a_j, a_j)
    m.add_motion("drive", "bearing1", velocity=2.0)
    return m, a_j


def test_constant_velocity_joint_output_speed_equals_input():
    beta = np.radians(30)
    m, a_j = cv_model("cv", beta)
    res = mb.simulate(m, 3.0, 0.02, method="dop853")
    assert res.success
    w2 = res.angular_velocity("shaft2")
    assert np.allclose(w2, 2.0 * a_j, atol=1e-8)
    # output angle = input angle: body x axis of shaft2 turned about a_j by 2 t
    x2 = res.orientation("shaft2")[:, :, 0]
    ang = np.unwrap(np.arctan2(x2 @ np.cross(a_j, [1.0, 0, 0]), x2[:, 0]))
    assert np.allclose(ang, 2.0 * res.time, atol=1e-8)
    assert mb.assemble(m).dof == 0 and not mb.assemble(m).redundant


def test_cardan_contrast_is_not_homokinetic():
    """The same driveline with a universal joint: the output speed ranges omega cos(beta)..omega/cos(beta)."""
    beta = np.radians(30)
    m, a_j = cv_model("cardan", beta)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.simulate(m, 3.2, 0.005, method="dop853")
    w = res.angular_velocity("shaft2") @ a_j
    assert w.max() == pytest.approx(2.0 / np.cos(beta), rel=1e-4)
    assert w.min() == pytest.approx(2.0 * np.cos(beta), rel=1e-4)

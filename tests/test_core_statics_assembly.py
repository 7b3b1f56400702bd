"""Core engine: static equilibrium, reactions reduced to the joint point, and the assembly report
(closed forms)."""
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

G = 9.81


def test_rod_under_torque_equilibrium_angle_and_pin_reaction():
    """T = m g (L/2) cos(theta): the rod hangs at theta = -acos(2 T / (m g L)) below the horizontal."""
    m_, L, T = 2.0, 1.0, 4.0
    model = mb.Model("rod", gravity=(0.0, -G, 0.0))
    th0 = -0.9          # near the stable (hanging) branch: Newton finds the nearest equilibrium
    c, s = np.cos(th0), np.sin(th0)
    rod = model.add_body("rod", m_, inertia=(0.01, m_ * L**2 / 12, m_ * L**2 / 12),
                         position=(L / 2 * c, L / 2 * s, 0), orientation=Rotation.from_rotvec([0, 0, th0]))
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1))
    model.add_torque("motor", rod, (0.0, 0.0, T))
    res = mb.equilibrium(model)
    assert res.success and len(res.time) == 1
    theta = th0 + res.joint_coordinate(pin)[0]
    assert theta == pytest.approx(-np.arccos(2 * T / (m_ * G * L)), abs=1e-9)
    assert np.allclose(res.reaction_force(pin)[0], [0.0, m_ * G, 0.0], atol=1e-9)
    assert np.allclose(res.reaction_torque(pin)[0], 0.0, atol=1e-9)   # the motor torque is not the pin's
    assert np.allclose(res.velocity(rod), 0.0) and np.allclose(res.acceleration(rod), 0.0)


def test_particle_on_spring_equilibrium_extension():
    """A particle hanging on a spring: extension m g / k, tension m g (force > 0 in tension)."""
    m_, k, L0 = 0.5, 200.0, 0.3
    model = mb.Model("hang", gravity=(0.0, 0.0, -G))
    ball = model.add_particle("ball", m_, position=(0, 0, -L0))
    spring = model.add_spring_damper("spring", (model.ground, (0, 0, 0)), (ball, (0, 0, -L0)), k, damping=3.0)
    res = mb.equilibrium(model)
    assert res.position(ball)[0] == pytest.approx([0, 0, -(L0 + m_ * G / k)], abs=1e-10)
    assert res.spring_length(spring)[0] == pytest.approx(L0 + m_ * G / k, abs=1e-10)
    assert res.spring_force(spring)[0] == pytest.approx(m_ * G, abs=1e-8)
    assert res.potential_energy()[0] == pytest.approx(0.5 * k * (m_ * G / k) ** 2 - m_ * G * (L0 + m_ * G / k),
                                                       abs=1e-10)


def test_cantilever_weld_reaction_reduced_to_joint_point():
    """A body welded to ground at P carries its weight: F = -m g on the body, T_P = -(r_cm - P) x m g."""
    m_ = 3.0
    g = np.array([0.0, -G, 0.0])
    P, r_cm = np.array([0.2, 0.1, -0.3]), np.array([1.2, 0.4, 0.5])
    rot = Rotation.from_rotvec([0.3, -0.2, 0.9])
    model = mb.Model("cantilever", gravity=g)
    beam = model.add_body("beam", m_, inertia=(0.1, 0.2, 0.3), position=r_cm, orientation=rot)
    weld = model.add_fixed("weld", model.ground, beam, point=P)
    for res in (mb.equilibrium(model), mb.simulate(model, 0.1, 0.05, method="dop853")):
        F, T = res.reaction_force(weld), res.reaction_torque(weld)
        assert np.allclose(F, -m_ * g, atol=1e-9)
        assert np.allclose(T, -np.cross(r_cm - P, m_ * g), atol=1e-9)
        # on ground: the opposite load, reduced to the same point
        assert np.allclose(res.reaction_force(weld, on=model.ground), m_ * g, atol=1e-9)
        assert np.allclose(res.reaction_torque(weld, on=model.ground), np.cross(r_cm - P, m_ * g), atol=1e-9)
        # frame=beam: the same vectors in the beam's axes
        assert np.allclose(res.reaction_force(weld, frame=beam), rot.inv().apply(-m_ * g), atol=1e-9)
        assert np.allclose(res.position(beam), r_cm, atol=1e-12)
    # default body_j when the weld point is omitted: the body's CM
    model2 = mb.Model("c2", gravity=g)
    b2 = model2.add_body("b", m_, inertia=(1, 1, 1), position=r_cm)
    w2 = model2.add_fixed("w", model2.ground, b2)
    res = mb.equilibrium(model2)
    assert np.allclose(res.reaction_torque(w2), 0.0, atol=1e-9)


def test_assembly_report_moves_bodies_to_satisfy_drivers_and_velocities():
    """A driver asking 0.1 rad at t = 0 rotates the arm: its CM moves by 2 r sin(0.05)."""
    model = mb.Model("asm")
    arm = model.add_body("arm", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.5, 0, 0),
                         angular_velocity=(0.0, 0.0, 5.0))
    pin = model.add_revolute("pin", model.ground, arm, (0, 0, 0), (0, 0, 1))
    model.add_motion("drive", pin, displacement="0.1 + 2*t")
    rep = mb.assemble(model)
    assert rep.dof == 0 and rep.residual < 1e-12 and not rep.redundant
    dr, da = rep.moved["arm"]
    assert dr == pytest.approx(2 * 0.5 * np.sin(0.05), abs=1e-12)
    assert da == pytest.approx(0.1, abs=1e-10)
    # the angular velocity is projected onto the driver's rate 2 rad/s (w_z 5 -> 2), CM velocity w x r
    assert "arm" in rep.velocity_changed and "arm" in str(rep) and "moved arm" in str(rep)
    res = mb.kinematics(model, 0.5, 0.1)
    assert np.allclose(res.angular_velocity(arm)[:, 2], 2.0, atol=1e-12)
    assert np.allclose(res.joint_coordinate(pin), 0.1 + 2 * res.time, atol=1e-12)
    # an undriven pendulum keeps its (consistent) initial state: nothing moved
    model = mb.Model("free")
    arm = model.add_body("arm", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.5, 0, 0))
    model.add_revolute("pin", model.ground, arm, (0, 0, 0), (0, 0, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rep = mb.assemble(model)
    assert rep.dof == 1 and not rep.moved and not rep.velocity_changed


def test_equilibrium_that_does_not_exist_raises_solver_error():
    model = mb.Model("fall", gravity=(0.0, 0.0, -G))
    model.add_particle("p", 1.0)
    with pytest.raises(mb.SolverError, match=r"static equilibrium not found in \d+ iterations \(residual 9.81\) "
                                             r"at t = 0 s"):
        mb.equilibrium(model)

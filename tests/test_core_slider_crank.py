"""Core engine, must-show 3: a driven slider-crank with mb.kinematics.

Slider motion against the closed form x = r cos(theta) + l cos(phi), sin(phi) = -r sin(theta) / l and its
exact time derivatives; joint reactions against a planar Newton-Euler inverse-dynamics solution written
here with numpy (9 equations for the 9 in-plane unknowns).
"""
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

G = 9.81
R_CRANK, L_ROD = 0.1, 0.35
M1, M2, M3 = 1.5, 2.0, 0.8                  # crank, rod, slider [kg]
I1, I2, I3 = M1 * R_CRANK**2 / 12, M2 * L_ROD**2 / 12, 0.01   # about z [kg m^2]
TH0 = np.pi / 6
DRIVE = "3*t + 2*t**2"                      # crank angle minus its initial value [rad]


def drive(t):
    """theta, theta_dot, theta_ddot of the crank [rad, rad/s, rad/s^2]."""
    return TH0 + 3 * t + 2 * t**2, 3 + 4 * t, 4.0 + 0 * t


def closed_form(t):
    """Planar kinematics: crank angle, rod angle and their rates; slider x, xd, xdd."""
    th, thd, thdd = drive(t)
    r, l = R_CRANK, L_ROD
    ph = -np.arcsin(r * np.sin(th) / l)
    phd = -r * np.cos(th) * thd / (l * np.cos(ph))
    phdd = (r * np.sin(th) * thd**2 - r * np.cos(th) * thdd + l * np.sin(ph) * phd**2) / (l * np.cos(ph))
    x = r * np.cos(th) + l * np.cos(ph)
    xd = -r * np.sin(th) * thd - l * np.sin(ph) * phd
    xdd = (-r * np.cos(th) * thd**2 - r * np.sin(th) * thdd - l * np.cos(ph) * phd**2
           - l * np.sin(ph) * phdd)
    return (th, thd, thdd), (ph, phd, phdd), (x, xd, xdd)


def rz(a):
    return Rotation.from_rotvec([0.0, 0.0, a])


def slider_crank(variant):
    """The mechanism in the x-y plane, gravity -y.  variant "revolutes": three 3D revolutes and a
    translational joint (redundant); "non_redundant": revolute, spherical, universal, translational."""
    model = mb.Model("slider_crank", gravity=(0.0, -G, 0.0))
    (th,), (ph,), (x,) = [[v[0]] for v in closed_form(np.array(0.0))]
    A = R_CRANK * np.array([np.cos(th), np.sin(th), 0.0])
    B = np.array([x, 0.0, 0.0])
    crank = model.add_body("crank", M1, inertia=(I1 / 10, I1, I1), position=A / 2, orientation=rz(th))
    rod = model.add_body("rod", M2, inertia=(I2 / 10, I2, I2), position=(A + B) / 2, orientation=rz(ph))
    slider = model.add_body("slider", M3, inertia=(I3, I3, I3), position=B)
    z = (0, 0, 1)
    o = model.add_revolute("O", model.ground, crank, (0, 0, 0), z)
    if variant == "revolutes":
        model.add_revolute("A", crank, rod, A, z)
        model.add_revolute("B", rod, slider, B, z)
    else:
        model.add_spherical("A", crank, rod, A)
        model.add_universal("B", rod, slider, B, axis_i=z, axis_j=(0, 1, 0))
    model.add_translational("slide", model.ground, slider, B, (1, 0, 0))
    model.add_motion("drive", o, displacement=DRIVE)
    return model, crank, rod, slider


def cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def planar_inverse_dynamics(t):
    """In-plane loads from Newton-Euler of the three bodies with the closed-form kinematics.

    Unknowns (ground axes): F_O on crank, F_A on rod (from crank), F_B on slider (from rod), N on the
    slider from the guide (y), M_s on the slider from the guide (z), driving torque tau on the crank."""
    (th, thd, thdd), (ph, phd, phdd), (x, xd, xdd) = closed_form(t)
    e1, e1n = np.array([np.cos(th), np.sin(th)]), np.array([-np.sin(th), np.cos(th)])
    e2, e2n = np.array([np.cos(ph), np.sin(ph)]), np.array([-np.sin(ph), np.cos(ph)])
    A = R_CRANK * e1
    a_A = R_CRANK * (thdd * e1n - thd**2 * e1)
    r1, a1 = A / 2, a_A / 2
    r2, a2 = A + L_ROD / 2 * e2, a_A + L_ROD / 2 * (phdd * e2n - phd**2 * e2)
    B = np.array([x, 0.0])
    a3 = np.array([xdd, 0.0])
    assert np.allclose(A + L_ROD * e2, B)            # loop closure of the closed form itself
    g = np.array([0.0, -G])
    K, rhs = np.zeros((9, 9)), np.zeros(9)
    # columns: FOx FOy FAx FAy FBx FBy N Ms tau
    K[0:2, 0:2], K[0:2, 2:4] = np.eye(2), -np.eye(2)
    K[2, 0:2] = [-(0 - r1[1]), (0 - r1[0])]                  # (O - r1) x F_O
    K[2, 2:4] = [(A - r1)[1], -(A - r1)[0]]                  # -(A - r1) x F_A
    K[2, 8] = 1.0
    K[3:5, 2:4], K[3:5, 4:6] = np.eye(2), -np.eye(2)
    K[5, 2:4] = [-(A - r2)[1], (A - r2)[0]]
    K[5, 4:6] = [(B - r2)[1], -(B - r2)[0]]
    K[6:8, 4:6] = np.eye(2)
    K[7, 6] = 1.0
    K[8, 7] = 1.0                                             # slider CM at B: only M_s acts about it
    rhs[0:2] = M1 * (a1 - g)
    rhs[2] = I1 * thdd
    rhs[3:5] = M2 * (a2 - g)
    rhs[5] = I2 * phdd
    rhs[6:8] = M3 * (a3 - g)
    return np.linalg.solve(K, rhs)


@pytest.fixture(scope="module", params=["revolutes", "non_redundant"])
def run(request):
    model, crank, rod, slider = slider_crank(request.param)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = mb.kinematics(model, 1.0, output_step=0.02)
    redundant = [w for w in caught if issubclass(w.category, mb.RedundantConstraintWarning)]
    assert bool(redundant) == (request.param == "revolutes")
    assert res.success, res.message
    return request.param, model, res, crank, rod, slider


def test_slider_motion_matches_closed_form(run):
    _, model, res, crank, rod, slider = run
    for r in (res, res.at([0.0137, 0.5, 0.9911])):
        _, (ph, phd, phdd), (x, xd, xdd) = closed_form(r.time)
        zero = 0 * r.time
        assert np.allclose(r.position(slider), np.stack([x, zero, zero], -1), rtol=0, atol=1e-9)
        assert np.allclose(r.velocity(slider), np.stack([xd, zero, zero], -1), rtol=0, atol=1e-9)
        assert np.allclose(r.acceleration(slider), np.stack([xdd, zero, zero], -1), rtol=0, atol=1e-9)
        assert np.allclose(r.joint_coordinate("slide"), x - x[0] if r is res else x - closed_form(0.0)[2][0],
                           rtol=0, atol=1e-9)
        assert np.allclose(r.joint_velocity("slide"), xd, rtol=0, atol=1e-9)
        assert np.allclose(r.joint_acceleration("slide"), xdd, rtol=0, atol=1e-9)
        assert np.allclose(r.angular_velocity(rod)[:, 2], phd, rtol=0, atol=1e-9)
        assert np.allclose(r.angular_acceleration(rod)[:, 2], phdd, rtol=0, atol=1e-9)
    (th, thd, thdd), _, _ = closed_form(res.time)
    assert np.allclose(res.joint_coordinate("O"), th - TH0, rtol=0, atol=1e-9)
    assert np.allclose(res.joint_velocity("O"), thd, rtol=0, atol=1e-9)
    assert np.allclose(res.joint_acceleration("O"), thdd, rtol=0, atol=1e-9)


def test_joint_reactions_match_planar_newton_euler(run):
    variant, model, res, crank, rod, slider = run
    ref = np.array([planar_inverse_dynamics(t) for t in res.time])
    F_O, F_A, F_B, N, M_s, tau = ref[:, 0:2], ref[:, 2:4], ref[:, 4:6], ref[:, 6], ref[:, 7], ref[:, 8]
    tol = 1e-7 * max(1.0, np.abs(ref).max())
    checks = [("O", crank, F_O), ("A", rod, F_A), ("B", slider, F_B),
              ("slide", slider, np.stack([0 * N, N], -1))]
    for name, body, F in checks:
        got = res.reaction_force(name, on=body)
        assert np.allclose(got[:, :2], F, rtol=0, atol=tol), name
        # action and reaction: the load on the other body is opposite (reduced to the same point)
        other = model.joints[name].body_i
        assert np.allclose(res.reaction_force(name, on=other), -got, rtol=0, atol=tol), name
        if variant == "non_redundant":   # determinate: out-of-plane components are exactly zero
            assert np.allclose(got[:, 2], 0.0, atol=tol), name
    # the motion's driving torque is part of the revolute's load on the crank (about z at O)
    assert np.allclose(res.reaction_torque("O", on=crank)[:, 2], tau, rtol=0, atol=tol)
    assert np.allclose(res.reaction_torque("drive", on=crank)[:, 2], tau, rtol=0, atol=tol)
    assert np.allclose(res.reaction_torque("slide", on=slider)[:, 2], M_s, rtol=0, atol=tol)
    if variant == "non_redundant":
        for name, body in (("A", rod), ("B", slider)):
            assert np.allclose(res.reaction_torque(name, on=body), 0.0, atol=tol), name

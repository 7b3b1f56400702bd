"""Core engine: Result measures are consistent with each other (finite differences on the dense output)
and with their definitions (frames, markers, joint coordinates between two moving bodies)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

H = 1e-4
TIMES = np.array([0.31, 0.77])


def ddt(res, f, t):
    """5-point central difference of f(res.at(.)) at times t (each output (N, ...))."""
    s = np.array([-2, -1, 1, 2]) * H
    vals = [np.asarray(f(res.at(t + d))) for d in s]
    return (vals[0] - 8 * vals[1] + 8 * vals[2] - vals[3]) / (12 * H)


def floating_pair(kind):
    """A free, spinning body_i (no gravity) carrying body_j on a joint, with a spring driving relative motion."""
    model = mb.Model(f"pair_{kind}")
    rot = Rotation.from_rotvec([0.2, 0.5, -0.3])
    bi = model.add_body("bi", 2.0, inertia=(0.2, 0.3, 0.4), position=(0, 0, 0), orientation=rot,
                        velocity=(0.1, -0.2, 0.3), angular_velocity=(0.3, -0.4, 0.8))
    bj = model.add_body("bj", 1.0, inertia=(0.05, 0.06, 0.07), position=(0.5, 0.2, 0.1),
                        orientation=Rotation.from_rotvec([-0.4, 0.1, 0.2]))
    axis = rot.apply([0.0, 0.0, 1.0])
    P = np.array([0.3, 0.1, 0.0])
    jt = getattr(model, f"add_{kind}")("j", bi, bj, P, axis)
    model.add_spring_damper("s", (bi, (-0.3, 0.4, 0.2)), (bj, (0.7, 0.2, 0.3)), 40.0, free_length=0.5)
    tip = bj.add_marker("tip", point=(0.9, 0.3, -0.2), orientation=Rotation.from_rotvec([0.0, 0.3, 0.0]))
    return model, bi, bj, jt, tip


@pytest.fixture(scope="module", params=["revolute", "translational", "cylindrical"])
def run(request):
    model, bi, bj, jt, tip = floating_pair(request.param)
    res = mb.simulate(model, 1.0, 0.05, method="dop853", rtol=1e-11, atol=1e-12)
    assert res.success, res.message
    return res, bi, bj, jt, tip


def test_joint_rates_between_moving_bodies_are_derivatives_of_the_coordinate(run):
    res, bi, bj, jt, tip = run
    x = res.joint_coordinate(jt)
    assert np.ptp(x, axis=0).min() > 0.05            # the joint really moves
    assert np.allclose(x[0], 0.0, atol=1e-12)          # zero at t = 0
    sub = res.at(TIMES)
    assert np.allclose(ddt(res, lambda r: r.joint_coordinate(jt), TIMES), sub.joint_velocity(jt), atol=1e-7)
    assert np.allclose(ddt(res, lambda r: r.joint_velocity(jt), TIMES), sub.joint_acceleration(jt), atol=1e-6)


def test_point_and_body_measures_are_consistent(run):
    res, bi, bj, jt, tip = run
    sub = res.at(TIMES)
    for target in (bj, tip):
        assert np.allclose(ddt(res, lambda r: r.position(target), TIMES), sub.velocity(target), atol=1e-7)
        assert np.allclose(ddt(res, lambda r: r.velocity(target), TIMES), sub.acceleration(target), atol=1e-6)
    # dA/dt = [w] A (w in ground), and alpha = dw/dt
    Ad = ddt(res, lambda r: r.orientation(bj), TIMES)
    w = sub.angular_velocity(bj)
    assert np.allclose(Ad, np.cross(w[:, None, :], np.swapaxes(sub.orientation(bj), 1, 2)).swapaxes(1, 2),
                       atol=1e-7)
    assert np.allclose(ddt(res, lambda r: r.angular_velocity(bj), TIMES), sub.angular_acceleration(bj), atol=1e-6)


def test_frame_option_expresses_vectors_in_body_or_marker_axes(run):
    res, bi, bj, jt, tip = run
    A = res.orientation(bj)
    R_marker = A @ tip.R_BM
    # a marker is fixed on its body: relative position in body axes is constant
    assert np.allclose(res.position(tip, frame=bj), tip.s_B, atol=1e-12)
    assert np.allclose(res.position(bj, frame=tip), -tip.R_BM.T @ tip.s_B, atol=1e-12)
    v, w = res.velocity(tip), res.angular_velocity(bi)
    assert np.allclose(res.velocity(tip, frame=bj), np.einsum("nji,nj->ni", A, v), atol=1e-12)
    assert np.allclose(res.velocity(tip, frame=tip), np.einsum("nji,nj->ni", R_marker, v), atol=1e-12)
    assert np.allclose(res.angular_velocity(bi, frame=bi), np.einsum("nji,nj->ni", res.orientation(bi), w),
                       atol=1e-12)
    # relative position of bj's CM from bi's CM, in bi's axes
    d = res.position(bj) - res.position(bi)
    assert np.allclose(res.position(bj, frame=bi), np.einsum("nji,nj->ni", res.orientation(bi), d), atol=1e-12)


def test_spring_measures_and_energy_balance(run):
    """Spring length/rate against the marker positions; energy is conserved (undamped, no gravity)."""
    res, bi, bj, jt, tip = run
    spring = res.system.model.forces["s"]
    pi = res.position(spring.marker_i)
    pj = res.position(spring.marker_j)
    L = np.linalg.norm(pj - pi, axis=1)
    assert np.allclose(res.spring_length("s"), L, atol=1e-12)
    assert np.allclose(res.spring_force(spring), 40.0 * (L - 0.5), atol=1e-9)
    assert np.allclose(ddt(res, lambda r: r.spring_length("s"), TIMES), res.at(TIMES).spring_velocity("s"),
                       atol=1e-7)
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) < 1e-8 * np.abs(E).max()


def test_multi_dof_joint_coordinates_against_closed_forms():
    """Spherical: rotation vector of a body spun about a fixed skew axis is w t n; its relative angular
    velocity is w n (body_i = ground axes). Planar: a particle sliding in a plane has u, v = v0 t."""
    import mbdsim as mb
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    m = mb.Model("ball")
    b = m.add_body("b", 1.0, (1.0, 1.0, 1.0), angular_velocity=2.0 * n)   # isotropic: spins about n
    s = m.add_spherical("s", m.ground, b, (0, 0, 0))
    res = mb.simulate(m, 1.0, 0.1, method="dop853", rtol=1e-11, atol=1e-13)
    t = res.time[:, None]
    np.testing.assert_allclose(res.joint_coordinate(s), 2.0 * t * n, atol=1e-8)
    np.testing.assert_allclose(res.joint_velocity(s), np.broadcast_to(2.0 * n, (len(t), 3)), atol=1e-8)
    np.testing.assert_allclose(res.joint_acceleration(s), 0.0, atol=1e-7)
    m = mb.Model("plane")
    p = m.add_particle("p", 1.0, position=(0, 0, 0), velocity=(0.3, -0.2, 0.0))
    pl = m.add_planar("pl", m.ground, p, (0, 0, 0), (0, 0, 1))
    res = mb.simulate(m, 1.0, 0.25, method="dop853")
    uv = res.joint_coordinate(pl)[:, :2]
    f_g = np.stack([uv[:, 0], uv[:, 1]], -1)
    assert np.allclose(np.linalg.norm(f_g, axis=1), np.hypot(0.3, 0.2) * res.time, atol=1e-9)

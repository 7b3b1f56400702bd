"""Results that answer frame questions: marker orientations, scipy rotations, motion relative to a
moving frame, joint coordinates of every kind (continuous in time), targets given by name.

References are closed forms (rotations about fixed axes, polar kinematics of a bead on a spinning rod,
free motion on a plane) or consistency identities (R_rel = Rot(a1) Rot(a2) for a universal joint,
exp(rotation vector) = relative rotation), never numbers copied from mbdsim's own output.
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.errors import ModelError

TIGHT = dict(method="dop853", rtol=1e-11, atol=1e-12)
G = 9.81


def rot(axis, angle):
    """Rotation matrices (N, 3, 3) about a unit axis by angles (N,)."""
    return Rotation.from_rotvec(np.outer(np.atleast_1d(angle), axis)).as_matrix()


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


# ----------------------------------------------------------------------------- orientation of a marker
def driven_rotor():
    n = unit((0.3, -0.4, 1.0))
    R0 = Rotation.from_rotvec((0.2, 0.5, -0.3)).as_matrix()       # body axes at t = 0
    M0 = Rotation.from_euler("ZYX", (0.7, -0.2, 1.1)).as_matrix()  # marker axes at t = 0
    model = mb.Model("rotor")
    body = model.add_body("rotor", 1.0, (0.1, 0.2, 0.3), position=(0.4, 0.1, -0.2), orientation=R0)
    tip = body.add_marker("tip", point=(0.9, 0.3, 0.1), orientation=M0)
    axle = model.add_revolute("axle", model.ground, body, (0.1, -0.2, 0.3), n)
    model.add_motion("spin", axle, displacement="1.5*t + 0.4*sin(3*t)")
    return model, body, tip, n, R0, M0


def test_marker_orientation_on_a_driven_body_matches_the_closed_form():
    model, body, tip, n, R0, M0 = driven_rotor()
    res = mb.kinematics(model, 2.0, 0.05)
    th = 1.5 * res.time + 0.4 * np.sin(3 * res.time)
    Rn = rot(n, th)
    np.testing.assert_allclose(res.orientation(tip), Rn @ M0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.orientation(body), Rn @ R0, rtol=0, atol=1e-12)
    # every measure that takes a body takes a marker, a body name or a "body.marker" name alike
    np.testing.assert_array_equal(res.orientation("rotor.tip"), res.orientation(tip))
    np.testing.assert_array_equal(res.orientation("rotor"), res.orientation(body))
    np.testing.assert_array_equal(res.position("rotor.tip"), res.position(tip))
    np.testing.assert_array_equal(res.velocity("rotor.tip", frame="rotor"), res.velocity(tip, frame=body))
    np.testing.assert_array_equal(res.angular_velocity("rotor.tip"), res.angular_velocity(body))
    # the frame of a marker: a vector fixed in the marker's axes
    np.testing.assert_allclose(res.angular_velocity(body, frame=tip),
                               np.einsum("nji,nj->ni", Rn @ M0, np.outer(1.5 + 1.2 * np.cos(3 * res.time), n)),
                               atol=1e-12)


@pytest.mark.parametrize("seq", ["xyz", "ZYX", "ZXZ", "yxy"])
def test_rotation_is_a_scipy_stack_matching_orientation_and_euler_angles_round_trip(seq):
    model, body, tip, *_ = driven_rotor()
    res = mb.kinematics(model, 1.0, 0.1)
    r = res.rotation(tip)
    assert isinstance(r, Rotation) and len(r) == len(res.time)
    np.testing.assert_allclose(r.as_matrix(), res.orientation(tip), atol=1e-14)
    ang = r.as_euler(seq)
    np.testing.assert_allclose(Rotation.from_euler(seq, ang).as_matrix(), res.orientation(tip), atol=1e-12)
    q = r.as_quat()           # scalar last
    np.testing.assert_allclose(Rotation.from_quat(q).as_matrix(), res.orientation(tip), atol=1e-12)


def test_unknown_target_names_the_entity():
    model, *_ = driven_rotor()
    res = mb.kinematics(model, 0.1, 0.1)
    with pytest.raises(ModelError, match="rotor.nose"):
        res.position("rotor.nose")
    with pytest.raises(ModelError, match="target"):
        res.orientation(3.0)


# ----------------------------------------------------------------------------- bead on a spinning rod
def bead_on_spinning_rod():
    model = mb.Model("bead")
    rod = model.add_body("rod", 2.0, (0.01, 0.2, 0.2), position=(0.5, 0, 0))
    bead = model.add_body("bead", 0.1, (1e-4, 1e-4, 1e-4), position=(0.3, 0, 0))
    hub = model.add_revolute("hub", model.ground, rod, (0, 0, 0), (0, 0, 1))
    slide = model.add_translational("slide", rod, bead, (0.3, 0, 0), (1, 0, 0))
    model.add_motion("turn", hub, displacement="0.8*t + 0.3*t**2")
    model.add_motion("feed", slide, displacement="0.2*sin(2*t)")
    return model, rod, bead


def test_bead_on_spinning_rod_relative_transport_and_coriolis_terms():
    model, rod, bead = bead_on_spinning_rod()
    res = mb.kinematics(model, 2.0, 0.05)
    t = res.time
    s, sd, sdd = 0.2 * np.sin(2 * t), 0.4 * np.cos(2 * t), -0.8 * np.sin(2 * t)
    th, thd, thdd = 0.8 * t + 0.3 * t**2, 0.8 + 0.6 * t, 0.6 + 0 * t
    z = np.zeros_like(t)
    v_rel = res.velocity(bead, frame=rod, relative_to=rod)
    a_rel = res.acceleration(bead, frame=rod, relative_to=rod)
    np.testing.assert_allclose(v_rel, np.stack([sd, z, z], -1), rtol=0, atol=1e-10)
    np.testing.assert_allclose(a_rel, np.stack([sdd, z, z], -1), rtol=0, atol=1e-10)
    # polar closed form of the absolute motion (r = 0.3 + s from the hub)
    r = 0.3 + s
    er = np.stack([np.cos(th), np.sin(th), z], -1)
    et = np.stack([-np.sin(th), np.cos(th), z], -1)
    a_abs = (sdd - r * thd**2)[:, None] * er + (r * thdd + 2 * sd * thd)[:, None] * et
    np.testing.assert_allclose(res.acceleration(bead), a_abs, rtol=0, atol=1e-10)
    # absolute = relative + transport + Coriolis, each built here from the rod's own motion
    w = np.stack([z, z, thd], -1)
    al = np.stack([z, z, thdd], -1)
    rho = res.position(bead) - res.position(rod)
    transport = res.acceleration(rod) + np.cross(al, rho) + np.cross(w, np.cross(w, rho))
    rel_ground = res.acceleration(bead, relative_to=rod)
    coriolis = 2 * np.cross(w, res.velocity(bead, relative_to=rod))
    np.testing.assert_allclose(res.acceleration(bead), rel_ground + transport + coriolis, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.velocity(bead), res.velocity(bead, relative_to=rod) + res.velocity(rod)
                               + np.cross(w, rho), rtol=0, atol=1e-12)
    # angular motion relative to the rod: the bead does not turn in it
    np.testing.assert_allclose(res.angular_velocity(bead, relative_to=rod), 0.0, atol=1e-12)
    np.testing.assert_allclose(res.angular_acceleration(bead, relative_to="rod"), 0.0, atol=1e-12)
    np.testing.assert_allclose(res.angular_velocity(rod, relative_to="ground"), w, atol=1e-12)
    # Adams' convention: the derivative taken in the frame, the result expressed anywhere
    np.testing.assert_allclose(res.velocity(bead, frame="ground", relative_to=rod), v_rel[:, 0:1] * er, atol=1e-10)


# ----------------------------------------------------------------------------- planar joint
def puck(u_axis=None, normal=(0, 0, 1)):
    model = mb.Model("puck")
    p = model.add_body("puck", 0.2, (1e-3, 1e-3, 2e-3), position=(0.5, 0.2, 0.0), velocity=(1.0, 0, 0),
                       angular_velocity=(0, 0, 50.0))
    ice = model.add_planar("ice", model.ground, p, (0.5, 0.2, 0.0), normal, u_axis=u_axis)
    return model, p, ice


@pytest.mark.parametrize("u_axis, expect", [((1, 0, 0), (1, 0, 50)), (None, (1, 0, 50)),
                                            ((0, 1, 0), (0, -1, 50)), ((0, -2, 0), (0, 1, 50))])
def test_free_spinning_puck_planar_coordinates_along_the_users_axes(u_axis, expect):
    model, p, ice = puck(u_axis)
    res = mb.simulate(model, 1.0, 0.1, **TIGHT)   # 5 rad of spin between samples
    x = res.joint_coordinate(ice)
    np.testing.assert_allclose(x[-1], expect, rtol=0, atol=1e-9)
    np.testing.assert_allclose(x[:, 2], 50 * res.time, atol=1e-9)        # continuous, no jump at pi
    np.testing.assert_allclose(res.joint_velocity(ice)[-1], np.array(expect) / 1.0, atol=1e-9)
    np.testing.assert_allclose(res.joint_acceleration(ice), 0.0, atol=1e-8)
    np.testing.assert_allclose(res.at(0.55).joint_coordinate(ice)[0], 0.55 * np.array(expect), atol=1e-9)


def test_planar_joint_acceleration_under_gravity_on_an_incline():
    """A puck on a plane with normal n: u'' and v'' are the in-plane gravity components along u, v."""
    n = unit((0.0, 0.6, 0.8))
    u = np.array([1.0, 0.0, 0.0])
    v = np.cross(n, u)
    model = mb.Model("incline", gravity=(0, 0, -G))
    p = model.add_body("puck", 0.3, (1e-3, 1e-3, 2e-3), angular_velocity=3.0 * n)
    ice = model.add_planar("ice", model.ground, p, (0, 0, 0), n, u_axis=u)
    res = mb.simulate(model, 0.5, 0.05, **TIGHT)
    g = np.array([0, 0, -G])
    acc = res.joint_acceleration(ice)
    np.testing.assert_allclose(acc[:, 0], g @ u, atol=1e-8)
    np.testing.assert_allclose(acc[:, 1], g @ v, atol=1e-8)
    np.testing.assert_allclose(acc[:, 2], 0.0, atol=1e-8)
    np.testing.assert_allclose(res.joint_coordinate(ice)[:, 1], 0.5 * (g @ v) * res.time**2, atol=1e-9)


def test_planar_u_axis_must_lie_in_the_plane():
    model = mb.Model()
    b = model.add_body("b", 1.0, (1, 1, 1))
    with pytest.raises(ModelError, match="u_axis"):
        model.add_planar("pl", model.ground, b, (0, 0, 0), (0, 0, 1), u_axis=(1, 0, 1))
    assert "pl" not in model.joints
    model.add_planar("pl", model.ground, b, (0, 0, 0), (1, 0, 0))    # default for a normal along x: ground y
    np.testing.assert_allclose(model.joints["pl"].u_axis, (0, 1, 0))


# ----------------------------------------------------------------------------- spherical and universal
def test_spherical_joint_spinning_past_pi_has_a_continuous_coordinate():
    n = unit((1.0, 2.0, 2.0))
    m = mb.Model("top")
    b = m.add_body("ball", 1.0, (1.0, 1.0, 1.0), angular_velocity=50.0 * n)    # isotropic: spins about n
    s = m.add_spherical("s", m.ground, b, (0, 0, 0))
    res = mb.simulate(m, 1.0, 0.1, **TIGHT)                                    # 5 rad per sample
    np.testing.assert_allclose(res.joint_coordinate(s), 50.0 * res.time[:, None] * n, atol=1e-8)
    sub = res.at([0.33, 0.71])
    np.testing.assert_allclose(sub.joint_coordinate(s), 50.0 * sub.time[:, None] * n, atol=1e-8)


def test_universal_joint_spinning_about_its_second_axis_is_continuous():
    """A free body on a universal joint spinning about axis_j (z) at 50 rad/s, sampled every 0.1 s."""
    m = mb.Model("spinner")
    b = m.add_body("b", 1.0, (0.2, 0.2, 0.1), angular_velocity=(0, 0, 50.0))
    u = m.add_universal("u", m.ground, b, (0, 0, 0), (1, 0, 0), (0, 0, 1))
    res = mb.simulate(m, 1.0, 0.1, **TIGHT)
    t = res.time
    np.testing.assert_allclose(res.joint_coordinate(u), np.outer(50 * t, (0, 0, 1)), atol=1e-8)
    np.testing.assert_allclose(res.joint_coordinate(u, kind="angles"), np.stack([0 * t, 50 * t], -1), atol=1e-8)
    np.testing.assert_allclose(res.joint_velocity(u, kind="angles")[-1], (0, 50), atol=1e-8)


def tumbling_top():
    m = mb.Model("tumble")
    b = m.add_body("body", 1.0, (1.0, 2.0, 3.0), angular_velocity=(4.0, 0.3, 2.0))   # torque-free tumbling
    s = m.add_spherical("s", m.ground, b, (0, 0, 0))
    return m, b, s


def test_tumbling_body_rotation_vector_is_continuous_and_exact():
    m, b, s = tumbling_top()
    res = mb.simulate(m, 3.0, 0.02, **TIGHT)
    th = res.joint_coordinate(s)
    np.testing.assert_allclose(Rotation.from_rotvec(th).as_matrix(), res.orientation(b), atol=1e-12)
    assert np.max(np.linalg.norm(th, axis=1)) > np.pi + 1.0                 # it has gone well past pi
    steps = np.linalg.norm(np.diff(th, axis=0), axis=1)
    assert np.max(steps) < 0.5                                              # |w| dt ~ 0.1: no 2 pi jumps


def cardan(beta=0.6):
    """Input shaft spinning about x (revolute on ground), output shaft on a revolute about an axis at
    beta to it, joined by a universal joint (axis_i along the input's y, axis_j along the output's z)."""
    m = mb.Model("cardan")
    a2 = np.array([np.cos(beta), np.sin(beta), 0.0])
    s1 = m.add_body("in", 1.0, (0.1, 0.1, 0.1), position=(-0.5, 0, 0))
    s2 = m.add_body("out", 1.0, (0.1, 0.1, 0.1), position=0.5 * a2)
    m.add_revolute("r1", m.ground, s1, (0, 0, 0), (1, 0, 0))
    m.add_revolute("r2", m.ground, s2, (0, 0, 0), a2)
    u = m.add_universal("u", s1, s2, (0, 0, 0), (0, 1, 0), (0, 0, 1))
    m.add_motion("drive", "r1", displacement="2*t + 0.3*sin(t)")
    return m, s1, s2, u


@pytest.mark.filterwarnings("ignore::mbdsim.RedundantConstraintWarning")   # both shafts pinned at the cross
def test_universal_joint_yoke_angles_decompose_the_relative_rotation():
    m, s1, s2, u = cardan()
    res = mb.kinematics(m, 4.0, 0.05)
    ang = res.joint_coordinate(u, kind="angles")
    rate = res.joint_velocity(u, kind="angles")
    acc = res.joint_acceleration(u, kind="angles")
    Ri, Rj = res.orientation(s1), res.orientation(s2)
    R_rel = np.einsum("nji,njk->nik", Ri, Rj)                # initial relative attitude is the identity
    np.testing.assert_allclose(rot((0, 1, 0), ang[:, 0]) @ rot((0, 0, 1), ang[:, 1]), R_rel, atol=1e-10)
    assert np.ptp(ang[:, 0]) > 0.5                            # the cross swings in the input yoke
    np.testing.assert_allclose(Rotation.from_rotvec(res.joint_coordinate(u)).as_matrix(), R_rel, atol=1e-10)
    # rates and accelerations against the dense output (central differences)
    h = 1e-5
    for tk in (0.7, 2.3):
        lo, hi = res.at(tk - h), res.at(tk + h)
        k = int(np.argmin(np.abs(res.time - tk)))
        mid = res.at(tk)
        d1 = (hi.joint_coordinate(u, kind="angles") - lo.joint_coordinate(u, kind="angles"))[0] / (2 * h)
        d2 = (hi.joint_velocity(u, kind="angles") - lo.joint_velocity(u, kind="angles"))[0] / (2 * h)
        np.testing.assert_allclose(mid.joint_velocity(u, kind="angles")[0], d1, atol=1e-6)
        np.testing.assert_allclose(mid.joint_acceleration(u, kind="angles")[0], d2, atol=1e-5)
        assert abs(res.time[k] - tk) < 0.03
    np.testing.assert_allclose(rate.shape, (len(res.time), 2))
    np.testing.assert_allclose(acc.shape, (len(res.time), 2))


@pytest.mark.filterwarnings("ignore::mbdsim.RedundantConstraintWarning")
def test_joint_kind_argument_is_checked():
    m, s1, s2, u = cardan()
    res = mb.kinematics(m, 0.1, 0.1)
    with pytest.raises(ModelError, match="kind"):
        res.joint_coordinate("r1", kind="angles")
    with pytest.raises(ModelError, match="kind"):
        res.joint_coordinate(u, kind="euler")


def test_rotation_vector_rate_formula_against_finite_differences():
    from mbdsim.results.joints import rotvec_rate
    t, h = 0.7, 1e-6
    th = lambda s: np.array([1.1 * np.sin(s), 0.8 * s, 1.5 * np.cos(2 * s)])   # noqa: E731 (|th| < pi)
    R = lambda s: Rotation.from_rotvec(th(s)).as_matrix()                       # noqa: E731
    W = (R(t + h) - R(t - h)) / (2 * h) @ R(t).T                                # [w]x = R' R^T
    w = np.array([W[2, 1], W[0, 2], W[1, 0]])
    np.testing.assert_allclose(rotvec_rate(th(t)[None], w[None])[0], (th(t + h) - th(t - h)) / (2 * h), atol=1e-8)
    np.testing.assert_allclose(rotvec_rate(np.zeros((1, 3)), w[None])[0], w, atol=1e-15)


def test_tumbling_rotation_vector_with_coarse_samples_matches_the_fine_history():
    """1.1 rad of rotation between samples: the branch comes from the rate prediction, not proximity."""
    m, b, s = tumbling_top()
    fine = mb.simulate(m, 3.0, 0.01, **TIGHT)
    coarse = fine.at(np.arange(0.0, 3.0 + 1e-9, 0.25))
    own = mb.simulate(m, 3.0, 0.25, **TIGHT)
    k = np.round(coarse.time / 0.01).astype(int)
    np.testing.assert_allclose(own.joint_coordinate(s), fine.joint_coordinate(s)[k], atol=1e-8)
    np.testing.assert_allclose(coarse.joint_coordinate(s), fine.joint_coordinate(s)[k], atol=1e-8)

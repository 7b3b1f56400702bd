"""Issue 30: a shape contact's exported time histories (to_dataframe): centre of pressure, normal of the
resultant normal force and slip speed, against statics and the sliding closed form."""
import numpy as np
import pytest

import mbdsim as mb

G = 9.81
K, E = 1e6, 1.0
A, MASS = 0.1, 1.0
RAMP = 1e-6   # full damping (400 N s/m) already at 1 um: the corners' bounce (2.5 um deep) dies out in ~10 ms


def incline(theta):
    """(normal, rotation whose z is the normal, downhill unit tangent) of a plane through the origin."""
    n = np.array([-np.sin(theta), 0.0, np.cos(theta)])
    R = np.array([[np.cos(theta), 0, -np.sin(theta)], [0, 1, 0], [np.sin(theta), 0, np.cos(theta)]])
    return n, R, -np.array([np.cos(theta), 0.0, np.sin(theta)])


def columns(df, name, suffixes):
    return df[[f"{name}.{s}" for s in suffixes]].to_numpy()


def box_model(theta=0.0, lift=0.0, v0=0.0, **friction):
    n, R, t = incline(theta)
    m = mb.Model(gravity=(0, 0, -G))
    delta = MASS * G * np.cos(theta) / (4 * K)
    b = m.add_body("box", MASS, (MASS * A * A / 6,) * 3, position=n * (A / 2 - delta + lift), orientation=R,
                   velocity=v0 * t)
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), n), b.add_shape("geo", mb.Box((A, A, A))), K, E, 400.0,
                  RAMP, **friction)
    return m, n, t


def test_box_resting_flat_has_its_centre_of_pressure_under_the_centre_of_mass():
    """Dropped from 1 mm: NaN while in the air; at rest the centre of pressure is the CM's foot on the
    plane (within the penetration) and the normal is the plane's, the force the weight."""
    m, n, _ = box_model(lift=1e-3)
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    df = res.to_dataframe()
    P, N = columns(df, "c", ("x [m]", "y [m]", "z [m]")), columns(df, "c", ("nx [-]", "ny [-]", "nz [-]"))
    assert np.all(np.isnan(P[0])) and np.all(np.isnan(N[0])) and df["c.points [-]"][0] == 0
    touching = df["c.points [-]"].to_numpy() > 0
    assert touching[-1] and not np.any(np.isnan(P[touching])) and not np.any(np.isnan(N[touching]))
    c = res.position("box")[-1]
    assert np.allclose(P[-1, :2], c[:2], atol=1e-9)
    assert abs(P[-1, 2]) <= MASS * G / (4 * K) * (1 + 1e-6)
    assert np.allclose(N[-1], n, atol=1e-12)
    assert df["c.Fz [N]"].iloc[-1] == pytest.approx(MASS * G, rel=1e-6)


def test_off_centre_load_moves_the_centre_of_pressure_by_the_moment_balance():
    """A vertical load P on the top face at (x_q, y_q) from the CM: moments about the CM give the centre of
    pressure at c + P (q - c) / (m g + P) horizontally (q the load point now: the box tilts a little)."""
    m, n, _ = box_model()
    P, xq, yq = 20.0, 0.03, -0.02
    load = m.bodies["box"].add_marker("load", (xq, yq, A))
    m.add_force("press", load, (0.0, 0.0, -P))
    res = mb.simulate(m, 0.5, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    df = res.to_dataframe()
    cop = columns(df, "c", ("x [m]", "y [m]"))[-1]
    c, q = res.position("box")[-1], res.position(load)[-1]
    assert np.max(np.abs(res.velocity("box")[-1])) < 1e-6   # at rest
    ref = c[:2] + P * (q[:2] - c[:2]) / (MASS * G + P)
    assert np.allclose(cop, ref, atol=1e-6 * A), (cop, ref)
    assert np.hypot(*(cop - c[:2])) > 0.3 * np.hypot(xq, yq) * P / (MASS * G + P)   # it did move
    assert np.allclose(columns(df, "c", ("nx [-]", "ny [-]", "nz [-]"))[-1], (0, 0, 1), atol=1e-12)


def test_box_held_on_an_incline_has_its_centre_of_pressure_downhill():
    """At rest on an incline the friction m g sin(th) acts h below the CM (h: the CM's height over the
    touching points); the moment balance moves the centre of pressure h tan(th) downhill of the CM."""
    theta = np.radians(20)
    m, n, t = box_model(theta, mu_static=0.6, mu_dynamic=0.5, stiction_velocity=1e-3, transition_velocity=1e-2)
    res = mb.simulate(m, 0.5, 0.01, method="dop853", rtol=1e-8)
    assert res.success
    df = res.to_dataframe()
    cop = columns(df, "c", ("x [m]", "y [m]", "z [m]"))[-1]
    c = res.position("box")[-1]
    h = (c - cop) @ n
    assert abs(h - A / 2) < 1e-3 * A
    assert (cop - c) @ t == pytest.approx(h * np.tan(theta), rel=1e-6)
    assert abs((cop - c) @ np.cross(n, t)) < 1e-9
    assert np.allclose(columns(df, "c", ("nx [-]", "ny [-]", "nz [-]"))[-1], n, atol=1e-12)


def test_slip_velocity_of_a_box_sliding_down_an_incline_is_v0_plus_a_t():
    """mu below tan(th): the box slides at v0 + g (sin th - mu cos th) t, every touching point with it."""
    theta, mu, v0 = np.radians(30), 0.3, 0.5
    m, n, t = box_model(theta, v0=v0, mu=mu, friction_velocity=1e-3)
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    df = res.to_dataframe()
    s = df["c.slip_velocity [m/s]"].to_numpy()
    ref = v0 + G * (np.sin(theta) - mu * np.cos(theta)) * res.time
    assert np.max(np.abs(s / ref - 1)) < 1e-4, np.max(np.abs(s / ref - 1))
    cop = columns(df, "c", ("x [m]", "y [m]", "z [m]"))
    assert np.all(np.isfinite(cop)) and np.all(df["c.points [-]"] == 4)


def test_table_scene_does_not_draw_the_centre_of_pressure_as_a_body():
    """The viewer's results-table scene takes "<name>.x [m]" for a body: the contact's centre-of-pressure
    columns are not drawn as one."""
    from mbdsim.viewer.scene import scene_from_table
    m, _, _ = box_model(lift=1e-3)
    res = mb.simulate(m, 0.05, 0.01)
    scene = scene_from_table(res.to_dataframe())
    assert [b["name"] for b in scene.bodies] == ["box"]


def test_box_thrown_tumbling_comes_to_rest_face_down_at_the_impact_height():
    """Thrown at 3 m/s spinning at 25 rad/s (bench/contact_shapes.py's tumbling scene): it lands on a corner,
    tumbles over edges and faces and rests on a face, its CM (m g / (4 k))^(1/e) below a/2, the centre of
    pressure under the CM, the normal the floor's."""
    from scipy.spatial.transform import Rotation
    k, e = 1e5, 1.5
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("box", MASS, (MASS * A * A / 6,) * 3, position=(0, 0, 0.2),
                   orientation=Rotation.from_rotvec((0.5, 0.3, 0.2)).as_matrix(), velocity=(3, 0, 0),
                   angular_velocity=(1, 25, -2))
    m.add_contact("c", mb.Plane(m.ground, (0, 0, 0), (0, 0, 1)), b.add_shape("geo", mb.Box((A, A, A))), k, e, 50.0,
                  1e-3, mu=0.5, friction_velocity=1e-2)
    res = mb.simulate(m, 2.0, 0.005, rtol=1e-5, monitor=False)
    assert res.success
    R = res.orientation("box")
    down = [int(np.argmax(np.abs(Rk[2]))) * 2 + int(Rk[2, np.argmax(np.abs(Rk[2]))] > 0) for Rk in R]
    df = res.to_dataframe()
    touching = df["c.points [-]"].to_numpy() > 0
    npts = df["c.points [-]"].to_numpy()
    assert {1, 2, 4} <= set(npts)   # on a corner, on an edge and on a face
    on = [d for d, t in zip(down, touching) if t]
    assert any(a != b for a, b in zip(on, on[1:]))   # tipped over an edge onto another face while touching
    assert float(res.kinetic_energy()[-1]) < 1e-9
    assert np.max(np.abs(R[-1, 2])) == pytest.approx(1.0, abs=1e-9)
    c = res.position("box")[-1]
    assert c[2] == pytest.approx(A / 2 - (MASS * G / (4 * k)) ** (1 / e), abs=1e-7)
    assert np.allclose(columns(df, "c", ("x [m]", "y [m]"))[-1], c[:2], atol=1e-9)
    assert np.allclose(columns(df, "c", ("nx [-]", "ny [-]", "nz [-]"))[-1], (0, 0, 1), atol=1e-12)

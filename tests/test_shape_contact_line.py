"""Issue 30: line contact of curved shapes (two cylinders, a capsule on a cylinder, axes parallel): points at
the ends of the overlap of the axes, so that the pair rests without rocking and rolls about its line.
Closed forms only."""
import numpy as np
from scipy.integrate import solve_ivp

import mbdsim as mb

G = 9.81


def test_cylinder_on_a_parallel_cylinder_rests_level_at_the_impact_penetration():
    """Two points (the ends of the overlap) share the weight: each at delta = (m g / (2 k))^(1/e), the
    centres ra + rb - delta apart, no tilt and no twist."""
    ra, rb, mass, k, e = 0.05, 0.03, 2.0, 1e6, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    low = m.ground.add_shape("low", mb.Cylinder(ra, 0.6, axis="x"))
    d = (mass * G / (2 * k)) ** (1 / e)
    b = m.add_body("top", mass, (0.002, 0.01, 0.01), position=(0.05, 0.0, ra + rb - d))
    c = m.add_contact("c", low, b.add_shape("geo", mb.Cylinder(rb, 0.3, axis="x")), k, e, 400.0, 1e-5,
                      mu=0.5, friction_velocity=1e-3)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-7)
    assert res.success
    assert abs(res.position("top")[-1, 2] - (ra + rb - d)) < 1e-3 * d
    assert np.max(np.abs(res.position("top")[-1, :2] - (0.05, 0.0))) < 1e-9
    assert np.max(np.abs(res.orientation("top")[-1] - np.eye(3))) < 1e-9
    pts = c and res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert len(last) == 2 and np.allclose(last.penetration, d, rtol=1e-3)
    assert np.allclose(np.sort(last.x.to_numpy()), (0.05 - 0.15, 0.05 + 0.15), atol=1e-9)


def test_slightly_twisted_cylinder_is_pushed_back_parallel():
    """A twist of 0.5 degree: the two end points at different depths give the restoring moment (a single
    EPA point gives none), so the twist decays instead of growing."""
    from scipy.spatial.transform import Rotation
    ra, rb, mass, k, e = 0.05, 0.03, 2.0, 1e6, 1.0
    m = mb.Model(gravity=(0, 0, -G))
    low = m.ground.add_shape("low", mb.Cylinder(ra, 0.6, axis="x"))
    d = (mass * G / (2 * k)) ** (1 / e)
    b = m.add_body("top", mass, (0.002, 0.01, 0.01), position=(0.0, 0.0, ra + rb - d),
                   orientation=Rotation.from_rotvec((0.0, 0.00873, 0.0)).as_matrix())
    m.add_contact("c", low, b.add_shape("geo", mb.Cylinder(rb, 0.3, axis="x")), k, e, 400.0, 1e-5)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-7, monitor=False)   # (contact dissipates)
    assert res.success
    R = res.orientation("top")[-1]
    assert abs(R[2, 0]) < 1e-3 * 0.00873   # the pitch about y is gone (the lower cylinder holds its line)


def test_capsule_rolls_off_a_cylinder_at_the_rolling_rate():
    """A capsule (radius r, I about its axis) on top of a fixed cylinder (radius R), axes parallel, released
    at phi0 from the top, rolls without slipping: rho phi'' (1 + I / (m r^2)) = g sin(phi) with rho the
    distance of the axes, i.e. a tangential acceleration g sin(phi) / (1 + I / (m r^2))."""
    R, r, mass, k, e = 0.1, 0.04, 1.0, 1e7, 1.0
    I = 0.5 * mass * r * r
    phi0 = 0.2
    d0 = (mass * G * np.cos(phi0) / (2 * k)) ** (1 / e)
    rho = R + r - d0
    m = mb.Model(gravity=(0, 0, -G))
    cyl = m.ground.add_shape("rail", mb.Cylinder(R, 0.5, axis="y"))
    b = m.add_body("cap", mass, (0.01, I, 0.01), position=(rho * np.sin(phi0), 0.0, rho * np.cos(phi0)))
    m.add_contact("c", cyl, b.add_shape("geo", mb.Capsule(r, 0.2, axis="y")), k, e, 2000.0, 1e-6,
                  mu=0.8, friction_velocity=1e-5)
    T = 0.12
    res = mb.simulate(m, T, T / 60, method="dop853", rtol=1e-9)
    assert res.success
    p = res.position("cap")
    phi = np.arctan2(p[:, 0], p[:, 2])
    ref = solve_ivp(lambda t, y: (y[1], G * np.sin(y[0]) / (rho * (1 + I / (mass * r * r)))), (0, T),
                    (phi0, 0.0), t_eval=res.time, rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(phi - ref.y[0])) < 1e-3 * (ref.y[0, -1] - phi0), np.max(np.abs(phi - ref.y[0]))
    assert np.max(np.abs(p[:, 1])) < 1e-9

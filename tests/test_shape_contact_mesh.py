"""Issue 30: triangle meshes (non-convex, through their bounding-volume hierarchy) as either side of a
contact: a box resting on a mesh floor, a ball rolling in a mesh bowl.  Closed forms only."""
import numpy as np

import mbdsim as mb

G = 9.81


def grid_surface(x0, y0, n, h, height):
    """Triangles of the surface z = height(x, y) over an n x n grid of cells of side h from (x0, y0),
    normals up (counter-clockwise seen from above)."""
    xs, ys = x0 + h * np.arange(n + 1), y0 + h * np.arange(n + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    v = np.column_stack([X.ravel(), Y.ravel(), height(X.ravel(), Y.ravel())])
    idx = lambda i, j: i * (n + 1) + j  # noqa: E731
    f = []
    for i in range(n):
        for j in range(n):
            f += [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)), (idx(i, j), idx(i + 1, j + 1), idx(i, j + 1))]
    return v, np.array(f)


def test_box_rests_on_a_triangle_mesh_floor_at_the_impact_penetration():
    """Four corners over different triangles carry a quarter of the weight each: the box rests flat at
    a/2 - (m g / (4 k))^(1/e)."""
    a, mass, k, e = 0.1, 1.0, 1e6, 1.0
    v, f = grid_surface(-0.52, -0.535, 10, 0.1, lambda x, y: 0.0 * x)
    m = mb.Model(gravity=(0, 0, -G))
    d = (mass * G / (4 * k)) ** (1 / e)
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=(0.0, 0.0, a / 2 - d))
    floor = m.ground.add_shape("floor", mb.Mesh(v, f))
    c = m.add_contact("c", b.add_shape("geo", mb.Box((a, a, a))), floor, k, e, 400.0, 1e-5)
    res = mb.simulate(m, 0.3, 0.01, method="dop853", rtol=1e-6)
    assert res.success
    assert abs(res.position("box")[-1, 2] - (a / 2 - d)) < 1e-3 * d
    assert np.max(np.abs(res.orientation("box")[-1] - np.eye(3))) < 1e-6
    pts = res.contact_points("c")
    last = pts[pts.time == pts.time.max()]
    assert c and len(last) == 4 and np.allclose(last.penetration, d, rtol=1e-3)


def test_box_dropped_tilted_on_a_mesh_floor_comes_to_rest_flat():
    a, mass, k, e = 0.1, 1.0, 1e6, 1.0
    from scipy.spatial.transform import Rotation
    v, f = grid_surface(-0.52, -0.535, 10, 0.1, lambda x, y: 0.0 * x)
    m = mb.Model(gravity=(0, 0, -G))
    d = (mass * G / (4 * k)) ** (1 / e)
    b = m.add_body("box", mass, (mass * a * a / 6,) * 3, position=(0.0, 0.0, 0.12),
                   orientation=Rotation.from_rotvec((0.3, 0.2, 0.1)).as_matrix())
    floor = m.ground.add_shape("floor", mb.Mesh(v, f))
    m.add_contact("c", floor, b.add_shape("geo", mb.Box((a, a, a))), k, e, 400.0, 1e-5, mu=0.5,
                  friction_velocity=1e-3)
    res = mb.simulate(m, 1.5, 0.01, method="dop853", rtol=1e-6, monitor=False)   # (contact dissipates)
    assert res.success
    assert abs(res.position("box")[-1, 2] - (a / 2 - d)) < 2e-2 * d
    Rf = res.orientation("box")[-1]
    assert abs(abs(Rf[2, 2]) + abs(Rf[2, 1]) + abs(Rf[2, 0]) - 1.0) < 1e-4   # a face down


def test_ball_rolls_in_a_mesh_bowl_at_the_closed_form_period():
    """A ball of radius r rolling without slipping in a spherical bowl of radius R (a non-convex triangle
    mesh, the reference side): small oscillations at omega^2 = 5 g / (7 (R - r + delta)), delta the
    contact penetration."""
    R, r, rho, k, e = 0.5, 0.05, 1000.0, 1e6, 1.5
    L, n = 0.08, 48   # facets of 3.3 mm: the period converges with the facet size (1.9% at 6.7 mm)
    v, f = grid_surface(-L, -L, n, 2 * L / n, lambda x, y: R - np.sqrt(R * R - x * x - y * y))
    ball = mb.Sphere(radius=r)
    mass = ball.mass_properties(rho)[0]
    delta = (mass * G / k) ** (1 / e)
    rc = R - r + delta
    th0 = 0.05
    m = mb.Model(gravity=(0, 0, -G))
    b = m.add_body("ball", 0.0, position=(rc * np.sin(th0), 0.0, R - rc * np.cos(th0)))
    s = b.add_shape("geo", ball, density=rho)
    bowl = m.ground.add_shape("bowl", mb.Mesh(v, f))
    m.add_contact("c", bowl, s, k, e, 20.0, 1e-4, mu=0.5, friction_velocity=1e-2)
    w = np.sqrt(5 * G / (7 * rc))
    T = 2 * np.pi / w
    # (with the monitor: the compiled run accumulates the contact's dissipated energy itself, issue 29)
    res = mb.simulate(m, 1.9 * T, T / 200, method="dop853", rtol=1e-7)
    assert res.success
    x, t = res.position("ball")[:, 0], res.time
    up = np.where((x[:-1] < 0) & (x[1:] >= 0))[0]
    tz = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    assert len(tz) >= 2
    assert abs((tz[1] - tz[0]) / T - 1) < 1e-2, ((tz[1] - tz[0]), T)
    assert np.max(x[len(x) // 2:]) > 0.8 * x[0]   # rolls on, without sticking or sinking
    assert res.stats["energy"] == "compiled" and not res.diagnostics.exceedances

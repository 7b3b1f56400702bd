"""Model files carry body shapes (every geometry kind, meshes by relative path or inline arrays), their
densities, and shape contacts with every parameter (issue 30): round trip through YAML and JSON, attribute by
attribute, and the reloaded model simulates as the original to 1e-12; bad input names file, line and field."""
import shutil

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelFileError
from mbdsim.io import load_model, model_from_dict, model_to_dict, save_model

K, E = 1e5, 1.5


def write_stl(path, a=0.1):
    import trimesh
    trimesh.creation.box((a, a, a)).export(path)
    return path


def every_shape_model(mesh_file):
    """A body of each geometry kind above a floor, and a contact of each normal and friction law."""
    import trimesh
    from scipy.spatial.transform import Rotation
    m = mb.Model("shapes", gravity=(0, 0, -9.81))
    floor = m.ground.add_shape("floor", mb.Box((4.0, 4.0, 0.2)), center=(0, 0, -0.1))
    plane = mb.Plane(m.ground, (0, 0, 0), (0, 0, 1))
    tilt = Rotation.from_rotvec([0.05, -0.03, 0.2]).as_matrix()
    ico = trimesh.creation.icosphere(1)
    geos = {"box": mb.Box((0.1, 0.12, 0.08)), "cyl": mb.Cylinder(0.05, 0.1, axis=(0.0, 1.0, 0.1)),
            "cylx": mb.Cylinder(0.04, 0.1, axis="x"), "cap": mb.Capsule(0.04, 0.1, axis=(1.0, 0.2, 0.0)),
            "ell": mb.Ellipsoid((0.06, 0.05, 0.04)), "sph": mb.Sphere(radius=0.05),
            "hull": mb.ConvexMesh(np.random.default_rng(3).normal(size=(20, 3)) * 0.04),
            "stl": mb.Mesh(mesh_file, scale=0.5), "arr": mb.Mesh(ico.vertices * 0.05, ico.faces)}
    shapes = {}
    for k, (name, g) in enumerate(geos.items()):
        x = 0.3 * k - 1.2
        b = m.add_body(name, mass=0.2, inertia=(1e-4, 2e-4, 3e-4), position=(x, 0, 0.1),
                       orientation=tilt if k % 2 else None, velocity=(0.1, 0, 0) if k % 3 == 0 else None)
        shapes[name] = b.add_shape("geo", g, center=(x, 0.001, 0.1) if k % 2 else None,
                                   orientation=tilt if k % 4 == 1 else None, density=800.0 if k % 3 else None)
    p = m.add_particle("ball", 0.1, position=(1.5, 0, 0.1))
    shapes["ball"] = p.add_shape("geo", mb.Sphere(radius=0.03), density=1000.0)
    m.bodies["box"].add_shape("nose", mb.Sphere(radius=0.02), center=(-1.2, 0.0, 0.15))
    m.add_contact("floor_mu", plane, [s for n, s in shapes.items() if n not in ("box", "hull")], K, E, 20.0, 1e-3,
                  mu=0.3, friction_velocity=2e-3)
    m.add_contact("floor_poisson", floor, [shapes["box"], shapes["hull"]], K, E, 20.0, 1e-3, restitution=0.4,
                  mu_static=0.5, mu_dynamic=0.4, stiction_velocity=1e-3, transition_velocity=5e-3)
    m.add_contact("round", [shapes["sph"], shapes["ball"]], shapes["cap"], K, 1.0, 5.0, 2e-3, mu_static=0.2,
                  mu_dynamic=0.1)
    m.add_contact("legacy_sides", [mb.Sphere(m.bodies["ell"], 0.01)], [plane], 1e4, 1.0, 1.0, 1e-3)
    return m


@pytest.fixture
def mesh_file(tmp_path):
    d = tmp_path / "meshes"
    d.mkdir()
    return write_stl(d / "cube.stl")


def same(a, b):
    """Equal floats / arrays / strings (exactly)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    return a == b


GEOMETRY_FIELDS = ("size", "radius", "length", "axis", "radii", "vertices", "faces", "scale")


def assert_models_equal(m1, m2):
    assert list(m1.bodies) == list(m2.bodies)
    for name, b1 in m1.bodies.items():
        b2 = m2.bodies[name]
        assert same(b1.mass, b2.mass) and same(np.asarray(b1.inertia), np.asarray(b2.inertia)), name
        assert list(b1.shapes) == list(b2.shapes), name
        for sname, s1 in b1.shapes.items():
            s2 = b2.shapes[sname]
            assert type(s1.geometry) is type(s2.geometry)
            for f in ("s_B", "R_BG", "density", "given_center", "given_orientation"):
                assert same(getattr(s1, f), getattr(s2, f)), (name, sname, f)
            for f in GEOMETRY_FIELDS:
                if hasattr(s1.geometry, f):
                    assert same(getattr(s1.geometry, f), getattr(s2.geometry, f)), (name, sname, f)
    assert list(m1.forces) == list(m2.forces)
    for name, e1 in m1.forces.items():
        e2 = m2.forces[name]
        assert type(e1) is type(e2)
        for f in ("stiffness", "exponent", "damping", "penetration", "mu", "friction_velocity", "restitution",
                  "mu_static", "mu_dynamic", "stiction_velocity", "transition_velocity"):
            assert same(getattr(e1, f), getattr(e2, f)), (name, f)
        names = lambda side: [(s.body.name, getattr(s, "name", getattr(s, "kind", None))) for s in side]  # noqa
        assert names(e1.shapes_i) == names(e2.shapes_i) and names(e1.shapes_j) == names(e2.shapes_j)
        assert [(a.body.name, b.body.name) for a, b in e1.pairs] == [(a.body.name, b.body.name) for a, b in e2.pairs]


@pytest.mark.parametrize("ext", ["yaml", "json"])
def test_every_shape_and_contact_law_round_trips_and_simulates_the_same(ext, tmp_path, mesh_file):
    m1 = every_shape_model(mesh_file)
    path = save_model(m1, tmp_path / f"model.{ext}")
    text = path.read_text()
    assert "meshes/cube.stl" in text and str(tmp_path) not in text     # relative to the model file's folder
    m2 = load_model(path)
    assert_models_equal(m1, m2)
    assert model_to_dict(m2, tmp_path) == model_to_dict(m1, tmp_path)
    # moved with its meshes elsewhere, it still loads
    moved = tmp_path / "moved"
    shutil.copytree(tmp_path / "meshes", moved / "meshes")
    shutil.copy(path, moved / path.name)
    assert_models_equal(m1, load_model(moved / path.name))
    r1 = mb.simulate(m1, 0.03, 0.005, method="dop853", rtol=1e-9)
    r2 = mb.simulate(m2, 0.03, 0.005, method="dop853", rtol=1e-9)
    assert r1.success and r2.success
    for name in m1.bodies:
        if name != "ground":
            assert np.max(np.abs(r1.position(name) - r2.position(name))) <= 1e-12, name
    assert np.max(np.abs(r1.position("box")[:, 2] - r1.position("box")[0, 2])) > 1e-4   # it did move


def test_density_is_not_counted_twice(mesh_file):
    m = mb.Model()
    b = m.add_body("b", mass=0.0, inertia=(0, 0, 0))
    b.add_shape("g", mb.Box((0.1, 0.2, 0.3)), density=1000.0)
    d = model_to_dict(m)
    assert d["bodies"][0]["mass"] == 0.0 and d["bodies"][0]["shapes"][0]["density"] == 1000.0
    m2 = model_from_dict(d)
    assert m2.bodies["b"].mass == b.mass == pytest.approx(6.0)
    b.mass = 7.0    # changed after the shapes: the totals are written, the shape without density
    d = model_to_dict(m)
    assert d["bodies"][0]["mass"] == 7.0 and "density" not in d["bodies"][0]["shapes"][0]
    assert model_from_dict(d).bodies["b"].mass == 7.0


def test_units_on_shapes_and_contacts():
    d = {"bodies": [{"name": "b", "mass": "0 kg", "inertia": [0, 0, 0], "position": [0, 0, "50 mm"],
                     "shapes": [{"name": "g", "geometry": {"type": "capsule", "radius": "2 cm", "length": "100 mm",
                                                          "axis": "x"}, "density": "1 g/cm**3"}]}],
         "ground": {"shapes": [{"name": "floor", "geometry": {"type": "box", "size": ["2 m", "2 m", "10 cm"]},
                                "center": [0, 0, "-5 cm"]}]},
         "forces": [{"type": "contact", "name": "c", "shape_i": "ground.floor", "shape_j": ["b.g"],
                     "stiffness": "100 kN/m", "exponent": 1, "damping": "10 N*s/m", "penetration": "1 mm",
                     "mu_static": 0.3, "mu_dynamic": 0.2, "stiction_velocity": "1 mm/s",
                     "transition_velocity": "1 cm/s"}]}
    m = model_from_dict(d)
    c = m.forces["c"]
    assert c.stiffness == pytest.approx(1e5) and c.penetration == pytest.approx(1e-3)
    assert c.stiction_velocity == pytest.approx(1e-3) and c.transition_velocity == pytest.approx(1e-2)
    g = m.bodies["b"].shapes["g"].geometry
    assert g.radius == pytest.approx(0.02) and g.length == pytest.approx(0.1)
    r, L = 0.02, 0.1
    assert m.bodies["b"].mass == pytest.approx(1000 * (np.pi * r * r * L + 4 / 3 * np.pi * r ** 3), rel=1e-12)


def write(tmp_path, text):
    p = tmp_path / "bad.yaml"
    p.write_text(text)
    return p


BODY = """bodies:
  - name: b
    mass: 1
    inertia: [1, 1, 1]
    shapes:
      - name: g
        geometry:
"""


@pytest.mark.parametrize("geometry, line, words", [
    ("          type: mesh\n          path: nowhere/part.stl\n", 9, ["nowhere/part.stl", "not found",
                                                                    "shape 'b.g'", "geometry.path"]),
    ("          type: box\n          size: [1, 2]\n", 9, ["expected 3 values", "shapes[0].geometry.size"]),
    ("          type: cone\n", 8, ["cone", "type"]),
    ("          type: convex_mesh\n          vertices: [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]\n", 9,
     ["span no volume", "shape 'b.g'"]),
    ("          type: mesh\n          vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]\n", 9,
     ["faces"]),
])
def test_bad_shapes_name_file_line_and_field(tmp_path, geometry, line, words):
    p = write(tmp_path, BODY + geometry)
    with pytest.raises(ModelFileError) as info:
        load_model(p)
    msg = str(info.value)
    assert "bad.yaml" in msg and f"line {line}" in msg, msg
    for w in words:
        assert w in msg, (w, msg)


def test_a_contact_with_an_unknown_shape_lists_the_shapes(tmp_path):
    p = write(tmp_path, BODY + "          type: sphere\n          radius: 0.1\n" + """forces:
  - type: contact
    name: c
    shape_i: {type: plane, body: ground, point: [0, 0, 0], normal: [0, 0, 1]}
    shape_j: [b.g, b.h]
    stiffness: 1e5
    exponent: 1
    damping: 10
    penetration: 1e-3
""")
    with pytest.raises(ModelFileError) as info:
        load_model(p)
    msg = str(info.value)
    assert "contact 'c'" in msg and "'b.h' not found" in msg and "b.g" in msg and "line 14" in msg, msg

"""Model files: every element kind survives model -> dict -> file -> model unchanged; units; simulation identity."""
import math

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelError
from mbdsim.io import json_schema, model_from_dict, model_to_dict


def every_kind_model():
    """One model holding every kind of entity the API builds (not meant to be simulated)."""
    from scipy.spatial.transform import Rotation
    m = mb.Model("all", gravity=(0, 0, -9.81))
    a = m.add_body("a", mass=2.0, inertia=(0.1, 0.2, 0.25), position=(0.3, 0.1, 0.7),
                   orientation=Rotation.from_euler("ZXZ", [0.3, 0.2, 0.1]).as_matrix(), velocity=(1, 0, 0),
                   angular_velocity=(0, 0, 2))
    a.add_marker("tip", point=(0.6, 0.1, 0.7), orientation=Rotation.from_rotvec([0, 0.3, 0]).as_matrix())
    b = m.add_body("b", shape=mb.Box((0.1, 0.2, 0.3)), density=7800, position=(1.0, 0.0, 0.0))
    c = m.add_body("c", mass=1.0, inertia=[[0.1, 0.01, 0], [0.01, 0.1, 0], [0, 0, 0.15]], position=(0, 2, 0))
    p = m.add_particle("p", mass=0.5, position=(0, 0, 3), velocity=(0, 1, 0))
    p.add_marker("c0")
    d = m.add_body("d", mass=1.0, inertia=(0.1, 0.1, 0.1), position=(0, -1, 0))
    e = m.add_body("e", mass=1.0, inertia=(0.1, 0.1, 0.1), position=(0, -2, 0))
    m.add_revolute("rev", m.ground, a, point=(0, 0, 0.7), axis=(0.2, 0.3, 1.0))
    m.add_translational("tra", m.ground, b, point=(1, 0, 0), axis=(1, 1, 0))
    m.add_cylindrical("cyl", m.ground, c, point=(0, 2, 0), axis=(0, 0, 1))
    m.add_spherical("sph", a, b, point=(0.5, 0, 0))
    m.add_universal("uni", m.ground, d, point=(0, -1, 0), axis_i=(1, 0, 0), axis_j=(0, 1, 0))
    m.add_planar("pla", m.ground, e, point=(0, -2, 0), normal=(0, 0, 1), u_axis=(0, 1, 0))
    m.add_fixed("fix", d, "e")
    m.add_point_on_curve("poc", a.markers["tip"], m.ground, mb.Spline([(0, 0, 0), (1, 0.2, 0), (2, 0, 0.1), (3, 1, 0)]))
    m.add_motion("m1", "rev", displacement="pi/6*(1-cos(pi*t/2))")
    m.add_motion("m2", "tra", velocity=0.5, initial_displacement=0.01)
    m.add_motion("m3", "cyl", acceleration="STEP(t, 0, 0, 1, 2)", initial_velocity=0.2, dof="translation")
    m.add_force("f", a.markers["tip"], (1, 2, 3), frame=a)
    m.add_force("f2", (b, (1.05, 0.01, 0.02)), (0, 0, -5), frame=a.markers["tip"])
    m.add_torque("tq", c, (0, 0, 1.5))
    m.add_spring_damper("k", a.markers["tip"], (b, (1.0, 0.0, 0.1)), stiffness=3000.0, damping=10.0, preload=1.0)
    m.add_torsion_spring("ks", "rev", 20.0, 0.5, free_angle=0.1, preload=0.2)
    m.add_bushing("bu", (d, (0, -1.5, 0)), (e, (0, -1.5, 0)), stiffness=(1e4,) * 3 + (100,) * 3, damping=(10,) * 6)
    m.add_contact("ct", mb.Sphere(p, 0.05), mb.Plane(m.ground, (0, 0, 0), (0, 0.1, 1)), 1e5, 1.5, 10.0, 1e-3, mu=0.3)
    m.add_stop("st", "cyl", lower=-0.1, upper=0.2, stiffness=1e4, dof="translation")
    m.add_friction("fr", "rev", 0.2, 0.15, pin_radius=0.01, preload=0.1)
    return m


@pytest.fixture(scope="module")
def every_kind_dict():
    return model_to_dict(every_kind_model())


def test_every_kind_round_trips_through_dict(every_kind_dict):
    d = every_kind_dict
    assert {j["type"] for j in d["joints"]} == {"revolute", "translational", "cylindrical", "spherical", "universal",
                                                 "planar", "fixed", "point_on_curve"}
    assert {f["type"] for f in d["forces"]} == {"force", "torque", "spring_damper", "torsion_spring", "bushing",
                                                 "contact", "stop", "friction"}
    assert model_to_dict(model_from_dict(d)) == d


@pytest.mark.parametrize("ext", ["yaml", "json"])
def test_every_kind_round_trips_through_files(every_kind_dict, tmp_path, ext):
    path = tmp_path / f"m.{ext}"
    mb.save_model(model_from_dict(every_kind_dict), path)
    again = mb.load_model(path)
    assert model_to_dict(again) == every_kind_dict
    mb.save_model(again, tmp_path / f"m2.{ext}")
    assert model_to_dict(mb.load_model(tmp_path / f"m2.{ext}")) == every_kind_dict


def test_built_model_matches_the_python_one():
    py, d = every_kind_model(), model_to_dict(every_kind_model())
    m = model_from_dict(d)
    for name, b in py.bodies.items():
        assert np.array_equal(m.bodies[name].inertia, b.inertia) and m.bodies[name].mass == b.mass
        assert np.array_equal(m.bodies[name].orientation, b.orientation)
    for name, j in py.joints.items():
        assert np.array_equal(m.joints[name].axis, j.axis) and np.array_equal(m.joints[name].point, j.point)
    assert np.array_equal(m.forces["f2"].s_B, py.forces["f2"].s_B) or \
        np.allclose(m.forces["f2"].s_B, py.forces["f2"].s_B, rtol=0, atol=1e-15)
    for t in (0.0, 0.7, 1.9):
        assert m.motions["m3"].function.value(t) == pytest.approx(py.motions["m3"].function.value(t), abs=1e-14)


def test_box_mass_properties_closed_form():
    m, J = mb.Box((0.1, 0.2, 0.3)).mass_properties(7800)
    assert m == pytest.approx(7800 * 0.006)
    assert np.allclose(np.diag(J), m / 12 * np.array([0.04 + 0.09, 0.01 + 0.09, 0.01 + 0.04]))
    m, J = mb.Cylinder(0.1, 2.0, axis="y").mass_properties(1000)
    assert m == pytest.approx(1000 * math.pi * 0.01 * 2)
    assert np.allclose(np.diag(J), [m * (0.03 + 4) / 12, m * 0.01 / 2, m * (0.03 + 4) / 12])
    m, J = mb.Sphere(None, 0.5).mass_properties(2.0)
    assert m == pytest.approx(2 * 4 / 3 * math.pi / 8) and J[0, 0] == pytest.approx(0.4 * m * 0.25)


@pytest.mark.parametrize("kwargs, field", [
    (dict(mass=0.0 - 1), "mass"), (dict(mass=True), "mass"), (dict(mass=float("inf")), "mass"),
    (dict(mass=1.0, inertia=(-1.0, 1.0, 1.0)), "inertia"),
    (dict(mass=1.0, inertia=(True, 1.0, 1.0)), "inertia"), (dict(shape=mb.Box((1, 1, 1))), "density"),
    (dict(mass=1.0, shape=mb.Box((1, 1, 1)), density=1.0), "mass"),
])
def test_bad_mass_properties_name_body_and_field(kwargs, field):
    with pytest.raises(ModelError) as err:
        mb.Model().add_body("blk", **kwargs)
    assert err.value.entity == "body 'blk'" and err.value.field == field


def test_impossible_inertia_fails_in_the_api_and_in_a_file():
    with pytest.raises(ModelError, match=r"body 'blk'.inertia: principal moments 1, 1, 2.5"):
        mb.Model().add_body("blk", mass=1.0, inertia=(1.0, 1.0, 2.5))
    with pytest.raises(mb.ModelFileError, match=r"body 'blk'.inertia: .*triangle inequality"):
        model_from_dict({"bodies": [{"name": "blk", "mass": 1, "inertia": [1, 1, 2.5]}]})


def test_units_are_converted_and_checked():
    d = {"name": "u", "gravity": [0, "-9.81 m/s^2", 0],
         "bodies": [{"name": "a", "mass": "500 g", "inertia": ["1 g*m^2", "2 kg*cm^2", 0.001],
                     "position": ["500 mm", 0, 0], "angular_velocity": [0, 0, "60 deg/s"],
                     "orientation": {"axis": [0, 0, 1], "angle": "30 deg"}}],
         "joints": [{"name": "pin", "type": "revolute", "body_i": "ground", "body_j": "a", "point": [0, 0, 0],
                     "axis": [0, 0, 1]}],
         "forces": [{"name": "k", "type": "torsion_spring", "joint": "pin", "stiffness": "3 kN*m/rad"}]}
    m = model_from_dict(d)
    a = m.bodies["a"]
    assert a.mass == 0.5 and a.position[0] == 0.5 and a.angular_velocity[2] == pytest.approx(math.pi / 3)
    assert np.allclose(np.diag(a.inertia), [1e-3, 2e-4, 1e-3])
    assert a.orientation[1, 0] == pytest.approx(0.5)
    assert m.forces["k"].stiffness == 3000.0
    with pytest.raises(mb.ModelFileError, match=r"body 'a'.position\[0\].*not a length"):
        model_from_dict({"bodies": [{"name": "a", "mass": 1, "position": ["2 kg", 0, 0]}]})


def test_callables_cannot_be_saved(tmp_path):
    m = mb.Model()
    b = m.add_body("b", mass=1.0, inertia=(1, 1, 1))
    m.add_torque("spin", b, lambda t, s: (0, 0, t))
    with pytest.raises(ModelError, match="torque 'spin'.torque: a Python callable"):
        mb.save_model(m, tmp_path / "x.yaml")
    m2 = mb.Model()
    m2.add_revolute("pin", m2.ground, m2.add_body("b", mass=1.0, inertia=(1, 1, 1)), (0, 0, 0), (0, 0, 1))
    m2.add_motion("drv", "pin", displacement=lambda t: t)
    with pytest.raises(ModelError, match="motion 'drv'.displacement"):
        model_to_dict(m2)


def test_json_schema_covers_every_kind():
    s = json_schema()
    text = str(s)
    for kind in ("point_on_curve", "bushing", "contact", "friction", "stop", "torsion_spring", "universal"):
        assert f"'{kind}'" in text
    assert s["additionalProperties"] is False


def test_readme_model_file_snippet_loads():
    import re
    from pathlib import Path

    import yaml
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    block = re.findall(r"```yaml\n(.*?)```", text, re.S)[0]
    m = model_from_dict(yaml.safe_load(block), source="README.md")
    assert m.bodies["box"].mass == pytest.approx(7800 * 0.006) and m.bodies["rod"].position[0] == 0.5


def joint_model(extra):
    base = {"bodies": [{"name": "a", "mass": 1, "inertia": [1, 1, 1]}, {"name": "s", "mass": 1, "inertia": [1, 1, 1]}],
            "joints": [{"name": "pin", "type": "revolute", "body_i": "ground", "body_j": "a", "point": [0, 0, 0],
                        "axis": [0, 0, 1]},
                       {"name": "rail", "type": "translational", "body_i": "ground", "body_j": "s", "point": [0, 0, 0],
                        "axis": [1, 0, 0]}]}
    base.update(extra)
    return model_from_dict(base)


def test_joint_dependent_units():
    m = joint_model({
        "motions": [{"name": "spin", "joint": "pin", "velocity": "60 deg/s", "initial_displacement": "90 deg"}],
        "forces": [{"name": "lim", "type": "stop", "joint": "rail", "lower": "-20 mm", "upper": "3 cm",
                    "stiffness": "2 kN/m^1.5", "damping": "10 N*s/m", "penetration": "1 mm"},
                   {"name": "fr", "type": "friction", "joint": "rail", "mu_static": 0.3, "mu_dynamic": 0.2,
                    "preload": "2 kN"},
                   {"name": "ct", "type": "contact", "shape_i": {"type": "sphere", "body": "s", "radius": "5 cm"},
                    "shape_j": {"type": "plane", "body": "ground", "point": [0, 0, 0], "normal": [0, 0, 1]},
                    "stiffness": "1 kN/mm^1.5", "exponent": 1.5, "damping": 10, "penetration": "0.1 mm"},
                   {"name": "bu", "type": "bushing", "marker_i": "a", "marker_j": "s",
                    "stiffness": ["1 kN/m", 0, 0, "2 N*m/deg", 0, 0], "preload": [0, 0, 0, 0, 0, "3 N*m"]}]})
    f = m.motions["spin"].function
    assert f.d1(0.3) == pytest.approx(math.pi / 3) and f.value(0.0) == pytest.approx(math.pi / 2)
    st = m.forces["lim"]
    assert (st.lower, st.upper, st.stiffness, st.penetration) == pytest.approx((-0.02, 0.03, 2000.0, 1e-3))
    assert m.forces["fr"].preload == 2000.0
    assert m.forces["ct"].stiffness == pytest.approx(1e3 * 1e3 ** 1.5) and m.forces["ct"].shape_i.radius == 0.05
    assert m.forces["bu"].stiffness[3] == pytest.approx(2 * 180 / math.pi) and m.forces["bu"].preload[5] == 3.0
    with pytest.raises(mb.ModelFileError, match=r"stop 'lim'.lower: .*not a length"):
        joint_model({"forces": [{"name": "lim", "type": "stop", "joint": "rail", "lower": "-20 deg", "stiffness": 1}]})
    with pytest.raises(mb.ModelFileError, match=r"motion 'spin'.velocity"):
        joint_model({"motions": [{"name": "spin", "joint": "pin", "velocity": "60 mm/s"}]})


def test_parametric_curve_from_expressions_round_trips():
    d = {"bodies": [{"name": "bead", "mass": 1, "inertia": [1, 1, 1], "position": [1, 0, 0],
                     "markers": [{"name": "c", "point": [1, 0, 0]}]}],
         "joints": [{"name": "ring", "type": "point_on_curve", "marker": "bead.c", "body": "ground",
                     "curve": {"type": "curve", "x": "cos(s)", "y": "sin(s)", "z": 0, "s_range": [0, "360 deg"],
                               "closed": True}}]}
    m = model_from_dict(d)
    C, d1, d2 = m.path_constraints["ring"].curve.derivatives(0.3)
    assert np.allclose(d1, [-math.sin(0.3), math.cos(0.3), 0]) and np.allclose(d2, [-math.cos(0.3), -math.sin(0.3), 0])
    once = model_to_dict(m)
    assert model_to_dict(model_from_dict(once)) == once
    with pytest.raises(mb.ModelFileError, match=r"joint 'ring'.curve: .*not allowed"):
        d["joints"][0]["curve"]["x"] = "__import__('os').getcwd()"
        model_from_dict(d)


def test_velocities_left_out_of_a_file_are_free_as_in_the_api():
    """A body without `velocity` / `angular_velocity` is solved at assembly (not held at zero): a driven
    crank from a file assembles without an InitialConditionWarning, and w = 2 pi rad/s as driven."""
    import warnings
    d = {"name": "crank", "bodies": [{"name": "c", "mass": 1, "inertia": [0.01, 0.01, 0.01], "position": [0.1, 0, 0]},
                                     {"name": "z", "mass": 1, "inertia": [0.01, 0.01, 0.01], "velocity": [0, 0, 0],
                                      "position": [0, 1, 0]}],
         "particles": [{"name": "p", "mass": 1, "position": [0, 2, 0]}],
         "joints": [{"name": "pin", "type": "revolute", "body_i": "ground", "body_j": "c", "point": [0, 0, 0],
                     "axis": [0, 0, 1]}],
         "motions": [{"name": "drive", "joint": "pin", "displacement": "2*pi*t"}]}
    m = model_from_dict(d)
    c, z, p = m.bodies["c"], m.bodies["z"], m.bodies["p"]
    assert not c.velocity_given and not c.angular_velocity_given and not p.velocity_given
    assert z.velocity_given and not z.angular_velocity_given
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rep = mb.assemble(m)
        res = mb.simulate(m, 0.01, 0.01)
    assert res.angular_velocity(c)[0] == pytest.approx([0, 0, 2 * math.pi], abs=1e-9)
    assert res.velocity(c)[0] == pytest.approx([0, 0.2 * math.pi, 0], abs=1e-9) and rep.dof == 9
    again = model_to_dict(model_from_dict(model_to_dict(m)))
    bodies = {b["name"]: b for b in again["bodies"]}
    assert "velocity" not in bodies["c"] and bodies["z"]["velocity"] == [0.0, 0.0, 0.0]
    assert "angular_velocity" not in bodies["z"]
    assert again == model_to_dict(m)

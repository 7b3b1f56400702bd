"""Model files carry every field the API takes: a model built with every element kind and option of the
API (issue 34) is saved to YAML and JSON, reloaded, and compared with the original attribute by
attribute (not through model_to_dict, which would hide a field dropped on both sides); a simulated
model agrees with its reloaded copy to 1e-12."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.io import model_from_dict
from mbdsim.model.joint_kinds import JOINT_KINDS


def full_model():
    """Every element kind and option of the Model API (not meant to be simulated)."""
    from scipy.spatial.transform import Rotation
    m = mb.Model("full", gravity=(0, 0, -9.81))
    m.add_input("u", 0.25)
    rot = Rotation.from_euler("ZXZ", [0.3, 0.2, 0.1]).as_matrix()
    a = m.add_body("a", mass=2.0, inertia=(0.1, 0.2, 0.25), position=(0.3, 0.1, 0.7), orientation=rot,
                   velocity=(1, 0, 0), angular_velocity=(0, 0, 2))
    a.add_marker("tip", point=(0.6, 0.1, 0.7), orientation=Rotation.from_rotvec([0, 0.3, 0]).as_matrix())
    a.add_marker("base")
    b = m.add_body("b", shape=mb.Box((0.1, 0.2, 0.3)), density=7800, position=(1.0, 0.0, 0.0), velocity=(0, 1, 0))
    b.add_marker("top", point=(1.0, 0.0, 0.15))
    c = m.add_body("c", shape=mb.Cylinder(0.05, 0.4, axis="y"), density=2700, position=(0, 2, 0),
                   angular_velocity=(0, 1, 0))
    s = m.add_body("s", shape=mb.Sphere(None, 0.1), density=1000, position=(0, 3, 0))
    p = m.add_particle("p", mass=0.5, position=(0, 0, 3), velocity=(0, 1, 0))
    p.add_marker("c0")
    m.ground.add_marker("anchor", point=(0, 0, 2), orientation=Rotation.from_rotvec([0.1, 0, 0]).as_matrix())
    bodies = [m.add_body(f"link{n}", mass=1.0, inertia=[[0.1, 0.01, 0], [0.01, 0.1, 0], [0, 0, 0.15]],
                         position=(n, -1, 0)) for n in range(len(JOINT_KINDS) + 4)]
    for k in bodies:
        k.add_marker("m", point=k.position + (0, 0.1, 0))
    g, x, y, z = m.ground, (1, 0, 0), (0, 1, 0), (0, 0, 1)
    k = iter(bodies)
    m.add_revolute("rev", g, a, point=(0, 0, 0.7), axis=(0.2, 0.3, 1.0), initial_displacement=0.5,
                   initial_velocity=-1.5)
    m.add_translational("tra", g, b, point=(1, 0, 0), axis=(1, 1, 0), initial_displacement=0.01,
                        initial_velocity=0.2)
    m.add_cylindrical("cyl", g, c, point=(0, 2, 0), axis=z, initial_displacement=(0.1, 0.02),
                      initial_velocity=(1.0, -0.3))
    m.add_spherical("sph", g, s, point=(0, 3, 0.1), initial_displacement=(0.1, 0.2, 0.3), initial_velocity=(1, 2, 3))
    m.add_universal("uni", g, next(k), point=(0, -1, 0), axis_i=x, axis_j=y, initial_displacement=(0.1, 0.2, 0),
                    initial_velocity=(0.5, 0, 0))
    m.add_planar("pla", g, next(k), point=(1, -1, 0), normal=z, u_axis=y, initial_displacement=(0.01, 0.02, 0.3),
                 initial_velocity=(0.1, 0.2, 0.3))
    k2 = next(k)
    m.add_fixed("fix", g, k2)
    m.add_fixed("fix_at", k2, next(k), point=(2.5, -1, 0))
    m.add_inline("il", g, next(k), (4, -1, 0), z)
    k5 = next(k)
    m.add_inplane("ip", g, k5, (5, -1, 0), normal=z)
    m.add_orientation("or", g, k5)
    k6 = next(k)
    m.add_parallel_axes("pa", g, k6, z)
    m.add_perpendicular("pp", g, k6, x, y)
    m.add_atpoint("ap", g, next(k), (7, -1, 0))
    m.add_screw("sc", g, next(k), (8, -1, 0), y, lead=0.01, initial_displacement=0.3, initial_velocity=2.0)
    k9, k10 = next(k), next(k)
    m.add_constant_velocity("cv", k9, k10, (9.5, -1, 0), x, (0.8, 0.6, 0))
    # joints between two markers, with and without initial conditions
    k11, k12, k13 = next(k), next(k), next(k)
    m.add_revolute("mrev", g.markers["anchor"], k11.markers["m"], initial_displacement=0.25, initial_velocity=1.0)
    m.add_universal("muni", k11.markers["m"], k12.markers["m"])
    m.add_screw("msc", k12.markers["m"], k13.markers["m"], lead=-0.02)
    m.add_point_on_curve("poc", a.markers["tip"], g, mb.Spline([(0, 0, 0), (1, 0.2, 0), (2, 0, 0.1), (3, 1, 0)]))
    m.add_point_on_curve("ring", p.markers["c0"], k10,
                         mb.Spline([(0, 0, 3), (1, 0, 3), (1, 1, 3), (0, 1, 3)], closed=True))
    # drivers
    m.add_motion("m1", "rev", displacement="pi/6*(1-cos(pi*t/2))")
    m.add_motion("m2", "tra", velocity=0.5, initial_displacement=0.01)
    m.add_motion("m3", "cyl", acceleration="STEP(t, 0, 0, 1, 2)", initial_displacement=0.1, initial_velocity=0.2,
                 dof="translation")
    m.add_motion("m4", "cyl", displacement=0.25)
    m.add_motion("m5", "sc", velocity="2*t", dof="translation")
    # loads and force elements
    m.add_force("f", a.markers["tip"], (1, 2, 3), frame=a)
    m.add_force("f2", (b, (1.05, 0.01, 0.02)), (0, 0, -5), frame=a.markers["tip"])
    m.add_force("fx", a, ("-10*DZ(a)", 0, "STEP(TIME, 0, 0, 1, 10)"), frame=g.markers["anchor"])
    m.add_torque("tq", c, (0, 0, 1.5))
    m.add_torque("tqx", a, (0, 0, "-0.2*WZ(a)"), frame=a.markers["base"])
    m.add_line_force("lf", a.markers["tip"], g.markers["anchor"], 3.0)
    m.add_line_force("lfx", (b, (1, 0, 0.1)), s, "30*(DM(a.tip, ground.anchor) - 0.4)")
    m.add_joint_force("jf", "rev", 0.5)
    m.add_joint_force("jfx", "cyl", "1.5*(1 - tra_dot/4)", dof="translation")
    m.add_spring_damper("k", a.markers["tip"], (b, (1.0, 0.0, 0.1)), stiffness=3000.0, damping=10.0, preload=1.0)
    m.add_spring_damper("k2", b.markers["top"], s, stiffness=10.0, free_length=0.7)
    m.add_torsion_spring("ks", "rev", 20.0, 0.5, free_angle=0.1, preload=0.2)
    m.add_torsion_spring("ks2", "cyl", 3.0)
    m.add_bushing("bu", (k6, (6, -1.5, 0)), (k5, (6, -1.5, 0)), stiffness=(1e4,) * 3 + (100,) * 3,
                  damping=(10,) * 6, preload=(1, 2, 3, 4, 5, 6))
    m.add_bushing("bu2", k9.markers["m"], k10.markers["m"], stiffness=(1, 2, 3, 4, 5, 6))
    m.add_contact("ct", mb.Sphere(p, 0.05), mb.Plane(g, (0, 0, 0), (0, 0.1, 1)), 1e5, 1.5, 10.0, 1e-3, mu=0.3,
                  friction_velocity=0.01)
    m.add_contact("ct2", mb.Sphere(s, 0.1, center=(0, 3, 0.01)), mb.Sphere(a, 0.2), 1e4, 2.0, 5.0, 2e-3)
    m.add_stop("st", "cyl", lower=-0.1, upper=0.2, stiffness=1e4, exponent=2.0, damping=3.0, penetration=0.002,
               dof="translation")
    m.add_stop("st2", "rev", upper=1.0, stiffness=50.0)
    m.add_friction("fr", "rev", 0.2, 0.15, pin_radius=0.01, preload=0.1, friction_arm=0.02, bending_arm=0.03)
    m.add_friction("fr2", "tra", 0.3, 0.2, preload=2.0, effective_length=0.1, reaction_arm=0.05)
    # coordinate constraints and sensors
    m.add_coupler("cp", "tra", "cyl", 0.05, dof_2="translation")
    m.add_coupler("cp2", "rev", "sc", -2.0)
    m.add_gear("gr", "rev", "mrev", -0.5)
    m.add_user_constraint("uc", "sin(rev) - 0.2*tra")
    m.add_sensor("turn", "rev - 0.5", value=0.1, direction=1, action="record")
    m.add_sensor("stop", "tra_dot", direction=-1)
    m.add_sensor("reach", "rev - u", direction=1)
    m.add_output("angle_error", "rev - 2*u")
    return m


def _differences(a, b, path="model", seen=None, out=None):
    """Every attribute path where `a` and `b` differ (floats and arrays exactly; callables by name)."""
    seen = set() if seen is None else seen
    out = [] if out is None else out
    if type(a) is not type(b):
        out.append(f"{path}: {type(a).__name__} {a!r} != {type(b).__name__} {b!r}")
    elif isinstance(a, np.ndarray):
        if a.shape != b.shape or not np.array_equal(a, b):
            out.append(f"{path}: {a!r} != {b!r}")
    elif a is None or isinstance(a, (bool, int, float, complex, str, np.generic)):
        if a != b and not (a != a and b != b):
            out.append(f"{path}: {a!r} != {b!r}")
    elif isinstance(a, (list, tuple)):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items != {len(b)}")
        for k, (u, v) in enumerate(zip(a, b)):
            _differences(u, v, f"{path}[{k}]", seen, out)
    elif isinstance(a, (set, frozenset)):
        if a != b:
            out.append(f"{path}: {a!r} != {b!r}")
    elif isinstance(a, dict):
        if set(a) != set(b):   # order aside: a file lists bodies before particles
            out.append(f"{path}: keys {list(a)} != {list(b)}")
        for key in a:
            if key in b:
                _differences(a[key], b[key], f"{path}[{key!r}]", seen, out)
    elif type(a).__name__ in ("function", "method", "builtin_function_or_method") or \
            (callable(a) and not hasattr(a, "__dict__")):
        if getattr(a, "__qualname__", None) != getattr(b, "__qualname__", None):
            out.append(f"{path}: {a!r} != {b!r}")
    elif id(a) in seen:
        if getattr(a, "name", None) != getattr(b, "name", None):
            out.append(f"{path}: {a!r} != {b!r}")
    else:
        seen.add(id(a))
        fields = {k: v for k, v in vars(a).items() if k != "_assembled"} if hasattr(a, "__dict__") else {}
        fields.update({k: getattr(a, k) for k in getattr(type(a), "__slots__", ()) if hasattr(a, k)})
        other = {k: v for k, v in vars(b).items() if k != "_assembled"} if hasattr(b, "__dict__") else {}
        other.update({k: getattr(b, k) for k in getattr(type(b), "__slots__", ()) if hasattr(b, k)})
        _differences(fields, other, path, seen, out)
    return out


def _same_motions(m1, m2):
    for name, mo in m1.motions.items():
        f, g = mo.function, m2.motions[name].function
        for t in (0.0, 0.37, 1.3, 2.5):
            assert (f.value(t), f.d1(t), f.d2(t)) == pytest.approx((g.value(t), g.d1(t), g.d2(t)), rel=0, abs=1e-14), \
                (name, t)


@pytest.mark.parametrize("ext", ["yaml", "json"])
def test_every_api_field_survives_save_and_load(tmp_path, ext):
    m = full_model()
    again = mb.load_model(mb.save_model(m, tmp_path / f"full.{ext}"))
    assert _differences(m, again) == []
    _same_motions(m, again)
    assert again.joints["rev"].initial_displacement[0] == 0.5 and again.joints["mrev"].marker_i.name == "anchor"


def test_every_joint_kind_and_model_section_is_exercised():
    """The round-trip model above keeps up with the API: every joint kind and every add_* method."""
    m = full_model()
    assert {j.kind for j in m.joints.values()} == set(JOINT_KINDS)
    methods = {n for n in dir(mb.Model) if n.startswith("add_")} - {"add_element", "add_fmu", "add_function"}
    # (FMUs and numba functions are code: not in files; tests/test_user_functions.py checks the refusal)
    source = __import__("inspect").getsource(full_model)
    assert [n for n in sorted(methods) if f".{n}(" not in source] == []


def test_pin_initial_angle_reloads(tmp_path):
    """The reported case: a pin at 0.5 rad before saving is at 0.5 rad after reloading."""
    m = mb.Model("pin", gravity=(0, -9.81, 0))
    rod = m.add_body("rod", mass=1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0, 0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1), initial_displacement=0.5, initial_velocity=1.0)
    for ext in ("yaml", "json"):
        again = mb.load_model(mb.save_model(m, tmp_path / f"pin.{ext}"))
        assert again.joints["pin"].initial_displacement.tolist() == [0.5]
        assert again.joints["pin"].initial_velocity.tolist() == [1.0]


def test_file_units_for_joint_initial_conditions():
    d = {"bodies": [{"name": "a", "mass": 1, "inertia": [1, 1, 1]}, {"name": "b", "mass": 1, "inertia": [1, 1, 1]}],
         "joints": [{"name": "pin", "type": "revolute", "body_i": "ground", "body_j": "a", "point": [0, 0, 0],
                     "axis": [0, 0, 1], "initial_displacement": "90 deg", "initial_velocity": "60 rpm"},
                    {"name": "cyl", "type": "cylindrical", "body_i": "a", "body_j": "b", "point": [0, 0, 0],
                     "axis": [0, 0, 1], "initial_displacement": ["30 deg", "5 mm"], "initial_velocity": [1, "2 cm/s"]}]}
    m = model_from_dict(d)
    assert m.joints["pin"].initial_displacement[0] == pytest.approx(np.pi / 2)
    assert m.joints["pin"].initial_velocity[0] == pytest.approx(2 * np.pi)
    assert m.joints["cyl"].initial_displacement == pytest.approx([np.pi / 6, 0.005])
    assert m.joints["cyl"].initial_velocity == pytest.approx([1.0, 0.02])
    d["joints"][1]["initial_displacement"] = ["30 deg", "5 deg"]
    with pytest.raises(mb.ModelFileError, match=r"joint 'cyl'.initial_displacement.*not a length"):
        model_from_dict(d)
    d["joints"][1]["initial_displacement"] = [0.1]
    with pytest.raises(mb.ModelFileError, match=r"joint 'cyl'.initial_displacement"):
        model_from_dict(d)
    d["joints"][1] = {"name": "il", "type": "inline", "body_i": "a", "body_j": "b", "point": [0, 0, 0],
                      "axis": [0, 0, 1], "initial_velocity": 0.1}   # the API's add_inline takes none
    with pytest.raises(mb.ModelFileError, match=r"initial_velocity"):
        model_from_dict(d)


def simulated_model():
    """A small model with a joint started off its drawn position, loads and elements; simulated."""
    m = mb.Model("sim", gravity=(0, -9.81, 0))
    rod = m.add_body("rod", mass=1.0, inertia=(0.001, 0.02, 0.02), position=(0.25, 0, 0))
    rod.add_marker("tip", point=(0.5, 0, 0))
    m.ground.add_marker("anchor", point=(0.6, 0.3, 0))
    m.add_revolute("pin", m.ground, rod, (0, 0, 0), (0, 0, 1), initial_displacement=0.5, initial_velocity=-1.0)
    m.add_torsion_spring("ks", "pin", 2.0, 0.05, free_angle=0.2)
    m.add_spring_damper("k", rod.markers["tip"], m.ground.markers["anchor"], 30.0, 0.5, free_length=0.3)
    m.add_torque("drag", rod, (0, 0, "-0.02*WZ(rod)"))
    m.add_joint_force("motor", "pin", 0.1)
    return m


@pytest.mark.parametrize("ext", ["yaml", "json"])
def test_reloaded_model_simulates_the_same(tmp_path, ext):
    m = simulated_model()
    again = mb.load_model(mb.save_model(m, tmp_path / f"sim.{ext}"))
    assert _differences(m, again) == []
    r1, r2 = mb.simulate(m, 0.5, 0.05), mb.simulate(again, 0.5, 0.05)
    assert r1.success and r2.success
    assert np.allclose(r1.q, r2.q, rtol=0, atol=1e-12) and np.allclose(r1.v, r2.v, rtol=0, atol=1e-12)
    assert r1.joint_coordinate("pin")[0] == pytest.approx(0.5, abs=1e-9)

"""Joint initial conditions and given body velocities held at assembly (issue 16).

Closed forms: a pendulum (rod centre speed = arm x rate), the kinetic-energy-weighted fit of an
inconsistent (v, w) pair, and the slider-crank position law x = r cos(th) + sqrt(L^2 - r^2 sin^2(th)).
"""
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

M, IZZ, ARM = 2.0, 1.0 / 6.0, 0.5


def pendulum(unit=1.0, gram=1.0, iv=None, **kw):
    """Rod of mass M about a revolute at the origin, drawn along x; lengths x unit, masses x gram."""
    model = mb.Model("pendulum", gravity=(0.0, -9.81 * unit, 0.0))
    inertia = np.array([1e-4, IZZ, IZZ]) * gram * unit**2
    rod = model.add_body("rod", M * gram, inertia=inertia, position=(ARM * unit, 0, 0), **kw)
    model.add_revolute("pin", "ground", rod, (0, 0, 0), (0, 0, 1), initial_velocity=iv)
    return model, rod


def assembled(model):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = mb.assemble(model)
    return rep, [w for w in caught if issubclass(w.category, mb.InitialConditionWarning)]


def test_joint_initial_velocity_sets_the_rod_centre_velocity():
    model, rod = pendulum(iv=2.0)
    res = mb.simulate(model, 0.01, 0.005)
    np.testing.assert_allclose(res.velocity(rod)[0], [0.0, ARM * 2.0, 0.0], atol=1e-12)
    assert res.joint_velocity("pin")[0] == pytest.approx(2.0, abs=1e-12)


def test_given_velocity_only_gives_the_rate_exactly_without_warning():
    model, rod = pendulum(velocity=(0, 1, 0))
    rep, warned = assembled(model)
    assert not warned
    res = mb.simulate(model, 0.01, 0.005)
    assert res.joint_velocity("pin")[0] == pytest.approx(2.0, abs=1e-12)


def test_inconsistent_velocity_and_spin_are_fitted_in_the_kinetic_energy_metric():
    # minimise M (ARM w - 1)^2 + IZZ (w - 5)^2  ->  w = (M ARM + 5 IZZ) / (M ARM^2 + IZZ) = 2.75
    expected = (M * ARM * 1.0 + IZZ * 5.0) / (M * ARM**2 + IZZ)
    assert expected == pytest.approx(2.75)
    model, rod = pendulum(velocity=(0, 1, 0), angular_velocity=(0, 0, 5))
    rep, warned = assembled(model)
    assert rep.v[5] == pytest.approx(expected, abs=1e-10)
    assert len(warned) == 1 and "body 'rod'" in str(warned[0].message) and "2.75" in str(warned[0].message)
    assert "rod" in rep.velocity_changed and "given" in str(rep)


def test_the_fit_is_independent_of_units():
    si, _ = pendulum(velocity=(0, 1, 0), angular_velocity=(0, 0, 5))
    mm, _ = pendulum(unit=1000.0, gram=1000.0, velocity=(0, 1000, 0), angular_velocity=(0, 0, 5))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = mb.simulate(si, 0.3, 0.01)
        b = mb.simulate(mm, 0.3, 0.01)
    np.testing.assert_allclose(b.joint_coordinate("pin"), a.joint_coordinate("pin"), atol=1e-8)
    np.testing.assert_allclose(b.joint_velocity("pin"), a.joint_velocity("pin"), atol=1e-7)


# ----------------------------------------------------------------------------- slider-crank
R, L = 0.1, 0.3


def slider_law(th, w):
    s = np.sqrt(L**2 - (R * np.sin(th))**2)
    return R * np.cos(th) + s, -R * w * np.sin(th) - R**2 * w * np.sin(th) * np.cos(th) / s


def slider_crank(drawn, x0=None, v0=None):
    """Crank (revolute at the origin), rod, slider on the x axis, drawn at crank angle `drawn`."""
    model = mb.Model("slider_crank", gravity=(0, -9.81, 0))
    A = R * np.array([np.cos(drawn), np.sin(drawn), 0.0])
    B = np.array([slider_law(drawn, 0.0)[0], 0.0, 0.0])
    phi = np.arctan2(-A[1], B[0] - A[0])
    crank = model.add_body("crank", 1.0, inertia=(1e-4, 1e-3, 1e-3), position=A / 2,
                           orientation=Rotation.from_rotvec([0, 0, drawn]))
    rod = model.add_body("rod", 2.0, inertia=(1e-4, 0.015, 0.015), position=(A + B) / 2,
                         orientation=Rotation.from_rotvec([0, 0, phi]))
    slider = model.add_body("slider", 0.5, inertia=(1e-3, 1e-3, 1e-3), position=B)
    z = (0, 0, 1)
    model.add_revolute("O", "ground", crank, (0, 0, 0), z, initial_displacement=x0, initial_velocity=v0)
    model.add_revolute("A", crank, rod, A, z)
    model.add_spherical("B", rod, slider, B)
    model.add_translational("slide", "ground", slider, B, (1, 0, 0))
    return model, slider


def test_slider_crank_started_from_another_angle_matches_the_closed_form_and_the_redrawn_model():
    start, w0 = np.radians(60.0), 2 * np.pi
    moved, slider = slider_crank(np.radians(25.0), x0=start - np.radians(25.0), v0=w0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = mb.assemble(moved)
    assert not [w for w in caught if "initial values" in str(w.message)]
    assert "crank" in rep.moved and "slider" in rep.moved
    res = mb.simulate(moved, 0.2, 0.01)
    x, xd = slider_law(start, w0)
    assert res.position(slider)[0, 0] == pytest.approx(x, abs=1e-10)        # branch kept: + root
    assert res.velocity(slider)[0, 0] == pytest.approx(xd, abs=1e-10)
    assert res.joint_coordinate("O")[0] == pytest.approx(start - np.radians(25.0), abs=1e-12)
    drawn, slider2 = slider_crank(start, v0=w0)
    ref = mb.simulate(drawn, 0.2, 0.01)
    np.testing.assert_allclose(res.position(slider), ref.position(slider2), atol=1e-8)
    np.testing.assert_allclose(res.velocity(slider), ref.velocity(slider2), atol=1e-7)


def test_joint_initial_values_must_have_the_joint_coordinate_shape():
    model = mb.Model()
    b = model.add_body("b", 1.0, inertia=(1, 1, 1))
    with pytest.raises(mb.ModelError, match="initial_displacement"):
        model.add_cylindrical("c", "ground", b, (0, 0, 0), (0, 0, 1), initial_displacement=1.0)
    with pytest.raises(mb.ModelError, match="initial_velocity"):
        model.add_revolute("r", "ground", b, (0, 0, 0), (0, 0, 1), initial_velocity=(1, 2))
    assert "c" not in model.joints and "r" not in model.joints


# ----------------------------------------------------------------------------- multi-coordinate joints
def one_joint(kind, x0, v0):
    model = mb.Model(kind)
    b = model.add_body("b", 1.5, inertia=(0.02, 0.03, 0.04), position=(0.1, 0.2, 0.3))
    p, z = (0.1, 0.0, 0.3), (0, 0, 1)
    add = {"cylindrical": lambda: model.add_cylindrical("j", "ground", b, p, z, initial_displacement=x0,
                                                        initial_velocity=v0),
           "planar": lambda: model.add_planar("j", "ground", b, p, z, initial_displacement=x0, initial_velocity=v0),
           "spherical": lambda: model.add_spherical("j", "ground", b, p, initial_displacement=x0, initial_velocity=v0),
           "universal": lambda: model.add_universal("j", "ground", b, p, z, (1, 0, 0), initial_displacement=x0,
                                                    initial_velocity=v0)}[kind]
    add()
    return model


def universal_values():
    """A consistent universal start: Rot(z, a) Rot(x, c) and w = a' z + c' (Rot(z, a) x)."""
    a, c, ad, cd = 0.4, -0.3, 1.5, 2.0
    rv = (Rotation.from_rotvec([0, 0, a]) * Rotation.from_rotvec([c, 0, 0])).as_rotvec()
    w = ad * np.array([0, 0, 1.0]) + cd * Rotation.from_rotvec([0, 0, a]).apply([1.0, 0, 0])
    return rv, w


@pytest.mark.parametrize("kind,x0,v0", [
    ("cylindrical", (0.7, 0.05), (3.0, -0.4)),
    ("planar", (0.05, -0.02, 0.9), (0.3, 0.1, -2.0)),
    ("spherical", (0.3, -0.5, 0.8), (1.0, 2.0, -3.0)),
    ("universal", *universal_values()),
])
def test_multi_coordinate_joints_start_at_the_given_values(kind, x0, v0):
    model = one_joint(kind, x0, v0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", mb.InitialConditionWarning)
        res = mb.simulate(model, 0.01, 0.005)
    np.testing.assert_allclose(res.joint_coordinate("j")[0], x0, atol=1e-10)
    np.testing.assert_allclose(res.joint_velocity("j")[0], v0, atol=1e-10)


def test_readme_initial_conditions_example_matches_the_closed_form():
    import re
    from pathlib import Path
    text = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = text.split("## Initial conditions", 1)[1].split("\n## ", 1)[0]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    ns = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        exec(compile(code.replace("print(", "str("), "README.md", "exec"), ns)   # noqa: S102 - our own docs
    x, xd = slider_law(np.radians(60.0), 2 * np.pi)
    assert ns["x0"] == pytest.approx(x, abs=1e-10) and ns["v0"] == pytest.approx(xd, abs=1e-10)


def test_joint_initial_values_against_a_driver_are_changed_with_a_warning_naming_the_joint():
    model, rod = pendulum(iv=1.0)
    model.joints["pin"].initial_displacement = np.array([0.3])
    model.add_motion("drive", "pin", displacement="0.1 + 2*t")
    rep, warned = assembled(model)
    text = str(warned[0].message)
    assert "joint 'pin' initial_displacement given 0.3, used 0.1" in text
    assert "joint 'pin' initial_velocity given 1, used 2" in text
    assert rep.moved["rod"][1] == pytest.approx(0.1, abs=1e-12)       # turned to the driver's 0.1 rad
    assert rep.v[5] == pytest.approx(2.0, abs=1e-12)


def test_inconsistent_initial_velocity_on_a_dependent_joint_is_warned_with_the_change():
    """Issue 34: the crank driven at 2 pi rad/s, the slide (dependent on it) given 1 m/s: the fit keeps
    the driver and moves the slide's value to the slider-crank law, named with how much it moved."""
    th, w = np.radians(60.0), 2 * np.pi
    model, slider = slider_crank(th)
    model.add_motion("turn", "O", velocity=w)
    model.joints["slide"].initial_velocity = np.array([1.0])
    rep, warned = assembled(model)
    used = slider_law(th, w)[1]     # slide coordinate: the slider's x from as drawn, its rate dx/dt
    assert len(warned) == 1
    text = str(warned[0].message)
    assert "joint 'slide' initial_velocity given 1, used" in text and "joint 'O'" not in text
    import re
    change = re.search(r"joint 'slide' initial_velocity .*?\(changed by (\S+) m/s\)", text)
    assert change and float(change.group(1)) == pytest.approx(used - 1.0, abs=1e-8)
    assert rep.joint_changed["slide"]["initial_velocity"] == pytest.approx([used - 1.0], abs=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = mb.kinematics(model, 0.02, 0.01)
    assert res.joint_velocity("slide")[0] == pytest.approx(used, abs=1e-9)
    # crank and slide both given, inconsistent (free mechanism): both are moved and named with units
    model, _ = slider_crank(th, v0=w)
    model.joints["slide"].initial_velocity = np.array([1.0])
    rep, warned = assembled(model)
    text = str(warned[0].message)
    assert "joint 'O' initial_velocity given 6.28318531" in text and "rad/s)" in text
    assert "joint 'slide' initial_velocity given 1" in text and "m/s)" in text
    assert set(rep.joint_changed) == {"O", "slide"} and "changed by" in str(rep)

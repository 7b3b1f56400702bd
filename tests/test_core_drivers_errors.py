"""Core engine, must-show 6 (part 2): every driver type end to end, every error path and its message,
and the DataFrame export.

Drivers: displacement / velocity / acceleration, each as an expression string and as a callable (and a
constant), on revolute, translational and cylindrical joints; mb.kinematics must reproduce the
closed-form coordinate, rate and second derivative.
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb

T_END, STEP = 1.0, 0.05


# ----------------------------------------------------------------------------- drivers
def spinner(kind="revolute"):
    """A body on a joint to ground along z through the origin (body CM off the axis)."""
    model = mb.Model("spinner", gravity=(0.0, -9.81, 0.0))
    body = model.add_body("arm", 2.0, inertia=(0.01, 0.02, 0.03), position=(0.4, 0.1, 0.0))
    jt = getattr(model, f"add_{kind}")("j", model.ground, body, (0, 0, 0), (0, 0, 1))
    return model, body, jt


X0, V0 = 0.2, -0.4


def exact(how, t):
    """Closed form of the driven coordinate for the three driver kinds (same acceleration a(t))."""
    a = -2 * np.sin(2 * t) + 0.6                      # x'' for every case
    if how == "displacement":                          # x = 0.5 sin 2t + 0.3 t^2
        return 0.5 * np.sin(2 * t) + 0.3 * t**2, np.cos(2 * t) + 0.6 * t, a
    if how == "velocity":                              # x' = cos 2t + 0.6 t, x(0) = X0
        return X0 + 0.5 * np.sin(2 * t) + 0.3 * t**2, np.cos(2 * t) + 0.6 * t, a
    # x'' = a, x(0) = X0, x'(0) = V0: x = X0 + V0 t + 0.5 sin 2t - t + 0.3 t^2
    return X0 + V0 * t + 0.5 * np.sin(2 * t) - t + 0.3 * t**2, V0 + np.cos(2 * t) - 1 + 0.6 * t, a


SPECS = {
    ("displacement", "string"): "0.5*sin(2*t) + 0.3*t**2",
    ("displacement", "callable"): lambda t: 0.5 * np.sin(2 * t) + 0.3 * t**2,
    ("velocity", "string"): "cos(2*t) + 0.6*t",
    ("velocity", "callable"): lambda t: np.cos(2 * t) + 0.6 * t,
    ("acceleration", "string"): "-2*sin(2*t) + 0.6",
    ("acceleration", "callable"): lambda t: -2 * np.sin(2 * t) + 0.6,
}


@pytest.mark.parametrize("kind", ["revolute", "translational"])
@pytest.mark.parametrize("how,form", sorted(SPECS))
def test_driver_kinds_reproduce_closed_form(kind, how, form):
    model, body, jt = spinner(kind)
    model.add_motion("m", jt, initial_displacement=X0, initial_velocity=V0, **{how: SPECS[how, form]})
    res = mb.kinematics(model, T_END, STEP)
    assert res.success, res.message
    x, xd, xdd = exact(how, res.time)
    tol = 1e-9 if form == "string" or how == "displacement" else 1e-8   # callables: numeric integration
    assert np.allclose(res.joint_coordinate(jt), x, rtol=0, atol=tol)
    assert np.allclose(res.joint_velocity(jt), xd, rtol=0, atol=tol)
    assert np.allclose(res.joint_acceleration(jt), xdd, rtol=0, atol=1e-7)
    if kind == "revolute":          # the body turns about z by x(t): its angular velocity is (0, 0, x')
        assert np.allclose(res.angular_velocity(body), np.stack([0 * x, 0 * x, xd], -1), atol=tol)
        c, s = np.cos(x), np.sin(x)
        p0 = np.array([0.4, 0.1])
        assert np.allclose(res.position(body)[:, :2], np.stack([c * p0[0] - s * p0[1], s * p0[0] + c * p0[1]], -1),
                           atol=tol)
    else:                           # the body slides along z by x(t)
        assert np.allclose(res.position(body), np.stack([0 * x + 0.4, 0 * x + 0.1, x], -1), atol=tol)
        assert np.allclose(res.acceleration(body)[:, 2], xdd, atol=1e-7)


def test_constant_velocity_driver_and_cylindrical_two_motions():
    model, body, jt = spinner("cylindrical")
    model.add_motion("spin", jt, velocity=3.0, dof="rotation")                 # a number is a constant
    model.add_motion("lift", jt, displacement="0.1*t", dof="translation")
    res = mb.kinematics(model, T_END, STEP)
    assert res.success, res.message
    xy = res.joint_coordinate(jt)
    assert xy.shape == (len(res.time), 2)
    assert np.allclose(xy, np.stack([3 * res.time, 0.1 * res.time], -1), atol=1e-9)
    assert np.allclose(res.joint_velocity(jt), np.broadcast_to([3.0, 0.1], xy.shape), atol=1e-9)
    assert np.allclose(res.joint_acceleration(jt), 0.0, atol=1e-9)
    # over 3 s the angle passes pi and 2 pi: the joint coordinate is unwrapped
    res = mb.kinematics(model, 3.0, 0.1)
    assert np.allclose(res.joint_coordinate(jt)[:, 0], 3 * res.time, atol=1e-9)


def test_driven_angle_beyond_pi_between_samples():
    """Large output step: the driver target wraps, the solver must follow the continuous branch."""
    model, body, jt = spinner()
    model.add_motion("m", jt, displacement="10*t")
    res = mb.kinematics(model, 2.0, 0.25)
    assert np.allclose(res.joint_coordinate(jt), 10 * res.time, atol=1e-9)


# ----------------------------------------------------------------------------- model input errors
def err(excinfo):
    return str(excinfo.value)


def test_bad_inputs_name_entity_and_field():
    m = mb.Model("e")
    cases = [
        (lambda: m.add_body("b", mass=-1.0), "body 'b'", "mass", "must be >= 0"),
        (lambda: m.add_particle("p", mass=0.0), "particle 'p'", "mass", "must be > 0"),
        (lambda: m.add_body("b", 1.0, inertia=(1, 2)), "body 'b'", "inertia", "expected 3 numbers"),
        (lambda: m.add_body("b", 1.0, inertia=[[1, 2, 0], [0, 1, 0], [0, 0, 1]]), "body 'b'", "inertia",
         "symmetric"),
        (lambda: m.add_body("b", 1.0, inertia=(1, -2, 1)), "body 'b'", "inertia", "positive semi-definite"),
        (lambda: m.add_body("b", 1.0, position=(0, np.nan, 0)), "body 'b'", "position", "finite"),
        (lambda: m.add_body("b", 1.0, orientation=np.diag([1, 1, -1.0])), "body 'b'", "orientation",
         "proper rotation"),
        (lambda: m.add_body("b", "heavy"), "body 'b'", "mass", "expected a number"),
        (lambda: mb.Model("g", gravity=(0, 1)), "model 'g'", "gravity", "expected 3 numbers"),
    ]
    for make, entity, field, text in cases:
        with pytest.raises(mb.ModelError) as ei:
            make()
        assert (ei.value.entity, ei.value.field) == (entity, field)
        assert err(ei).startswith(f"{entity}.{field}: ") and text in err(ei), err(ei)
    assert list(m.bodies) == ["ground"]          # failed adds leave nothing behind


def test_joint_and_load_input_errors():
    m = mb.Model("e")
    b = m.add_body("b", 1.0, inertia=(1, 1, 1), position=(1, 0, 0))
    other = mb.Model("other").add_body("x", 1.0)
    cases = [
        (lambda: m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 0)), "joint 'j'", "axis", "non-zero"),
        (lambda: m.add_revolute("j", m.ground, b, (0, 0), (0, 0, 1)), "joint 'j'", "point", "3 numbers"),
        (lambda: m.add_revolute("j", "nobody", b, (0, 0, 0), (0, 0, 1)), "joint 'j'", "body_i",
         "no body_i named 'nobody'"),
        (lambda: m.add_revolute("j", m.ground, other, (0, 0, 0), (0, 0, 1)), "joint 'j'", "body_j",
         "not part of this model"),
        (lambda: m.add_revolute("j", b, b, (0, 0, 0), (0, 0, 1)), "joint 'j'", "body_j", "two different bodies"),
        (lambda: m.add_universal("j", m.ground, b, (0, 0, 0), (0, 0, 1), (0, 1, 1)), "joint 'j'", "axis_j",
         "perpendicular"),
        (lambda: m.add_force("f", (b, (0, 0, 0)), (1, 2)), "force 'f'", "force", "3 numbers"),
        (lambda: m.add_force("f", 3.0, (1, 2, 3)), "force 'f'", "at", "Marker, a body (its centre of mass) or (body, point)"),
        (lambda: m.add_torque("tq", "nobody", (1, 2, 3)), "torque 'tq'", "body", "no body named"),
        (lambda: m.add_spring_damper("s", (b, (1, 0, 0)), (m.ground, (0, 0, 0)), -5.0), "spring 's'",
         "stiffness", ">= 0"),
        (lambda: b.add_marker("mk", point=(1, 2)), "marker 'b.mk'", "point", "3 numbers"),
    ]
    for make, entity, field, text in cases:
        with pytest.raises(mb.ModelError) as ei:
            make()
        assert (ei.value.entity, ei.value.field) == (entity, field), err(ei)
        assert text in err(ei), err(ei)
    assert not m.joints and not m.forces
    m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))   # the names were not claimed by the failures


def test_duplicate_names():
    m = mb.Model("e")
    b = m.add_body("b", 1.0)
    m.add_revolute("j", m.ground, b, (0, 0, 0), (0, 0, 1))
    b.add_marker("tip", (1, 0, 0))
    for make, entity in ((lambda: m.add_body("b", 1.0), "body 'b'"),
                         (lambda: m.add_particle("j", 1.0), "particle 'j'"),
                         (lambda: m.add_spherical("b", m.ground, b, (0, 0, 0)), "joint 'b'"),
                         (lambda: m.add_motion("j", "j", displacement="t"), "motion 'j'"),
                         (lambda: m.add_body("ground", 1.0), "body 'ground'")):
        with pytest.raises(mb.ModelError, match="already exists") as ei:
            make()
        assert (ei.value.entity, ei.value.field) == (entity, "name")
    with pytest.raises(mb.ModelError, match="marker 'b.tip'.name: a marker of this name already exists"):
        b.add_marker("tip", (2, 0, 0))
    with pytest.raises(mb.ModelError, match="must be a non-empty string"):
        m.add_body("", 1.0)


def test_motion_errors():
    m, body, jt = spinner()
    sph = m.add_spherical("ball", m.ground, m.add_body("c", 1.0, inertia=(1, 1, 1)), (0, 0, 0))
    cases = [
        (dict(joint="nojoint", displacement="t"), "joint", "no joint named 'nojoint'"),
        (dict(joint=sph, displacement="t"), "joint", "cannot drive a spherical joint"),
        (dict(joint=jt, displacement="t", velocity="1"), "displacement", "exactly one"),
        (dict(joint=jt), "displacement", "exactly one"),
        (dict(joint=jt, displacement="t", dof="translation"), "dof", "'translation' is not a coordinate"),
        (dict(joint=jt, displacement="__import__('os').getcwd()"), "displacement", "__import__"),
        (dict(joint=jt, displacement="t + x"), "displacement", "x"),
        (dict(joint=jt, velocity="sin(t"), "velocity", ""),
        (dict(joint=jt, acceleration=lambda t: "abc"), "acceleration", ""),
        (dict(joint=jt, velocity="t", initial_displacement="zero"), "initial_displacement", "expected a number"),
    ]
    for kwargs, field, text in cases:
        with pytest.raises(mb.ModelError) as ei:
            m.add_motion("mo", **kwargs)
        assert (ei.value.entity, ei.value.field) == ("motion 'mo'", field), err(ei)
        assert text in err(ei), err(ei)
    assert not m.motions
    m.add_motion("mo", jt, displacement="t")


def test_particle_orientation_errors_at_analysis():
    m = mb.Model("e")
    p = m.add_particle("p", 1.0, position=(1, 0, 0))
    b = m.add_body("b", 1.0, inertia=(1, 1, 1))
    m.add_revolute("r", p, b, (1, 0, 0), (0, 0, 1))
    with pytest.raises(mb.ModelError, match="joint 'r'.body_i: a particle must be body_j"):
        mb.assemble(m)
    m = mb.Model("e")
    p = m.add_particle("p", 1.0, position=(1, 0, 0))
    jt = m.add_revolute("r", m.ground, p, (0, 0, 0), (0, 0, 1))
    m.add_motion("spin", jt, displacement="t")
    with pytest.raises(mb.ModelError, match="motion 'spin'.joint: cannot drive a rotation of a particle"):
        mb.kinematics(m, 1.0, 0.1)


def test_analysis_argument_errors():
    m, body, jt = spinner()
    with pytest.raises(mb.ModelError, match="simulate.method: unknown method 'euler'"):
        mb.simulate(m, 1.0, method="euler")
    with pytest.raises(mb.ModelError, match="analysis.end_time: must be greater than the start time"):
        mb.simulate(m, 0.0, method="dop853")
    with pytest.raises(mb.ModelError, match="analysis.output_step: must be positive"):
        mb.simulate(m, 1.0, output_step=-0.1, method="dop853")
    with pytest.raises(mb.ModelError, match="model 'spinner'.motions: .*1 DOF remain free"):
        mb.kinematics(m, 1.0, 0.1)
    res = mb.simulate(m, 0.1, 0.05, method="dop853")
    with pytest.raises(mb.ModelError, match="joint 'nojoint'.joint: is not a joint of the analysed model"):
        res.joint_coordinate("nojoint")
    with pytest.raises(mb.ModelError):
        res.reaction_force("nojoint")
    with pytest.raises(mb.ModelError, match="spring"):
        res.spring_length("nospring")
    with pytest.raises(ValueError, match="outside the result's range"):
        res.at(0.2)


def test_bad_force_callable_stops_the_run_naming_the_force():
    m, body, jt = spinner()
    m.add_force("push", (body, (0.4, 0.1, 0.0)), lambda t, s: (1.0, 2.0) if t > 0.05 else (0.0, 0.0, 0.0))
    res = mb.simulate(m, 0.2, 0.01, method="dop853")
    assert not res.success and res.status != 0
    assert "force 'push'.force: callable returned" in res.message
    assert 0 < len(res.time) and res.time[-1] <= 0.05 + 1e-12


# ----------------------------------------------------------------------------- lock-up, impossible drivers
R, L = 0.3, 0.2          # crank longer than the rod: the crank locks at sin(theta) = L / R


def short_rod_slider_crank(drive="t"):
    m = mb.Model("lock", gravity=(0.0, -9.81, 0.0))
    crank = m.add_body("crank", 1.0, inertia=(1e-3, 1e-2, 1e-2), position=(R / 2, 0, 0))
    rod = m.add_body("rod", 1.0, inertia=(1e-3, 1e-2, 1e-2), position=(R + L / 2, 0, 0))
    slider = m.add_body("slider", 1.0, inertia=(1e-3, 1e-3, 1e-3), position=(R + L, 0, 0))
    o = m.add_revolute("O", m.ground, crank, (0, 0, 0), (0, 0, 1))
    m.add_spherical("A", crank, rod, (R, 0, 0))
    m.add_universal("B", rod, slider, (R + L, 0, 0), (0, 0, 1), (0, 1, 0))
    m.add_translational("slide", m.ground, slider, (R + L, 0, 0), (1, 0, 0))
    m.add_motion("drive", o, displacement=drive)
    return m, slider


def test_kinematic_lockup_names_time_joints_and_keeps_the_steps_before():
    m, slider = short_rod_slider_crank("t")
    t_lock = np.arcsin(L / R)
    res = mb.kinematics(m, 1.5, 0.01)
    assert not res.success and res.status == -1
    assert res.time[-1] < t_lock < res.time[-1] + 0.01 + 1e-12          # every good step is kept
    th = res.time
    x = R * np.cos(th) + np.sqrt(L**2 - (R * np.sin(th)) ** 2)
    assert np.allclose(res.position(slider)[:, 0], x, atol=1e-9)
    msg = res.message
    assert "lock-up or impossible motion" in msg
    assert f"at t = {res.time[-1] + 0.01:.9g} s" in msg
    assert "joints involved:" in msg and ("A" in msg.split("joints involved:")[1])
    assert f"last good state at t = {res.time[-1]:.9g} s" in msg
    e = res.error
    assert isinstance(e, mb.AssemblyError) and e.time == pytest.approx(res.time[-1] + 0.01)
    assert set(e.joints) <= {"O", "A", "B", "slide", "drive"} and e.joints and e.state is not None


def test_impossible_driver_at_assembly_raises_naming_joints():
    m, _ = short_rod_slider_crank("2")      # 2 rad beyond the lock angle already at t = 0
    with pytest.raises(mb.AssemblyError) as ei:
        mb.kinematics(m, 1.0, 0.1)
    assert "assembly failed" in err(ei) and "at t = 0 s" in err(ei) and "joints involved:" in err(ei)
    assert ei.value.time == 0.0 and ei.value.joints and ei.value.state is not None
    with pytest.raises(mb.AssemblyError, match="assembly failed"):
        mb.assemble(m)


@pytest.mark.parametrize("method", ["rk45", "dop853"])
def test_dynamic_lockup_stops_with_error_naming_time_and_joints(method):
    """A driven crank in a dynamic run: the equations of motion become singular at the lock angle."""
    m, slider = short_rod_slider_crank("8*t")
    t_lock = np.arcsin(L / R) / 8
    res = mb.simulate(m, 0.2, 0.01, method=method)
    assert not res.success
    assert res.time[-1] < t_lock and len(res.time) == int(t_lock / 0.01) + 1
    assert isinstance(res.error, mb.SolverError)
    assert res.error.time == pytest.approx(t_lock, abs=1e-6)
    assert f"at t = {res.error.time:.9g} s" in res.message and "joints involved:" in res.message
    assert set(res.error.joints) & {"O", "A", "B", "slide", "drive"}


def test_redundant_warning_names_the_joints_once():
    """A shaft on two coaxial revolute bearings: 10 equations, 5 coordinates fixed, 5 dependent."""
    m = mb.Model("shaft", gravity=(0, -9.81, 0))
    shaft = m.add_body("shaft", 1.0, inertia=(0.1, 0.01, 0.1), position=(0, 0.5, 0))
    m.add_revolute("bearing_1", m.ground, shaft, (0, 0, 0), (0, 1, 0))
    m.add_revolute("bearing_2", m.ground, shaft, (0, 1, 0), (0, 1, 0))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rep = mb.assemble(m)
    red = [w for w in caught if issubclass(w.category, mb.RedundantConstraintWarning)]
    assert len(red) == 1
    assert "joints involved: bearing_1, bearing_2" in str(red[0].message) or \
        "joints involved: bearing_2, bearing_1" in str(red[0].message)
    assert "5 of 10 equations are dependent" in str(red[0].message)
    assert rep.dof == 1 and set(rep.redundant) == {"bearing_1", "bearing_2"}


# ----------------------------------------------------------------------------- export
def test_to_dataframe_columns_and_values():
    model, body, jt = spinner()
    p = model.add_particle("ball", 1.0, position=(0, 1, 0), velocity=(1, 0, 0))
    model.add_motion("m", jt, displacement="2*t")
    res = mb.simulate(model, 0.5, 0.1, method="dop853")
    df = res.to_dataframe()
    assert list(df.columns[:1]) == ["time [s]"] and len(df) == len(res.time)
    for c in ("arm.x [m]", "arm.vz [m/s]", "arm.wz [rad/s]", "ball.y [m]", "ball.vx [m/s]",
              "j.angle [rad]", "j.angle_rate [rad/s]"):
        assert c in df.columns, c
    assert "ball.wx [rad/s]" not in df.columns
    assert np.allclose(df["j.angle [rad]"], 2 * res.time) and np.allclose(df["arm.wz [rad/s]"], 2.0)
    assert np.allclose(df["arm.x [m]"], res.position(body)[:, 0])
    assert np.allclose(df["ball.y [m]"], 1.0 - 0.5 * 9.81 * res.time**2, atol=1e-9)
    assert np.allclose(df["ball.vx [m/s]"], 1.0, atol=1e-9)

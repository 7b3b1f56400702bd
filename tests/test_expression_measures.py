"""Measures of load expressions (issue 14): derivatives of one another by finite differences, Adams
angle conventions, compiled kernel = numpy reference, error messages, model-file round trip."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.errors import ModelError
from mbdsim.model.loadexpr import MEASURE_KIND, parse_load


def _tumbling():
    m = mb.Model(gravity=(0, 0, -9.81))
    a = m.add_body("a", mass=1.0, inertia=(0.1, 0.2, 0.3), position=(0.2, 0.1, 0.5),
                   velocity=(0.3, -0.2, 1.0), angular_velocity=(1.0, 2.0, -0.5))
    b = m.add_body("b", mass=2.0, inertia=(0.3, 0.2, 0.25), position=(-0.4, 0.3, 0.1),
                   orientation=Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(),
                   velocity=(-0.1, 0.4, 0.8), angular_velocity=(-0.7, 0.4, 1.5))
    a.add_marker("p", (0.3, 0.2, 0.4), Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix())
    b.add_marker("q", (-0.5, 0.1, 0.2), Rotation.from_rotvec([-0.4, 0.1, 0.2]).as_matrix())
    return m


@pytest.fixture(scope="module")
def tumbling():
    h = 1e-4
    return mb.simulate(_tumbling(), 0.05, output_step=h, rtol=1e-12), h


@pytest.mark.parametrize("pos,vel", [("DX(a.p, b.q)", "VX(a.p, b.q)"), ("DY(a.p, b)", "VY(a.p, b)"),
                                     ("DZ(a.p)", "VZ(a.p)"), ("DM(a.p, b.q)", "VR(a.p, b.q)"),
                                     ("VX(a.p, b.q)", "ACCX(a.p, b.q)"), ("VZ(b.q, a, a.p)", None),
                                     ("AZ(a.p, b.q)", None)])
def test_measures_are_derivatives_of_one_another(tumbling, pos, vel):
    """Central differences of the position measures (ground components) give the velocity measures;
    those of the velocities the accelerations; a component in moving axes k, and the AX..AZ angles, are
    checked against their own definition below."""
    res, h = tumbling
    x = res.expression(pos)
    if vel is None:
        return
    fd = (x[2:] - x[:-2]) / (2 * h)
    v = res.expression(vel)[1:-1]
    assert np.abs(fd - v).max() < 1e-6 * max(1.0, np.abs(v).max())


def test_measures_against_their_definitions(tumbling):
    res = tumbling[0]
    pa, va = res.position("a.p"), res.velocity("a.p")
    pb, vb = res.position("b.q"), res.velocity("b.q")
    Rq = res.orientation("b.q")
    Rp = res.orientation("a.p")
    d, dv = pa - pb, va - vb
    np.testing.assert_allclose(res.expression("DX(a.p, b.q, b.q)"), np.einsum("ni,ni->n", Rq[:, :, 0], d), atol=1e-13)
    np.testing.assert_allclose(res.expression("VY(a.p, b.q, b.q)"), np.einsum("ni,ni->n", Rq[:, :, 1], dv), atol=1e-13)
    np.testing.assert_allclose(res.expression("VM(a.p, b.q)"), np.linalg.norm(dv, axis=1), atol=1e-13)
    dw = res.angular_velocity("a") - res.angular_velocity("b")
    np.testing.assert_allclose(res.expression("WZ(a, b, b.q)"), np.einsum("ni,ni->n", Rq[:, :, 2], dw), atol=1e-12)
    np.testing.assert_allclose(res.expression("WM(a, b)"), np.linalg.norm(dw, axis=1), atol=1e-12)
    acc = res.acceleration("a.p") - res.acceleration("b.q")
    np.testing.assert_allclose(res.expression("ACCZ(a.p, b.q)"), acc[:, 2], atol=1e-10)
    # Adams AX/AY/AZ: atan2(-zi.yj, zi.zj), atan2(zi.xj, zi.zj), atan2(xi.yj, xi.xj)
    dot = lambda u, v: np.einsum("ni,ni->n", Rp[:, :, u], Rq[:, :, v])  # noqa: E731
    np.testing.assert_allclose(res.expression("AX(a.p, b.q)"), np.arctan2(-dot(2, 1), dot(2, 2)), atol=1e-13)
    np.testing.assert_allclose(res.expression("AY(a.p, b.q)"), np.arctan2(dot(2, 0), dot(2, 2)), atol=1e-13)
    np.testing.assert_allclose(res.expression("AZ(a.p, b.q)"), np.arctan2(dot(0, 1), dot(0, 0)), atol=1e-13)


@pytest.mark.parametrize("axis,name", [(0, "AX"), (1, "AY"), (2, "AZ")])
def test_adams_angles_of_a_single_rotation(axis, name):
    """A marker rotated by a about one axis of another: that angle measure is a (|a| < pi)."""
    m = mb.Model()
    for a in (-2.5, -0.7, 0.4, 3.0):
        rv = np.zeros(3)
        rv[axis] = a
        name_b = f"b{len(m.bodies)}"
        m.add_body(name_b, mass=1.0, inertia=(1, 1, 1), orientation=Rotation.from_rotvec(rv).as_matrix())
        m.add_fixed(f"f{name_b}", "ground", name_b)
        res = mb.simulate(m, 0.01, output_step=0.01)
        assert res.expression(f"{name}({name_b})")[0] == pytest.approx(a, abs=1e-12)


def test_compiled_measures_equal_numpy():
    """The numba kernel's measures equal the numpy reference at random states, every kind."""
    from mbdsim.model.loadexpr import Measure
    from mbdsim.system.assemble import assemble_system
    from mbdsim.system.exprloads_kernel import measure
    from mbdsim.system.exprmeasures import measure_values
    from mbdsim.system.exprloads_pack import _measure_row
    from mbdsim.system.frames import body_frames, Frames
    m = _tumbling()
    sys = assemble_system(m)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = sys.q0 + 0.3 * rng.standard_normal(sys.nq)
        v = rng.standard_normal(sys.nv)
        fr = body_frames(sys, q, v)
        fb = Frames(fr.r[None], fr.A[None], fr.rd[None], fr.w[None])
        for name, kind in MEASURE_KIND.items():
            if kind >= 16:
                continue
            for args in (("a.p", "b.q", "b"), ("b", None, "a.p"), ("a", "b.q", None)):
                ms = Measure(name, *args)
                row = _measure_row(sys, ms, 0, None, None)
                got = measure(row[0], *row[1], row[2][0], row[2][1], row[3][0], row[3][1], row[3][2], row[4],
                              fr.r, fr.A, fr.rd, fr.w)
                assert got == pytest.approx(measure_values(sys, fb, ms)[0], abs=1e-12), (name, args)


# ----------------------------------------------------------------------------- errors
@pytest.mark.parametrize("text,words", [
    ("WZZ(disk)", ["function not allowed", "WZ", "DM", "ACCX"]),
    ("WZ(dsk)", ["no body or body.marker named 'dsk'", "disk", "ground"]),
    ("DM(disk.tp, ground)", ["has no marker 'tp'", "tip"]),
    ("-2*pni_dot", ["unknown name", "pin_dot"]),
    ("DX(disk, ground, disk, disk)", ["DX takes 1 to 3 arguments"]),
    ("DM(disk, ground, disk)", ["DM takes 1 to 2 arguments"]),
    ("ACCZ(disk)", ["ACCZ depends on the accelerations", "algebraic loop"]),
    ("WZ(1+disk)", ["arguments of WZ name a body"]),
    ("__import__('os').system('ls')", ["not allowed"]),
])
def test_misspelt_names_are_errors_listing_valid_ones(text, words):
    m = mb.Model()
    b = m.add_body("disk", mass=1.0, inertia=(1, 1, 1))
    b.add_marker("tip", (1, 0, 0))
    m.add_revolute("pin", "ground", "disk", (0, 0, 0), (0, 0, 1))
    with pytest.raises(ModelError) as exc:
        m.add_torque("motor", "disk", [0, 0, text])
    msg = str(exc.value)
    assert "torque 'motor'" in msg and "torque[2]" in msg
    for w in words:
        assert w in msg
    assert "motor" not in m.forces
    with pytest.raises(ModelError, match="line force 'lf'.magnitude"):
        m.add_line_force("lf", b.markers["tip"], m.ground, text)
    with pytest.raises(ModelError, match="joint force 'jf'.value"):
        m.add_joint_force("jf", "pin", text)


def test_joint_force_input_errors():
    m = mb.Model()
    m.add_body("a", mass=1.0, inertia=(1, 1, 1))
    m.add_spherical("s", "ground", "a", (0, 0, 0))
    with pytest.raises(ModelError, match="joint force 'j'.joint: a spherical joint has no single axis"):
        m.add_joint_force("j", "s", 1.0)
    m.add_body("c", mass=1.0, inertia=(1, 1, 1))
    m.add_revolute("r", "ground", "c", (0, 0, 0), (0, 0, 1))
    with pytest.raises(ModelError, match="'translation' is not a coordinate of revolute joint"):
        m.add_joint_force("j", "r", 1.0, dof="translation")
    with pytest.raises(ModelError, match="joint force 'j'.joint: no joint named 'rr'"):
        m.add_joint_force("j", "rr", 1.0)


def test_expression_parse_keeps_measure_texts():
    m = _tumbling()
    le = parse_load(m, "k_*DM(a.p, b.q)".replace("k_", "3") + " + STEP(TIME, 0, 0, 1, 2)", "load 'x'", "value")
    assert set(le.measures) == {"DM(a.p, b.q)"}
    assert le.text.startswith("3*DM(a.p, b.q)")
    d = le.expr.derivative("DM(a.p, b.q)")
    assert d.text == "3"


# ----------------------------------------------------------------------------- model files
def _file_model():
    m = mb.Model(gravity=(0, -9.81, 0))
    rod = m.add_body("rod", mass=1.0, inertia=(0.01, 0.1, 0.1), position=(0.5, 0, 0))
    rod.add_marker("tip", (1.0, 0, 0))
    base = m.add_body("base", mass=1.0, inertia=(1, 1, 1), position=(1.2, 0.3, 0))
    base.add_marker("anchor", (1.2, 0.3, 0))
    m.add_fixed("weld", "ground", "base", (1.2, 0.3, 0))
    m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
    m.add_torque("drag", "rod", [0, 0, "-0.2*WZ(rod)"])
    m.add_force("push", rod.markers["tip"], ["STEP(TIME, 0, 0, 0.5, 2)", 0.0, "-0.5*VY(rod.tip)"], frame=rod)
    m.add_line_force("cable", rod.markers["tip"], base.markers["anchor"],
                     "30*(DM(rod.tip, base.anchor) - 0.4) + 0.5*VR(rod.tip, base.anchor)")
    m.add_joint_force("motor", "pin", "1.5*(1 - pin_dot/4) - 0.1*pin")
    return m


@pytest.mark.parametrize("ext", ["yaml", "json"])
def test_expression_loads_round_trip_through_model_files(tmp_path, ext):
    m = _file_model()
    path = mb.save_model(m, tmp_path / f"m.{ext}")
    text = path.read_text()
    assert "DM(rod.tip, base.anchor)" in text and "pin_dot" in text
    m2 = mb.load_model(path)
    from mbdsim.io.dump import model_to_dict
    assert model_to_dict(m2) == model_to_dict(m)
    r1 = mb.simulate(m, 1.0, output_step=0.1, rtol=1e-10)
    r2 = mb.simulate(m2, 1.0, output_step=0.1, rtol=1e-10)
    assert np.abs(r1.joint_coordinate("pin")).max() > 0.1
    np.testing.assert_array_equal(r1.joint_coordinate("pin"), r2.joint_coordinate("pin"))


def test_model_file_expression_never_runs_code(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("bodies:\n- {name: a, mass: 1, inertia: [1, 1, 1]}\n"
                 "forces:\n- {type: force, name: f, at: a, force: [\"__import__('os').system('echo hacked')\", 0, 0]}\n")
    with pytest.raises(ModelError, match="not allowed"):
        mb.load_model(p)
    p.write_text("bodies:\n- {name: a, mass: 1, inertia: [1, 1, 1]}\n"
                 "forces:\n- {type: line_force, name: f, at_i: a, at_j: ground, magnitude: \"3 kN\"}\n")
    m = mb.load_model(p)
    assert m.forces["f"].magnitude == 3000.0


def test_callables_still_run_and_refuse_model_files(tmp_path):
    m = mb.Model()
    m.add_body("disk", mass=1.0, inertia=(1.0, 1.0, I := 2.0))
    m.add_revolute("pin", "ground", "disk", (0, 0, 0), (0, 0, 1))
    m.add_line_force("lf", ("disk", (1, 0, 0)), ("ground", (1, 1, 0)), lambda t, s: 0.0)
    m.add_joint_force("motor", "pin", lambda t, s: 2.0)
    res = mb.simulate(m, 1.0, output_step=0.5)
    assert res.joint_velocity("pin")[-1] == pytest.approx(2.0 / I, rel=1e-8)
    with pytest.raises(ModelError, match="callable"):
        mb.save_model(m, tmp_path / "x.yaml")


def test_sensor_on_a_measure_meets_the_drop_time():
    """A sensor on DZ(ball, ground) - R (the gap) stops a free fall from h at t = sqrt(2 (h - R) / g)."""
    m = mb.Model(gravity=(0, 0, -9.81))
    m.add_body("ball", mass=1.0, inertia=(1, 1, 1), position=(0.3, 0, 1.0))
    m.add_sensor("floor", "DZ(ball, ground) - 0.1", 0.0, direction=-1)
    res = mb.simulate(m, 1.0, output_step=0.01)
    assert res.sensor_events[0].time == pytest.approx(np.sqrt(2 * 0.9 / 9.81), abs=1e-10)
    with pytest.raises(ModelError, match="sensor 'x'.signal.*no body or body.marker named 'bal'"):
        m.add_sensor("x", "DZ(bal)")

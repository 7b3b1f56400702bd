"""Joint primitives (Adams JPRIM), screw and constant-velocity joints (issue 11).

- phi_q, nu, gamma of each new joint kind against finite differences (the numpy reference and the
  dispatching implementation), for rigid, ground and particle bodies;
- each primitive leaves exactly its relative freedoms (kinematic null space, assembly DOF);
- primitives are built from compiled row kinds: method="auto" (compiled core) agrees with the reference
  DOP853 path, and a body on an inclined inline + orientation pair slides as the closed form says;
- marker-pair form; errors name the joint and the field.
"""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelError
from mbdsim.model.joints import JOINT_DOF
from mbdsim.system import assemble_system, equations
from test_core_jacobians import AXIS, POINT, check_equations, make_body

AXIS_J = np.cross(AXIS, [0.0, 0.0, 1.0])
AXIS_J /= np.linalg.norm(AXIS_J)
PRIMS = ["inline", "inplane", "orientation", "parallel_axes", "perpendicular", "atpoint"]
NEW = PRIMS + ["screw", "constant_velocity"]
ROWS = {"inline": 2, "inplane": 1, "orientation": 3, "parallel_axes": 2, "perpendicular": 1, "atpoint": 3,
        "screw": 5, "constant_velocity": 4}
CV_AXIS_J = np.array([0.0, 0.6, 0.8])


def add(model, kind, bi, bj, name="j"):
    if kind in ("inline",):
        return model.add_inline(name, bi, bj, POINT, AXIS)
    if kind == "inplane":
        return model.add_inplane(name, bi, bj, POINT, normal=AXIS)
    if kind == "orientation":
        return model.add_orientation(name, bi, bj)
    if kind == "parallel_axes":
        return model.add_parallel_axes(name, bi, bj, AXIS)
    if kind == "perpendicular":
        return model.add_perpendicular(name, bi, bj, AXIS, AXIS_J)
    if kind == "atpoint":
        return model.add_atpoint(name, bi, bj, POINT)
    if kind == "screw":
        return model.add_screw(name, bi, bj, POINT, AXIS, lead=0.05)
    return model.add_constant_velocity(name, bi, bj, POINT, AXIS, CV_AXIS_J)


def build(kind, pair):
    model = mb.Model("prim")
    names = pair.split("-")
    bodies = [model.ground if n == "ground" else make_body(model, f"b{k}", n == "particle", 20 + k)
              for k, n in enumerate(names)]
    return model, add(model, kind, *bodies)


CASES = ([(k, p) for k in NEW for p in ("rigid-rigid", "ground-rigid", "rigid-ground")]
         + [(k, "rigid-particle") for k in ("inline", "inplane", "atpoint")]
         + [("atpoint", "particle-particle"), ("atpoint", "particle-rigid")])


@pytest.mark.parametrize("impl", ["dispatch", "numpy"])
@pytest.mark.parametrize("kind,pair", CASES)
def test_jacobian_nu_gamma_against_finite_differences(kind, pair, impl):
    model, _ = build(kind, pair)
    sys = check_equations(model, impl=impl)
    assert sys.nc == ROWS[kind]
    phi0 = equations.constraint_terms(sys, sys.q0, sys.v0, 0.0)[0]
    assert np.abs(phi0).max() < 1e-12   # satisfied as built


def test_screw_jacobian_past_half_turns():
    """The screw row is single-valued over many turns: FD check after 7.3 turns of body_j."""
    from mbdsim.solvers.common import increment
    from scipy.spatial.transform import Rotation
    model = mb.Model("screw")
    model.add_body("b1", 1.0, inertia=(0.1, 0.2, 0.3), position=POINT + 0.2 * AXIS,
                   orientation=Rotation.from_rotvec([0.3, -0.2, 0.5]))   # CM on the axis
    add(model, "screw", "ground", "b1")
    sys = assemble_system(model)
    h = model.bodies["b1"].orientation.T @ AXIS
    dx = np.zeros(sys.nv)
    dx[3:6] = 7.3 * 2 * np.pi * h
    dx[0:3] = 7.3 * 0.05 * AXIS
    q = increment(sys, sys.q0, dx)
    phi, J, _, _ = equations.constraint_terms(sys, q, np.zeros(sys.nv), 0.0)
    assert np.abs(phi).max() < 1e-9
    for k in range(sys.nv):
        e = 1e-6 * np.eye(sys.nv)[k]
        d = (equations.constraint_terms(sys, increment(sys, q, e), np.zeros(sys.nv), 0.0)[0]
             - equations.constraint_terms(sys, increment(sys, q, -e), np.zeros(sys.nv), 0.0)[0]) / 2e-6
        assert np.allclose(d, J[:, k], atol=1e-7)


def twists(kind):
    """Relative motions (w, v_P) of body j (ground axes, P the joint point) each kind allows."""
    eye, z = np.eye(3), np.zeros(3)
    f = np.cross(AXIS, eye[0]); f /= np.linalg.norm(f)
    g = np.cross(AXIS, f)
    return {"inline": [(eye[k], z) for k in range(3)] + [(z, AXIS)],
            "inplane": [(eye[k], z) for k in range(3)] + [(z, f), (z, g)],
            "orientation": [(z, eye[k]) for k in range(3)],
            "parallel_axes": [(AXIS, z)] + [(z, eye[k]) for k in range(3)],
            "perpendicular": [(z, eye[k]) for k in range(3)] + [(AXIS, z), (AXIS_J, z)],
            "atpoint": [(eye[k], z) for k in range(3)],
            "screw": [(AXIS, 0.05 / (2 * np.pi) * AXIS)]}[kind]


@pytest.mark.parametrize("kind", PRIMS + ["screw"])
def test_each_kind_leaves_exactly_its_freedoms(kind):
    model, jt = build(kind, "ground-rigid")
    sys = assemble_system(model)
    J = equations.constraint_terms(sys, sys.q0, sys.v0, 0.0)[1]
    body = jt.body_j
    for w, vP in twists(kind):
        v = np.concatenate([vP + np.cross(w, body.position - POINT), body.orientation.T @ w])
        assert np.abs(J @ v).max() < 1e-12, (kind, w, vP)
    assert np.linalg.matrix_rank(J, tol=1e-9) == 6 - JOINT_DOF[kind] == 6 - mb.assemble(model).dof
    assert len(twists(kind)) == JOINT_DOF[kind]


def _slider(with_markers=False):
    """A block on an inclined line (inline + orientation = a translational joint), gravity -z."""
    m = mb.Model("incline", gravity=(0, 0, -9.81))
    d = np.array([1.0, 0.0, 1.0]) / np.sqrt(2)
    b = m.add_body("block", 2.0, inertia=(0.1, 0.2, 0.3), position=(0.3, 0.0, 0.3))
    if with_markers:
        mi = m.ground.add_marker("line", (0, 0, 0), _frame_z(d))
        mj = b.add_marker("slot", (0.3, 0, 0.3), _frame_z(d))
        m.add_inline("line", mi, mj)
        m.add_orientation("keep", mi, mj)
    else:
        m.add_inline("line", "ground", "block", (0, 0, 0), d)
        m.add_orientation("keep", "ground", "block")
    return m, d


def _frame_z(z):
    from mbdsim.math.rotation import perpendicular_frame
    f, g, h = perpendicular_frame(np.asarray(z, float))
    return np.column_stack([f, g, h])


@pytest.mark.parametrize("markers", [False, True])
def test_inline_orientation_slider_closed_form_and_compiled_path(markers):
    m, d = _slider(markers)
    a = -9.81 * d[2]            # acceleration along d
    res = {meth: mb.simulate(m, 0.8, 0.1, method=meth) for meth in ("auto", "dop853")}
    assert res["auto"].stats["method"].endswith("(compiled)"), res["auto"].stats["method"]
    t = res["auto"].time
    x = 0.5 * a * t**2
    for r in res.values():
        p = r.position("block") - np.array([0.3, 0, 0.3])
        assert np.allclose(p, np.outer(x, d), atol=1e-9)
        # the reaction holds the weight's normal component and no torque: N = m g cos(45 deg)
        F = r.reaction_force("line") + r.reaction_force("keep")
        n = np.array([-d[2], 0, d[0]])
        assert np.allclose(F @ n, 2.0 * 9.81 * d[0], rtol=1e-9)
        assert np.allclose(F @ d, 0.0, atol=1e-9)
    assert np.allclose(res["auto"].q, res["dop853"].q, atol=1e-8)


def test_pendulum_from_atpoint_and_parallel_axes_matches_revolute():
    """atpoint + parallel_axes = revolute: the same motion (compiled core) and the same reaction."""
    out = []
    for prims in (False, True):
        m = mb.Model("pend", gravity=(0, -9.81, 0))
        m.add_body("rod", 1.5, inertia=(0.01, 0.04, 0.05), position=(0.4, 0, 0))
        if prims:
            m.add_atpoint("pin", "ground", "rod", (0, 0, 0))
            m.add_parallel_axes("axes", "ground", "rod", (0, 0, 1))
        else:
            m.add_revolute("pin", "ground", "rod", (0, 0, 0), (0, 0, 1))
        r = mb.simulate(m, 1.0, 0.05)
        assert r.stats["method"].endswith("(compiled)"), r.stats["method"]
        F = r.reaction_force("pin") + (r.reaction_force("axes") if prims else 0)
        out.append((r.q, F))
    assert np.allclose(out[0][0], out[1][0], atol=1e-9)
    assert np.allclose(out[0][1], out[1][1], atol=1e-6)


def test_errors_name_joint_and_field():
    m = mb.Model("e")
    m.add_body("b", 1.0, inertia=(1, 1, 1))
    m.add_particle("p", 1.0, position=(1, 0, 0))
    with pytest.raises(ModelError, match="joint 'x'.*axis_j"):
        m.add_perpendicular("x", "ground", "b", (0, 0, 1), (0, 0.1, 1))
    assert "x" not in m.joints
    with pytest.raises(ModelError, match="joint 's'.*lead"):
        m.add_screw("s", "ground", "b", (0, 0, 0), (0, 0, 1), lead=0.0)
    with pytest.raises(ModelError, match="joint 's'.*lead"):
        m.add_screw("s", "ground", "b", (0, 0, 0), (0, 0, 1))
    with pytest.raises(ModelError, match="joint 'i'.*axis"):
        m.add_inline("i", "ground", "b", (0, 0, 0))
    m.add_orientation("o", "ground", "p")
    with pytest.raises(ModelError, match="joint 'o'.*body_j.*particle"):
        mb.assemble(m)
    m2 = mb.Model("e2")
    m2.add_body("b", 1.0, inertia=(1, 1, 1))
    m2.add_inline("i", "ground", "b", (0, 0, 0), (1, 0, 0))
    r = mb.simulate(m2, 0.1)
    with pytest.raises(ModelError, match="joint 'i'.*no joint coordinates"):
        r.joint_coordinate("i")

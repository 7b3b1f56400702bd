"""Joints between marker pairs, conflicting motions, universal-joint axes and the AssemblyReport (issue 16).

Closed form: the four-bar loop closure B = circle(A, b) n circle(D, c) on the upper branch.
"""
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

A_, B_, C_, D_ = 0.1, 0.35, 0.3, 0.4     # crank, coupler, rocker, ground link [m]
TH = np.radians(50.0)


def closure(th):
    """Crank pin A and rocker pin B (upper branch) of the four-bar with ground pivots (0,0), (D_,0)."""
    A = A_ * np.array([np.cos(th), np.sin(th), 0.0])
    D = np.array([D_, 0.0, 0.0])
    d = np.linalg.norm(D - A)
    x = (d**2 + B_**2 - C_**2) / (2 * d)
    h = np.sqrt(B_**2 - x**2)
    e = (D - A) / d
    n = np.array([-e[1], e[0], 0.0])
    return A, A + x * e + h * n


def bar(model, name, p, q, mass, offset=(0.0, 0.0, 0.0), turn=0.0):
    """A bar from p to q (drawn shifted by `offset` and turned by `turn` rad about z) with markers at its
    ends, given where the drawn bar has them."""
    c, d = (p + q) / 2, q - p
    R = Rotation.from_rotvec([0, 0, np.arctan2(d[1], d[0]) + turn]).as_matrix()
    pos = c + np.asarray(offset)
    body = model.add_body(name, mass, inertia=(1e-4, mass * d @ d / 12, mass * d @ d / 12), position=pos,
                          orientation=R)
    half = np.linalg.norm(d) / 2
    return body, body.add_marker("p", pos - R[:, 0] * half, R), body.add_marker("q", pos + R[:, 0] * half, R)


def four_bar(offset=(0.03, -0.02, 0.0), turn=np.radians(4.0), rocker_motion=False):
    model = mb.Model("four_bar", gravity=(0, -9.81, 0))
    A, B = closure(TH)
    O, D = np.zeros(3), np.array([D_, 0.0, 0.0])
    g = model.ground
    # a marker-pair joint's coordinate is zero where its markers' axes coincide (Adams' convention): the
    # ground marker of the driven crank is turned to the crank's drawn angle so that the motion starts there
    go, gd = g.add_marker("o", O, Rotation.from_rotvec([0, 0, TH]).as_matrix()), g.add_marker("d", D)
    crank, c_o, c_a = bar(model, "crank", O, A, 1.0)
    coupler, k_a, k_b = bar(model, "coupler", A, B, 2.0, offset, turn)
    rocker, r_d, r_b = bar(model, "rocker", D, B, 1.5)
    model.add_revolute("O", go, c_o)
    model.add_revolute("A", c_a, k_a)
    model.add_revolute("B", k_b, r_b)
    model.add_revolute("D", gd, r_d)
    model.add_motion("drive", "O", velocity=2.0)
    if rocker_motion:
        model.add_motion("rocker_drive", "D", displacement="0.5*t")
    return model, coupler, (A + B) / 2


def test_four_bar_drawn_apart_and_joined_by_marker_pairs_assembles_to_the_closed_form():
    model, coupler, centre = four_bar()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mb.RedundantConstraintWarning)
        rep = mb.assemble(model)
        res = mb.kinematics(model, 0.2, 0.01)
    k = list(model.bodies).index("coupler") - 1
    np.testing.assert_allclose(rep.q[rep.system.r_idx[k]], centre, atol=1e-9)
    np.testing.assert_allclose(res.position(coupler)[0], centre, atol=1e-9)
    assert set(rep.moved) == {"coupler"}             # crank held by its motion, rocker drawn closed
    dr, da = rep.moved["coupler"]
    assert dr == pytest.approx(np.hypot(0.03, 0.02), rel=0.3) and da == pytest.approx(np.radians(4), rel=0.3)
    assert "moved coupler" in str(rep)
    A, B = closure(TH + 2.0 * 0.2)                    # later times follow the closure too
    np.testing.assert_allclose(res.position(coupler)[-1], (A + B) / 2, atol=1e-8)


def test_marker_joints_refuse_points_axes_and_mixes():
    model = mb.Model()
    b = model.add_body("b", 1.0, inertia=(1, 1, 1))
    mi, mj = model.ground.add_marker("i"), b.add_marker("j")
    with pytest.raises(mb.ModelError, match="point"):
        model.add_revolute("r", mi, mj, (0, 0, 0))
    with pytest.raises(mb.ModelError, match="body_j"):
        model.add_revolute("r", mi, b, (0, 0, 0), (0, 0, 1))
    with pytest.raises(mb.ModelError, match="same body"):
        model.add_revolute("r", mj, b.add_marker("k"))
    assert "r" not in model.joints
    model.add_revolute("r", mi, mj)


def test_second_motion_on_a_driven_coordinate_is_refused_naming_both():
    model, _, _ = four_bar(offset=(0, 0, 0), turn=0.0)
    with pytest.raises(mb.ModelError, match="drive2.*already driven by motion 'drive'"):
        model.add_motion("drive2", "O", displacement="t")
    assert "drive2" not in model.motions


def test_over_driven_four_bar_is_an_assembly_error_naming_the_motions_before_any_step():
    model, _, _ = four_bar(offset=(0, 0, 0), turn=0.0, rocker_motion=True)
    for analysis in (lambda: mb.kinematics(model, 0.1), lambda: mb.simulate(model, 0.1)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with pytest.raises(mb.AssemblyError, match="over-driven") as err:
                analysis()
        assert "drive" in err.value.joints and "rocker_drive" in err.value.joints
        assert err.value.time == 0.0


def test_universal_axes_within_1e_6_rad_are_orthogonalised_and_noted_larger_refused():
    model = mb.Model()
    b = model.add_body("b", 1.0, inertia=(1, 1, 1))
    j = model.add_universal("u", "ground", b, (0, 0, 0), (0, 0, 1), (1, 0, 5e-7))
    assert abs(j.axis @ j.axis_j) < 1e-15
    rep = mb.assemble(model)
    assert "orthogonalised" in str(rep) and rep.notes
    with pytest.raises(mb.ModelError, match=r"axis_j.*0\.0572958 deg \(0\.001 rad\)") as err:
        model.add_universal("u2", "ground", b, (0, 0, 0), (0, 0, 1), (1, 0, 1e-3))
    assert "u2" not in model.joints


def test_a_consistent_model_reports_no_motion_from_round_off():
    model = mb.Model()
    R = Rotation.from_rotvec([0.3, -0.2, 1.1]).as_matrix()
    rod = model.add_body("rod", 1.0, inertia=(0.1, 0.2, 0.25), position=R @ [0.5, 0, 0], orientation=R)
    model.add_revolute("pin", "ground", rod, (0, 0, 0), R[:, 2])
    rep = mb.assemble(model)
    assert rep.moved == {} and "no body moved" in str(rep) and rep.residual < 1e-12

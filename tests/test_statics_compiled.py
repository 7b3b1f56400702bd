"""Static equilibrium and quasi-static analysis on the compiled core (issue 29: `quasi_static` in compiled
code): the loads, the chart's projection and the unbalanced load of every trial configuration come from one
compiled call per batch (solvers.faststatic), the trust-region iteration stays as it was.

References: closed forms (a chain of links hanging under torsion springs, solved by the joint-torque
balance with scipy; a driven crank holding a pendulum), and the numpy force elements of the reference
evaluator (solvers.static_eval.Reference: an independent implementation of every load) on a model mixing
gravity, torsion springs, a spring-damper and a Python-callable torque.
"""
import numpy as np
import pytest
from scipy.optimize import fsolve

import mbdsim as mb
import mbdsim.solvers.static as static
import mbdsim.solvers.static_eval as static_eval

G = 9.81


def arm(n, k, drive=None, extra=False):
    """n uniform links (1 kg, 1 m) along +x, pinned end to end about z, gravity -y, torsion springs of
    stiffness k [N m/rad] on every joint but the first; the first driven by `drive` (an expression of t)
    or sprung too."""
    model = mb.Model("arm", gravity=(0.0, -G, 0.0))
    prev, x = model.ground, 0.0
    for i in range(n):
        b = model.add_body(f"l{i}", 1.0, inertia=(0.01, 1 / 12, 1 / 12), position=(x + 0.5, 0, 0))
        j = model.add_revolute(f"j{i}", prev, b, (x, 0, 0), (0, 0, 1))
        if i == 0 and drive is not None:
            model.add_motion("drive", j, displacement=drive)
        else:
            model.add_torsion_spring(f"k{i}", j, k, damping=0.1)
        prev, x = b, x + 1.0
    if extra:
        model.add_spring_damper("tie", (model.ground, (n / 2, 1.0, 0.0)), (prev, (x, 0, 0)), 15.0, 1.0,
                                free_length=0.5)
        model.add_torque("motor", prev, lambda t, s: (0.0, 0.0, 0.3 * np.sin(s.position("l0")[1] + 1.0)))
    return model


def absolute_angles(rel):
    return np.cumsum(rel)


def chain_balance(n, k, first=None):
    """Relative joint angles of the hanging chain of `arm` (first joint fixed at `first` when driven):
    each joint's spring torque k x_i balances the moment of the weights beyond it."""
    def residual(x):
        rel = np.concatenate([[first], x]) if first is not None else x
        th = absolute_angles(rel)
        ends = np.concatenate([[0.0], np.cumsum(np.cos(th))])   # x of the joints and the tip
        cms = ends[:-1] + 0.5 * np.cos(th)
        out = []
        for i in range(0 if first is None else 1, n):
            moment = -G * np.sum(cms[i:] - ends[i])   # moment about joint i of the weights beyond it (z)
            out.append(k * rel[i] - moment)
        return out
    guess = np.zeros(n - (first is not None))
    return fsolve(residual, guess, xtol=1e-13)


def link_angles(res, n):
    th = [np.unwrap(np.arctan2(*(res.orientation(f"l{i}")[:, :2, 0].T[::-1]))) for i in range(n)]
    return np.diff(np.concatenate([np.zeros((1, len(th[0]))), np.array(th)]), axis=0).T


def test_sprung_chain_sags_to_the_joint_torque_balance_compiled():
    n, k = 4, 40.0
    res = mb.equilibrium(arm(n, k))
    assert res.stats["method"] == "trust-region Newton (compiled)" and res.stats["stable"]
    ref = chain_balance(n, k)
    assert np.max(np.abs(link_angles(res, n)[0] - ref)) < 1e-9
    assert res.spring_force("k1")[0] == pytest.approx(k * ref[1], abs=1e-7)


def test_quasi_static_driven_chain_against_the_balance_at_every_sample():
    n, k = 3, 25.0
    res = mb.quasi_static(arm(n, k, drive="0.8*t"), 2.0, 0.1)
    assert res.success and res.stats["method"] == "trust-region Newton (compiled)"
    rel = link_angles(res, n)
    for i, t in enumerate(res.time):
        assert np.max(np.abs(rel[i, 1:] - chain_balance(n, k, first=0.8 * t))) < 1e-9
    mid = res.at([0.55])   # solved again between samples, from the nearest one
    assert np.max(np.abs(link_angles(mid, n)[0, 1:] - chain_balance(n, k, first=0.8 * 0.55))) < 1e-9


def test_compiled_and_reference_evaluators_agree(monkeypatch):
    """Gravity, torsion springs, a spring-damper and a Python-callable torque of the state: the same
    equilibria, driver efforts, reactions and stiffness eigenvalues from both evaluators."""
    model = arm(4, 30.0, drive="t", extra=True)
    res = mb.quasi_static(model, 1.5, 0.05)
    assert res.success and "compiled" in res.stats["method"]
    monkeypatch.setattr(static, "evaluator", lambda sys, rows, sf: static_eval.Reference(sys, rows, sf))
    ref = mb.quasi_static(arm(4, 30.0, drive="t", extra=True), 1.5, 0.05)
    assert ref.success and "compiled" not in ref.stats["method"]
    assert np.max(np.abs(res.position("l3") - ref.position("l3"))) < 1e-8
    tau = ref.driver_effort("drive")
    assert np.max(np.abs(res.driver_effort("drive") - tau)) < 1e-7 * np.max(np.abs(tau))
    f = ref.reaction_force("j2")
    assert np.max(np.abs(res.reaction_force("j2") - f)) < 1e-7 * np.max(np.abs(f))
    e1, e2 = np.array(res.stats["stiffness_eigenvalues"]), np.array(ref.stats["stiffness_eigenvalues"])
    assert np.max(np.abs(e1 - e2)) < 1e-5 * np.max(np.abs(e2))


def test_wound_spring_equilibrium_beyond_a_turn_compiled():
    """A constant torque of 10 N m winds a torsion spring (2 N m/rad) to 5 rad from its free angle: the
    kernel continues the angle over the iterations and the Result reads it continued."""
    model = mb.Model("wound")
    drum = model.add_body("drum", 1.0, inertia=(0.1, 0.1, 0.1), position=(0.3, 0, 0))
    axle = model.add_revolute("axle", model.ground, drum, (0, 0, 0), (0, 0, 1))
    model.add_torsion_spring("clock", axle, 2.0, free_angle=0.5)
    model.add_torque("load", drum, (0.0, 0.0, 10.0))
    res = mb.equilibrium(model)
    assert "compiled" in res.stats["method"]
    assert res.joint_coordinate(axle)[0] == pytest.approx(5.5, abs=1e-9)
    assert res.spring_length("clock")[0] == pytest.approx(5.5, abs=1e-9)


def test_bead_on_a_helix_held_by_a_spring_compiled_against_the_reference_evaluator(monkeypatch):
    """Point-on-curve (the curve parameter follows the foot point in the kernels, so the tangent basis
    leaves it out): a bead on a helix pulled by a spring; the same equilibrium, reaction and stability from
    the reference evaluator, and one stable direction (no spurious neutral one along the parameter)."""
    def model():
        m = mb.Model("bead", gravity=(0, -G, 0))
        bead = m.add_particle("bead", 0.2, position=(0.3 * np.cos(-1.0), 0.3 * np.sin(-1.0), -0.1))
        m.add_point_on_curve("path", bead.add_marker("c"), m.ground,
                             mb.Curve(("0.3*cos(s)", "0.3*sin(s)", "0.1*s"), (-8, 8)))
        m.add_spring_damper("sp", (m.ground, (0.5, 0.0, 0.2)), bead, 20.0, free_length=0.1)
        return m
    res = mb.equilibrium(model())
    assert res.stats["method"] == "trust-region Newton (compiled)" and res.stats["stable"]
    assert len(res.stats["stiffness_eigenvalues"]) == 1 and not res.stats["neutral_directions"]
    monkeypatch.setattr(static, "evaluator", lambda sys, rows, sf: static_eval.Reference(sys, rows, sf))
    ref = mb.equilibrium(model())
    assert ref.stats["method"] == "trust-region Newton"
    assert np.max(np.abs(res.position("bead") - ref.position("bead"))) < 1e-10
    assert np.max(np.abs(res.reaction_force("path") - ref.reaction_force("path"))) < 1e-8
    p = res.position("bead")[0]   # on the helix, and the spring's pull balances gravity along its tangent
    s = np.arctan2(p[1], p[0]) + 2 * np.pi * np.round((p[2] / 0.1 - np.arctan2(p[1], p[0])) / (2 * np.pi))
    assert np.allclose(p, [0.3 * np.cos(s), 0.3 * np.sin(s), 0.1 * s], atol=1e-9)
    d = np.array([0.5, 0.0, 0.2]) - p
    pull = 20.0 * (np.linalg.norm(d) - 0.1) * d / np.linalg.norm(d)
    tangent = np.array([-0.3 * np.sin(s), 0.3 * np.cos(s), 0.1])
    assert abs((pull + [0, -0.2 * G, 0]) @ tangent) < 1e-8


def shafts(n, k=4.0):
    """n shafts on ground pins about z (1 kg, no gravity), a torsion spring k [N m/rad] on each but the
    first, a torque of 1 N m about z on the first."""
    m = mb.Model("shafts")
    joints = []
    for i in range(n):
        b = m.add_body(f"s{i}", 1.0, inertia=(0.1, 0.1, 0.1), position=(float(i), 0, 0))
        joints.append(m.add_revolute(f"j{i}", m.ground, b, (float(i), 0, 0), (0, 0, 1)))
        if i:
            m.add_torsion_spring(f"k{i}", joints[-1], k)
    m.add_torque("drive", "s0", (0.0, 0.0, 1.0))
    return m, joints


def test_gear_pair_compiled_at_the_virtual_work_balance(monkeypatch):
    """A gear pair (a two-body coupler: its continued angles carried by the kernels, left out of the
    tangent basis): V = k theta_1^2 / 2 - 1 N m theta_0 with theta_1 = -0.5 theta_0, minimum at theta_0 =
    1 / (0.25 k); the same from the reference evaluator."""
    m, (ja, jb) = shafts(2)
    m.add_gear("g", ja, jb, -0.5)
    res = mb.equilibrium(m)
    assert res.stats["method"] == "trust-region Newton (compiled)" and res.stats["stable"]
    assert len(res.stats["stiffness_eigenvalues"]) == 1
    assert res.joint_coordinate(ja)[0] == pytest.approx(1.0, abs=1e-9)
    assert res.joint_coordinate(jb)[0] == pytest.approx(-0.5, abs=1e-9)
    monkeypatch.setattr(static, "evaluator", lambda sys, rows, sf: static_eval.Reference(sys, rows, sf))
    m2, _ = shafts(2)
    m2.add_gear("g", "j0", "j1", -0.5)
    ref = mb.equilibrium(m2)
    assert "compiled" not in ref.stats["method"]
    assert np.max(np.abs(res.reaction_torque("j1") - ref.reaction_torque("j1"))) < 1e-8


def test_differential_compiled_at_the_closed_form(monkeypatch):
    """A coupler on three shafts (theta_2 = theta_0 + theta_1: a wide row, bordered in the kernels, its
    Jacobian G from the terms' blocks): the closed form theta = (2, -1, 1) tau / k (minimum of
    k theta_1^2 / 2 + k theta_2^2 / 2 - tau theta_0), and the reference evaluator's reactions."""
    m, joints = shafts(3)
    m.add_user_constraint("diff", "j0 + j1 - j2")
    res = mb.equilibrium(m)
    assert res.stats["method"] == "trust-region Newton (compiled)" and res.stats["stable"]
    assert len(res.stats["stiffness_eigenvalues"]) == 2
    for jt, x in zip(joints, (0.5, -0.25, 0.25)):
        assert res.joint_coordinate(jt)[0] == pytest.approx(x, abs=1e-9)
    monkeypatch.setattr(static, "evaluator", lambda sys, rows, sf: static_eval.Reference(sys, rows, sf))
    m2, _ = shafts(3)
    m2.add_user_constraint("diff", "j0 + j1 - j2")
    ref = mb.equilibrium(m2)
    assert ref.stats["method"] == "trust-region Newton"
    for j in ("j0", "j1", "j2"):
        assert np.max(np.abs(res.reaction_torque(j) - ref.reaction_torque(j))) < 1e-8


def test_joint_friction_is_refused_by_statics_naming_it():
    """Statics cannot load joint friction (indeterminate at rest): a ModelError naming the element."""
    model = arm(3, 20.0)
    model.add_friction("fr", "j1", 0.3, 0.2, pin_radius=0.01)
    with pytest.raises(mb.ModelError) as err:
        mb.equilibrium(model)
    assert err.value.entity == "friction 'fr'"

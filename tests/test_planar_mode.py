"""Planar mode (issue 11): a 2D mechanism of ordinary revolute joints flagged planar is not reported as
redundant; the out-of-plane equations are dropped by design and noted; the in-plane reactions are
determinate: they equal those of the same mechanism built without redundancy (one revolute replaced by
an inline primitive along the normal, which keeps only the two in-plane equations of its point).
"""
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelError
from mbdsim.solvers.assembly import RedundantConstraintWarning

A, B, C, D = (np.array(p, float) for p in ([0, 0, 0], [0, 1, 0], [2, 1.5, 0], [2.5, 0, 0]))


def four_bar(planar, last="revolute", tilt=0.0):
    m = mb.Model("fourbar", gravity=(0, -9.81, 0), planar=planar)
    for n, (p, q) in {"crank": (A, B), "coupler": (B, C), "rocker": (C, D)}.items():
        m.add_body(n, 1.0 + len(n) / 10, inertia=(0.01, 0.1, 0.1), position=(p + q) / 2)
    m.add_revolute("jA", "ground", "crank", A, (0, 0, 1))
    m.add_revolute("jB", "crank", "coupler", B, (0, 0, 1))
    m.add_revolute("jC", "coupler", "rocker", C, (np.sin(tilt), 0, np.cos(tilt)))
    if last == "revolute":
        m.add_revolute("jD", "rocker", "ground", D, (0, 0, 1))
    else:
        m.add_inline("jD", "rocker", "ground", D, (0, 0, 1))
    return m


def test_planar_four_bar_does_not_warn_and_says_why():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RedundantConstraintWarning)
        rep = mb.assemble(four_bar(True))
    assert rep.dof == 1 and rep.redundant == []
    assert any("3 out-of-plane equations are dependent by design" in n for n in rep.notes)
    assert "out-of-plane" in str(rep)
    with pytest.warns(RedundantConstraintWarning):        # the same model not flagged: reported
        mb.assemble(four_bar(False))


def test_in_plane_reactions_are_determinate():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RedundantConstraintWarning)
        res = mb.simulate(four_bar(True), 1.0, 0.05)
        ref = mb.simulate(four_bar(False, last="inline"), 1.0, 0.05)   # 9 + 2 ... no redundancy at all
    assert not mb.assemble(four_bar(False, last="inline")).redundant
    assert np.allclose(res.q, ref.q, atol=1e-8)
    for j in ("jA", "jB", "jC", "jD"):
        F, Fr = res.reaction_force(j), ref.reaction_force(j)
        assert np.allclose(F[:, :2], Fr[:, :2], atol=1e-6 * np.abs(Fr).max()), j
        assert np.allclose(res.reaction_torque(j)[:, 2], ref.reaction_torque(j)[:, 2], atol=1e-6), j
    # Newton for the crank (in plane): the joints' forces plus its weight give m a
    m = 1.0 + 5 / 10
    acc = res.acceleration("crank")
    F = res.reaction_force("jA", on="crank") + res.reaction_force("jB", on="crank")
    assert np.allclose(F[:, :2] + m * np.array([0, -9.81]), m * acc[:, :2], atol=1e-8)


def test_non_planar_model_flagged_planar_still_warns():
    with pytest.warns(RedundantConstraintWarning):
        rep = mb.assemble(four_bar(True, tilt=0.2))
    assert rep.redundant


def test_planar_argument_checked():
    m = mb.Model("x", planar=(0, 1, 0))
    assert np.allclose(m.planar, [0, 1, 0]) and mb.Model("y").planar is None
    with pytest.raises(ModelError, match="model 'z'.*planar"):
        mb.Model("z", planar=(0, 0, 0))

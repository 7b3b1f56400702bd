"""Joint coordinates do not depend on output sampling: whole turns counted on the solver's steps (issue 14)."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb

G = 9.81


def looping_model():
    """Three bodies looping in vertical planes, each turning several times per 0.5 s with rates that vary
    by a factor ~3 over a turn (the prediction from the rates at 0.5 s samples is off by more than pi):
    a short pendulum on a revolute joint, one on a cylindrical joint (also sliding), and a body on a
    planar joint pulled by a spring attached off its centre of mass."""
    m = mb.Model("looping", gravity=(0, -G, 0))
    z = (0, 0, 1)
    p1 = m.add_body("p1", 1.0, (1e-4, 1e-4, 1e-4), position=(0, -0.1, 0))
    m.add_revolute("rev", m.ground, p1, (0, 0, 0), z, initial_velocity=[21.0])
    p2 = m.add_body("p2", 1.0, (1e-4, 1e-4, 1e-4), position=(1, -0.1, 0))
    m.add_cylindrical("cyl", m.ground, p2, (1, 0, 0), z, initial_velocity=[-22.0, 0.3])
    p3 = m.add_body("p3", 1.0, (1e-3, 1e-3, 1e-3), position=(3, 0, 0))
    m.add_planar("pl", m.ground, p3, (3, 0, 0), z, initial_velocity=[0.0, 0.0, 25.0])
    m.add_spring_damper("spring", (m.ground, (3, 0.05, 0)), (p3, (3.1, 0, 0)), stiffness=40.0)
    return m


def coordinates(res, ts=None):
    r = res if ts is None else res.at(ts)
    return r.joint_coordinate("rev"), r.joint_coordinate("cyl")[:, 0], r.joint_coordinate("pl")[:, 2]


@pytest.mark.parametrize("method", [None, "rk45", "hht"])
def test_joint_coordinates_are_the_same_for_any_output_step(method):
    model = looping_model()
    coarse = mb.simulate(model, 1.0, output_step=0.5, method=method)
    fine = mb.simulate(model, 1.0, output_step=0.01, method=method)
    assert coarse.success and fine.success
    common = np.searchsorted(fine.time, coarse.time)
    assert np.allclose(fine.time[common], coarse.time)
    for c, f in zip(coordinates(coarse), coordinates(fine)):
        # the fine samples follow the turns (a turn per ~30 samples at most): the reference branch
        assert np.max(np.abs(np.diff(f))) < 1.0
        assert np.max(np.abs(np.diff(c))) > 2 * np.pi            # several turns between coarse samples
        assert np.max(np.abs(c - f[common])) < 1e-9
    # dense output and Result.at: the same at any time, from either run
    ts = np.array([0.137, 0.5, 0.9731, 1.0])
    for a, b, f in zip(coordinates(coarse, ts), coordinates(fine, ts), coordinates(fine)):
        assert np.max(np.abs(a - b)) < 1e-9
        assert np.max(np.abs(a - np.interp(ts, fine.time, f))) < 0.3     # on the fine samples' branch


def test_crossings_convention_at_the_start_of_a_signal():
    """A ball thrown up at v0 from height h0: the height's crossings of h0 are the return alone
    (2 v0 / g), never t = 0; a ball released at rest (vertical speed 0 at t = 0, the level) has no
    crossing at t = 0 either (scipy's solve_ivp events would report t0 in both cases)."""
    v0, h0 = 3.0, 1.0
    m = mb.Model("throw", gravity=(0, -G, 0))
    ball = m.add_particle("ball", 1.0, position=(0, h0, 0), velocity=(0.5, v0, 0))
    rest = m.add_particle("rest", 1.0, position=(2, h0, 0))
    res = mb.simulate(m, 1.0, output_step=0.1)
    up = res.crossings(lambda r: r.position(ball)[:, 1], h0)
    assert up == pytest.approx([2 * v0 / G], abs=1e-9)
    assert len(res.crossings(lambda r: r.position(ball)[:, 1], h0, direction=+1)) == 0
    assert res.crossings(lambda r: r.velocity(ball)[:, 1], 0.0) == pytest.approx([v0 / G], abs=1e-9)
    assert len(res.crossings(lambda r: r.velocity(rest)[:, 1], 0.0)) == 0       # starts at the level
    assert len(res.crossings(lambda r: r.position(rest)[:, 1], h0)) == 0

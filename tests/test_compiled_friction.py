"""Joint friction stick/slip on the compiled core (issue 29) against closed forms and conservation laws.

The spring-pulled block: breakaway and stop against the closed form; the coasting slider-crank (a
closed loop, friction in the bore) comes to rest with the energy balance kinetic +
potential + dissipated = initial energy to 1e-6 of it, and stops when the event-driven reference
(force_elements.friction, Python) says; the torque-driven crank-rocker with friction in every pin
passes its rocker's extremes (reversals carried by the loop) where the closed form puts them, with
the drive's work = change of energy + dissipation. Each states the issue-29 contract: "(compiled)" in
res.stats["method"].
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

import mbdsim as mb
from test_friction_loops import four_bar, rocker_extreme_crank_angles, slider_crank

G = 9.81


def spring_pulled_block(m=2.0, k=200.0, vp=0.5, mu_s=0.5, mu_d=0.3):
    """Block on a ground slide (x), pulled through a spring k [N/m] by an anchor driven at vp [m/s]."""
    mdl = mb.Model("stick_slip", gravity=(0, -G, 0))
    block = mdl.add_particle("block", m, (0, 0, 0), velocity=(0, 0, 0))
    anchor = mdl.add_particle("anchor", 1.0, (1, 0, 0), velocity=(vp, 0, 0))
    slide = mdl.add_translational("slide", mdl.ground, block, (0, 0, 0), (1, 0, 0))
    rail = mdl.add_translational("rail", mdl.ground, anchor, (1, 0, 0), (1, 0, 0))
    mdl.add_motion("pull", rail, displacement=f"{vp}*t")
    mdl.add_spring_damper("spring", (anchor, (1, 0, 0)), (block, (0, 0, 0)), k, free_length=1.0)
    mdl.add_friction("friction", slide, mu_s, mu_d)
    return mdl, slide


def closed_form(m=2.0, k=200.0, vp=0.5, mu_s=0.5, mu_d=0.3):
    """Breakaway time (k vp t = mu_s m g) and the next stop: slip phase m xdd = k (vp t - x) - mu_d m g,
    u = x - vp t + mu_d m g / k harmonic at w = sqrt(k/m) from u0 = (mu_d - mu_s) m g / k, ud0 = -vp."""
    tb = mu_s * m * G / (k * vp)
    w, u0 = np.sqrt(k / m), (mu_d - mu_s) * m * G / k
    xd = lambda s: -u0 * w * np.sin(w * s) - vp * np.cos(w * s) + vp   # noqa: E731
    s_stop = brentq(xd, 1e-3 / w, 2 * np.pi / w - 1e-3 / w)
    x_stop = u0 * np.cos(w * s_stop) - vp / w * np.sin(w * s_stop) + vp * (tb + s_stop) - mu_d * m * G / k
    return tb, tb + s_stop, x_stop


def test_spring_pulled_block_breaks_away_at_k_x_equal_mu_s_m_g_and_stops_again():
    tb, ts, xs = closed_form()
    model, slide = spring_pulled_block()
    res = mb.simulate(model, ts + 0.05, output_step=0.01)
    assert res.success, res.message
    ev = res.friction_events("friction")
    assert [mode for _, mode, _ in ev[:3]] == ["stick", "slip", "stick"]
    assert ev[1][0] == pytest.approx(tb, rel=1e-8)
    assert ev[2][0] == pytest.approx(ts, rel=1e-7)
    assert float(res.at(ev[2][0]).joint_coordinate(slide)[0]) == pytest.approx(xs, rel=1e-7)
    # stuck before breakaway: the static friction carries the spring force k vp t
    before = res.time < tb - 1e-3
    assert np.allclose(res.friction_force("friction")[before], -200.0 * 0.5 * res.time[before], atol=1e-8)


def test_friction_runs_compiled():
    model, _ = spring_pulled_block()
    res = mb.simulate(model, 0.1, output_step=0.01)
    assert res.success, res.message
    assert "(compiled)" in res.stats["method"], res.stats["method"]   # "not compiled" must not count


def test_coasting_slider_crank_comes_to_rest_compiled_with_energy_balance(monkeypatch):
    model = slider_crank("coast", mu=0.4)
    res = mb.simulate(model, 3.5, output_step=0.01)
    assert res.success, res.message
    assert "(compiled)" in res.stats["method"], res.stats["method"]
    ev = res.friction_events("friction")
    assert ev[-1][1] == "stick" and ev[-1][0] < 3.0
    after = res.time > ev[-1][0]
    assert np.max(np.abs(res.joint_velocity("O")[after])) < 1e-10   # at rest, and staying there
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert D[-1] > 0.5 * E[0]
    assert np.max(np.abs(E + D - E[0])) < 1e-6 * E[0]
    # the same stop as the event-driven reference path (Python, scipy's DOP853)
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", False)
    ref = mb.simulate(slider_crank("coast", mu=0.4), ev[-1][0] + 0.05, output_step=0.05)
    assert "(compiled)" not in ref.stats["method"]
    ev_ref = ref.friction_events("friction")
    assert [(m, d) for _, m, d in ev_ref] == [(m, d) for _, m, d in ev]
    assert np.allclose([e[0] for e in ev_ref], [e[0] for e in ev], rtol=1e-6, atol=0)


def test_crank_rocker_with_friction_in_every_pin_compiled_through_rocker_extremes():
    res = mb.simulate(four_bar("torque"), 0.3, output_step=0.01)
    assert res.success, res.message
    assert "(compiled)" in res.stats["method"], res.stats["method"]
    ev = res.friction_events("f_O4")[1:]          # rocker pivot reversals: the rocker's extremes
    assert len(ev) >= 2 and all(m == "slip" for _, m, _ in ev)
    crank = (res.at([e[0] for e in ev]).joint_coordinate("O2") + 0.3) % (2 * np.pi)
    ext = rocker_extreme_crank_angles()
    assert np.max(np.min(np.abs(crank[:, None] - ext[None]), axis=1)) < 1e-7
    th = res.joint_coordinate("O2") + 0.3
    E = res.kinetic_energy() + res.potential_energy()
    W = 0.3 * (th - th[0])
    assert np.max(np.abs(W - (E - E[0] + res.dissipated_energy()))) < 1e-6 * W[-1]

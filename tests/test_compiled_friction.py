"""Joint friction stick/slip against closed forms, and the issue-29 contract that it runs compiled.

The physics checks run on whatever path `simulate` picks; `test_friction_runs_compiled` states the
issue-29 contract (res.stats["method"] says "(compiled)") and is a strict xfail until the compiled
step loop carries friction (system/compiled.py still raises NotCompiled for lock rows).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

import mbdsim as mb

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

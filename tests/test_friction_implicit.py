"""Joint friction stick/slip on the compiled implicit steppers, HHT-alpha and Radau IIA (issue 29).

The spring-pulled block's breakaway (k vp t = mu_s m g) and next stop against the closed form; the
coasting slider-crank (friction in the bore of a closed loop) comes to rest with kinetic + potential +
dissipated energy = the initial energy to 1e-6 of it, and stops when the compiled DOP853 (an explicit
method, its events on its own dense output) says. Each run states "(compiled)" in res.stats["method"].
"""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from test_compiled_friction import G, closed_form, spring_pulled_block
from test_friction_loops import four_bar, slider_crank

METHODS = [("hht", "HHT (compiled)", 1e-9), ("radau", "Radau IIA (compiled)", None)]


@pytest.mark.parametrize("method, name, rtol", METHODS)
def test_spring_pulled_block_breakaway_and_stop_on_implicit_steppers(method, name, rtol):
    tb, ts, xs = closed_form()
    model, slide = spring_pulled_block()
    res = mb.simulate(model, ts + 0.05, output_step=0.01, method=method, rtol=rtol)
    assert res.success, res.message
    assert res.stats["method"] == name
    ev = res.friction_events("friction")
    assert [mode for _, mode, _ in ev[:3]] == ["stick", "slip", "stick"]
    assert ev[1][0] == pytest.approx(tb, rel=1e-8)   # the stick phase is exact: the anchor is a driver
    assert ev[2][0] == pytest.approx(ts, rel=1e-6)
    assert float(res.at(ev[2][0]).joint_coordinate(slide)[0]) == pytest.approx(xs, rel=1e-6)
    before = res.time < tb - 1e-3   # stuck: static friction carries the spring force k vp t
    assert np.allclose(res.friction_force("friction")[before], -200.0 * 0.5 * res.time[before], atol=1e-8)
    after = res.time > ev[2][0] + 1e-3   # stuck again
    assert np.max(np.abs(res.joint_velocity(slide)[after])) < 1e-9


@pytest.mark.parametrize("method, name, rtol", METHODS)
def test_coasting_slider_crank_energy_balance_on_implicit_steppers(method, name, rtol):
    res = mb.simulate(slider_crank("coast", mu=0.4), 1.6, output_step=0.01, method=method, rtol=rtol)
    assert res.success, res.message
    assert res.stats["method"] == name
    ev = res.friction_events("friction")
    assert ev[-1][1] == "stick" and ev[-1][0] < 1.5
    after = res.time > ev[-1][0]
    assert np.max(np.abs(res.joint_velocity("O")[after])) < 1e-9   # at rest, and staying there
    E = res.kinetic_energy() + res.potential_energy()
    D = res.dissipated_energy()
    assert D[-1] > 0.5 * E[0]
    assert np.max(np.abs(E + D - E[0])) < 1e-6 * E[0]
    ref = mb.simulate(slider_crank("coast", mu=0.4), ev[-1][0] + 0.05, output_step=0.05, method="dop853")
    assert ref.stats["method"].startswith("DOP853") and "(compiled)" in ref.stats["method"]
    ev_ref = ref.friction_events("friction")
    assert [(m, d) for _, m, d in ev_ref] == [(m, d) for _, m, d in ev]
    assert np.allclose([e[0] for e in ev_ref], [e[0] for e in ev], rtol=1e-6, atol=0)


def test_four_bar_held_by_all_pins_on_radau():
    """A four-bar coasting with friction in all four pins stops as one held group (the shared capacity
    carried by the sticking pin's switching function) on Radau as on DOP853: the same stick/slip history
    to 1e-7, at rest after it, energy balance to 1e-6 of the initial energy."""
    runs = {m: mb.simulate(four_bar("coast", mu=0.3, pin=0.05), 0.7, output_step=0.01, method=m, rtol=1e-8)
            for m in ("radau", "dop853")}
    res = runs["radau"]
    assert res.success, res.message
    assert res.stats["method"] == "Radau IIA (compiled)"
    pins = ("f_O2", "f_A", "f_B", "f_O4")
    for n in pins:
        ev, ev_ref = res.friction_events(n), runs["dop853"].friction_events(n)
        assert [(m, d) for _, m, d in ev] == [(m, d) for _, m, d in ev_ref]
        assert np.allclose([e[0] for e in ev], [e[0] for e in ev_ref], rtol=1e-7, atol=0)
        assert ev[-1][1] == "stick"
    t_stop = max(res.friction_events(n)[-1][0] for n in pins)
    assert np.max(np.abs(res.joint_velocity("O2")[res.time > t_stop])) < 1e-10
    E = res.kinetic_energy() + res.potential_energy()
    assert np.max(np.abs(E + res.dissipated_energy() - E[0])) < 1e-6 * E[0]


def stiff_pulled_block(k_stiff=1e7, c_stiff=3000.0):
    """The spring-pulled block carrying a 0.01 kg tag on a slide of its own, held to it by a stiff,
    overdamped spring-damper (k_stiff [N/m], c_stiff [N s/m]: eigenvalues about -k/c and -c/m, a stiff
    machine); the tag's weight goes through the block into its friction slide."""
    mdl = mb.Model("stiff_block", gravity=(0, -G, 0))
    block = mdl.add_particle("block", 2.0, (0, 0, 0))
    tag = mdl.add_particle("tag", 0.01, (0.1, 0, 0))
    anchor = mdl.add_particle("anchor", 1.0, (1, 0, 0), velocity=(0.5, 0, 0))
    slide = mdl.add_translational("slide", mdl.ground, block, (0, 0, 0), (1, 0, 0))
    mdl.add_translational("tag_slide", block, tag, (0.1, 0, 0), (1, 0, 0))
    rail = mdl.add_translational("rail", mdl.ground, anchor, (1, 0, 0), (1, 0, 0))
    mdl.add_motion("pull", rail, displacement="0.5*t")
    mdl.add_spring_damper("spring", (anchor, (1, 0, 0)), (block, (0, 0, 0)), 200.0, free_length=1.0)
    mdl.add_spring_damper("stiff", (block, (0.1, 0, 0)), (tag, (0.1, 0, 0)), k_stiff, free_length=0.0,
                          damping=c_stiff)
    mdl.add_friction("friction", slide, 0.5, 0.3)
    return mdl, slide


@pytest.mark.parametrize("method", ["radau", None])
def test_stiff_machine_with_friction_on_radau(method):
    """A stiff machine with stick/slip runs on the compiled Radau in a few hundred steps (DOP853 takes
    ~29,000 on it) with the breakaway and stop of the block's closed form for the total mass 2.01 kg
    (the tag's stiff spring deflects by m_tag a / k ~ 1e-9 m); at the defaults the automatic method
    detects the stiffness and hands over to Radau, the friction modes going on."""
    tb, ts, xs = closed_form(m=2.01)
    model, slide = stiff_pulled_block()
    res = mb.simulate(model, ts + 0.05, output_step=0.01, method=method)
    assert res.success, res.message
    if method is None:
        assert "then Radau IIA (compiled)" in res.stats["method"], res.stats["method"]
    else:
        assert res.stats["method"] == "Radau IIA (compiled)"
    assert res.stats["steps"] < 1000
    ev = res.friction_events("friction")
    assert [mode for _, mode, _ in ev] == ["stick", "slip", "stick"]
    assert ev[1][0] == pytest.approx(tb, rel=1e-8)
    assert ev[2][0] == pytest.approx(ts, rel=1e-6)
    assert float(res.at(ev[2][0]).joint_coordinate(slide)[0]) == pytest.approx(xs, rel=1e-6)

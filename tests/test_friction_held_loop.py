"""A held group of two degrees of freedom on the compiled core (issue 29): a five-bar (2 DOF) with pin
friction in all five pins coasts to rest under a slowly rising crank torque r t. One pin stops first
(the loop goes on as a four-bar), then the rest stop together: five stuck pins in a 2-DOF loop, two
sticking locks and three held ones, each held lock depending on both sticking ones, so the group's
static capacity is shared through both (the zonotope of `fastfriction.group_margin`). Against closed
forms: the mechanism stays exactly where it stopped while the torque is below the breakaway load and
breaks away at t = T_b / r, with T_b the least virtual dissipation over the loop's motions per unit crank
rotation, min over (dth1 = 1, dth5 = s) of sum_k mu_s N_k |dphi_k| (the dual of the least-load
programme; N_k the preloads, the pins unloaded at rest without gravity; dphi_k the pins' relative
rotations from the five-bar's closed-form positions), the pins slipping in the directions of the
minimising motion and the pin it leaves at rest staying stuck; kinetic energy + dissipation = initial
energy + the drive's work to 1e-6 of the initial energy; the stops and the breakaway where the
event-driven reference path (force_elements.friction_lcp, scipy's DOP853) puts them.
"""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from test_friction_held import MU_S, five_bar
from test_friction_loops import drive_work

RATE, PRELOAD = 0.02, 0.02   # [N m / s], [N m] (five_bar's preload, every pin)
TH1, TH5 = 1.8, 1.3          # five_bar's crank angles as built [rad]
PINS = ("O1", "A", "B", "C", "O5")


def coasting_five_bar():
    """five_bar released with crank rates -1 and 0.6 rad/s, under the crank torque RATE t."""
    m = five_bar(f"{RATE}*t")
    m.joints["O1"].initial_velocity = [-1.0]
    m.joints["O5"].initial_velocity = [0.6]
    return m


def pin_angles(t1, t5):
    """Relative rotations [rad] of the pins O1, A, B, C, O5 at crank angles t1, t5 (closed-form positions:
    five_bar's geometry, the couplers' pin B on the same side as built)."""
    A = 0.1 * np.array([np.cos(t1), np.sin(t1)])
    C = np.array([0.3, 0.0]) + 0.1 * np.array([np.cos(t5), np.sin(t5)])
    d = np.linalg.norm(C - A)
    ex = (C - A) / d
    B = A + 0.5 * d * ex + np.sqrt(0.25**2 - (0.5 * d) ** 2) * np.array([-ex[1], ex[0]])
    p1, p2 = np.arctan2(*(B - A)[::-1]), np.arctan2(*(C - B)[::-1])
    return np.array([t1, p1 - t1, p2 - p1, t5 - p2, t5])


def breakaway(t1, t5):
    """(T_b [N m], the minimising motion's pin rates per unit crank rate) at crank angles t1, t5: the least
    of the convex piecewise-linear sum_k cap_k |a_k + s b_k| over s lies at one of its kinks."""
    d = 1e-6
    a = (pin_angles(t1 + d, t5) - pin_angles(t1 - d, t5)) / (2 * d)
    b = (pin_angles(t1, t5 + d) - pin_angles(t1, t5 - d)) / (2 * d)
    cap = MU_S * PRELOAD
    kinks = [-a[k] / b[k] for k in range(5) if abs(b[k]) > 1e-12]
    s = min(kinks, key=lambda x: np.sum(cap * np.abs(a + x * b)))
    return float(np.sum(cap * np.abs(a + s * b))), a + s * b


def events(res):
    return {n: res.friction_events("f_" + n) for n in PINS}


def test_five_bar_held_by_five_pins_breaks_away_at_the_closed_form_load_compiled(monkeypatch):
    end = 1.4
    res = mb.simulate(coasting_five_bar(), end, output_step=0.005, rtol=1e-9)
    assert res.success, res.message
    assert "(compiled)" in res.stats["method"], res.stats["method"]
    ev = events(res)
    stops = {n: [t for t, m, _ in e if m == "stick"] for n, e in ev.items()}
    assert all(len(s) == 1 for s in stops.values())
    t_s = max(s[0] for s in stops.values())                 # the last pins stop together: the group
    assert sorted(s[0] for s in stops.values())[1] == pytest.approx(t_s, abs=1e-12)
    assert min(s[0] for s in stops.values()) < t_s - 0.05   # one pin stopped first
    th1 = float(res.at(t_s).joint_coordinate("O1")[0]) + TH1
    th5 = float(res.at(t_s).joint_coordinate("O5")[0]) + TH5
    T_b, motion = breakaway(th1, th5)
    assert RATE * t_s < 0.5 * T_b                           # held at the stop
    slips = {n: [(t, d) for t, m, d in e if m == "slip" and t > t_s] for n, e in ev.items()}
    moving = [n for n, r in zip(PINS, motion) if abs(r) > 1e-6]
    assert len(moving) == 4 and all(not slips[n] for n in PINS if n not in moving)
    t_b = slips[moving[0]][0][0]
    assert t_b == pytest.approx(T_b / RATE, rel=1e-6)       # the closed-form breakaway load
    for n, r in zip(PINS, motion):                          # together, in the minimising motion's directions
        if n in moving:
            assert slips[n][0] == (pytest.approx(t_b, abs=1e-12), np.sign(r))
    held = (res.time > t_s + 1e-9) & (res.time < t_b - 1e-9)
    assert np.count_nonzero(held) > 50
    for n in PINS:                                          # at rest, exactly
        x = res.joint_coordinate(n)[held]
        assert np.max(np.abs(x - x[0])) < 1e-12 and np.max(np.abs(res.joint_velocity(n)[held])) < 1e-10
    assert res.joint_velocity("O1")[-1] > 0.1               # moving again, with the torque
    # kinetic energy + dissipation = initial energy + the drive's work (Gauss-Legendre between the events)
    cuts = sorted({0.0, res.time[-1], *(t for e in ev.values() for t, _, _ in e)})
    power = lambda r: RATE * r.time * r.joint_velocity("O1")  # noqa: E731
    E, D = res.kinetic_energy(), res.dissipated_energy()
    for t in (t_s, t_b, res.time[-1]):
        k = int(np.searchsorted(res.time, t))
        tk = float(res.time[k])
        W = drive_work(res, [c for c in cuts if c < tk] + [tk], power)
        assert abs(E[k] + D[k] - E[0] - W) < 1e-6 * E[0], t
    # the same stick/slip history as the event-driven reference path (Python, scipy's DOP853)
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", False)
    ref = mb.simulate(coasting_five_bar(), end, output_step=0.05, rtol=1e-9)
    assert "(compiled)" not in ref.stats["method"]
    for n, e_ref in events(ref).items():
        assert [x[1:] for x in e_ref] == [x[1:] for x in ev[n]]
        assert np.allclose([x[0] for x in e_ref], [x[0] for x in ev[n]], rtol=1e-7, atol=0)


def test_five_bar_held_group_on_the_compiled_radau():
    """The same group on Radau IIA (fastswitch: the switching functions on its collocation polynomial),
    coasting without the torque: DOP853's stick/slip history to 1e-8, at rest after it, kinetic energy +
    dissipation constant to 1e-6 of the initial energy."""
    def coasting():
        m = five_bar(None)
        m.joints["O1"].initial_velocity = [-1.0]
        m.joints["O5"].initial_velocity = [0.6]
        return m
    runs = {m: mb.simulate(coasting(), 0.6, output_step=0.005, method=m, rtol=1e-9) for m in ("radau", "dop853")}
    res = runs["radau"]
    assert res.success, res.message
    assert res.stats["method"] == "Radau IIA (compiled)"
    for n, ev in events(res).items():
        ev_ref = events(runs["dop853"])[n]
        assert [x[1:] for x in ev] == [x[1:] for x in ev_ref] and ev[-1][1] == "stick"
        assert np.allclose([x[0] for x in ev], [x[0] for x in ev_ref], rtol=1e-8, atol=0)
    t_stop = max(ev[-1][0] for ev in events(res).values())
    for n in PINS:
        assert np.max(np.abs(res.joint_velocity(n)[res.time > t_stop + 1e-9])) < 1e-10
    E = res.kinetic_energy()
    assert np.max(np.abs(E + res.dissipated_energy() - E[0])) < 1e-6 * E[0]

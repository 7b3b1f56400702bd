"""A held group on the compiled core (issue 29): a crank-rocker with friction in all four pins coasts to
rest; its four locks are dependent (one DOF), so the pins stick as one group whose static capacity is
shared.  Against closed forms: while the crank torque T = r t stays below the group's capacity
C = sum_k |c_k| mu_s N_k (c_k the pins' joint rates per unit crank rate at the stop, from the four-bar's
closed-form positions; N_k the preloads, the pins being unloaded at rest without gravity) the mechanism
stays where it stopped; all four pins break away together at t = C / r; kinetic energy + dissipation = initial energy +
the drive's work to 1e-6 of the initial energy; the stop and the breakaway where the event-driven
reference path (force_elements.friction_lcp, scipy's DOP853) puts them.
"""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from test_friction_loops import drive_work, four_bar_points, rz

RATE, MU_S, MU_D = 0.01, 0.4, 0.3
PRELOADS = {"O2": 0.02, "A": 0.01, "B": 0.015, "O4": 0.012}   # [N m]
TH0 = 0.3


def held_four_bar(w0=-1.0):
    """Crank-rocker (test_friction_loops' links) without gravity, coasting from w0 [rad/s], pin friction
    with preloads in every joint, a crank torque RATE * t [N m]."""
    m = mb.Model("held_four_bar", gravity=(0, 0, 0))
    A, B, O4 = four_bar_points(TH0)
    ang = lambda v: rz(np.arctan2(v[1], v[0]))  # noqa: E731
    crank = m.add_body("crank", 0.5, (1e-4, 4e-4, 4e-4), position=A / 2, orientation=ang(A))
    coupler = m.add_body("coupler", 1.0, (1e-4, 0.01, 0.01), position=(A + B) / 2, orientation=ang(B - A))
    rocker = m.add_body("rocker", 0.8, (1e-4, 6e-3, 6e-3), position=(B + O4) / 2, orientation=ang(B - O4))
    z = (0, 0, 1)
    joints = [m.add_revolute("O2", m.ground, crank, (0, 0, 0), z, initial_velocity=[w0]),
              m.add_revolute("A", crank, coupler, A, z), m.add_revolute("B", coupler, rocker, B, z),
              m.add_revolute("O4", m.ground, rocker, O4, z)]
    for jt in joints:
        m.add_friction("f_" + jt.name, jt, MU_S, MU_D, pin_radius=0.01, preload=PRELOADS[jt.name])
    m.add_torque("drive", crank, (0, 0, f"{RATE}*t"))
    return m


def link_angles(th):
    """Crank, coupler and rocker angles [rad] at crank angle th (closed-form positions)."""
    A, B, O4 = four_bar_points(th)
    return np.array([th, np.arctan2(*(B - A)[1::-1]), np.arctan2(*(B - O4)[1::-1])])


def capacity(th):
    """The group's static capacity C [N m] at crank angle th: sum_k |c_k| mu_s N_k, c_k the joint rates
    of O2, A, B, O4 per unit crank rate (central differences of the closed-form angles)."""
    d = 1e-6
    r2, r3, r4 = (link_angles(th + d) - link_angles(th - d)) / (2 * d)
    c = {"O2": r2, "A": r3 - r2, "B": r4 - r3, "O4": r4}
    return MU_S * sum(abs(c[n]) * PRELOADS[n] for n in PRELOADS)


def events(res):
    """{pin: [(time [s], mode, direction)]} of the four pins' friction."""
    return {n: res.friction_events("f_" + n) for n in PRELOADS}


def test_four_bar_stopped_with_friction_in_every_pin_is_held_as_one_group_compiled(monkeypatch):
    res = mb.simulate(held_four_bar(), 3.0, output_step=0.01, rtol=1e-9)
    assert res.success, res.message
    assert "(compiled)" in res.stats["method"], res.stats["method"]
    ev = events(res)
    stops = [t for e in ev.values() for t, m, _ in e if m == "stick"]
    t_s = stops[0]
    assert len(stops) == 4 and max(stops) - min(stops) < 1e-12        # the pins stop together, once
    breaks = [min(t for t, m, _ in e if m == "slip" and t > t_s) for e in ev.values()]
    t_b = breaks[0]
    assert max(breaks) - min(breaks) < 1e-12                           # and break away together
    th_s = float(res.at(t_s).joint_coordinate("O2")[0]) + TH0
    assert RATE * t_s < 0.5 * capacity(th_s)                           # held at the stop
    assert t_b == pytest.approx(capacity(th_s) / RATE, rel=1e-6)       # the closed-form breakaway load
    held = (res.time > t_s + 1e-9) & (res.time < t_b - 1e-9)
    assert np.count_nonzero(held) > 50
    assert np.max(np.abs(res.joint_coordinate("O2")[held] + TH0 - th_s)) < 1e-10
    for n in PRELOADS:
        assert np.max(np.abs(res.joint_velocity(n)[held])) < 1e-10
    assert res.joint_velocity("O2")[-1] > 0.5                          # moving again, with the torque
    # kinetic energy + dissipation = initial energy + the drive's work (Gauss-Legendre between the events)
    cuts = sorted({0.0, res.time[-1], *(t for e in ev.values() for t, _, _ in e)})
    power = lambda r: RATE * r.time * r.joint_velocity("O2")  # noqa: E731
    E, D = res.kinetic_energy(), res.dissipated_energy()
    for t in (t_s, t_b, res.time[-1]):
        k = int(np.searchsorted(res.time, t))   # the first sample at or after t
        tk = float(res.time[k])
        W = drive_work(res, [c for c in cuts if c < tk] + [tk], power)
        assert abs(E[k] + D[k] - E[0] - W) < 1e-6 * E[0], t
    # the same stick/slip history as the event-driven reference path (Python, scipy's DOP853)
    from mbdsim.solvers import dynamic
    monkeypatch.setattr(dynamic, "USE_COMPILED", False)
    ref = mb.simulate(held_four_bar(), 1.6, output_step=0.05, rtol=1e-9)
    assert "(compiled)" not in ref.stats["method"]
    for n, e_ref in events(ref).items():
        e = [x for x in ev[n] if x[0] <= 1.6]
        assert [x[1:] for x in e_ref] == [x[1:] for x in e]
        assert np.allclose([x[0] for x in e_ref], [x[0] for x in e], rtol=1e-7, atol=0)


def five_bar(torque=0.005):
    """Five-bar (2 DOF: cranks 0.1 m on ground pivots 0.3 m apart, two 0.25 m couplers) at rest without
    gravity, pin friction with a preload of 0.02 N m in all five pins, a torque [N m] (None: none) on the first
    crank, by default below their capacity."""
    m = mb.Model("five_bar", gravity=(0, 0, 0))
    O1, O5 = np.zeros(3), np.array([0.3, 0.0, 0.0])
    A, C = O1 + 0.1 * np.array([np.cos(1.8), np.sin(1.8), 0]), O5 + 0.1 * np.array([np.cos(1.3), np.sin(1.3), 0])
    d = np.linalg.norm(C - A)
    ex = (C - A) / d
    B = A + 0.5 * d * ex + np.sqrt(0.25**2 - (0.5 * d) ** 2) * np.array([-ex[1], ex[0], 0.0])
    ang = lambda v: rz(np.arctan2(v[1], v[0]))  # noqa: E731
    links = [m.add_body(n, 0.5, (1e-4, 3e-3, 3e-3), position=(p + q) / 2, orientation=ang(q - p))
             for n, p, q in (("c1", O1, A), ("l1", A, B), ("l2", B, C), ("c2", O5, C))]
    z = (0, 0, 1)
    joints = [m.add_revolute("O1", m.ground, links[0], O1, z), m.add_revolute("A", links[0], links[1], A, z),
              m.add_revolute("B", links[1], links[2], B, z), m.add_revolute("C", links[2], links[3], C, z),
              m.add_revolute("O5", m.ground, links[3], O5, z)]
    for jt in joints:
        m.add_friction("f_" + jt.name, jt, MU_S, MU_D, pin_radius=0.01, preload=0.02)
    if torque is not None:
        m.add_torque("drive", links[0], (0, 0, torque))
    return m


def test_held_group_of_two_degrees_of_freedom_stays_at_rest_compiled():
    """Five pins stuck in a 2-DOF loop: three held locks each depend on both sticking ones, their shared
    capacity carried by the compiled path (tests/test_friction_held_loop.py: the breakaway); under a
    torque below it the loop stays at rest."""
    res = mb.simulate(five_bar(), 0.2, output_step=0.01)
    assert res.success, res.message
    assert "(compiled)" in res.stats["method"], res.stats["method"]
    for n in ("O1", "A", "B", "C", "O5"):
        assert res.friction_events("f_" + n) == [(0.0, "stick", 0.0)]
        assert np.max(np.abs(res.joint_velocity(n))) < 1e-10

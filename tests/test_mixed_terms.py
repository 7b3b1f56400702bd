"""Constraint equations of systems with rows the compiled kernel does not know (point-on-curve,
couplers; screw and constant-velocity rows beside them, compiled): the mixed evaluation (kernel for the rows it knows, the curve
point and the remaining rows added group by group) against the group-by-group evaluation of every
row, on random states away from the constraint manifold (tests/test_path.py holds the curve rows against finite
differences through the same entry point)."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.system.assemble import assemble_system
from mbdsim.system.equations import _terms_mixed, constraint_terms, constraint_terms_numpy


def _wheel_with_bead():
    """A bead on a spiral fixed on a wheel that turns on a revolute joint, plus a second body on a
    helix fixed to ground (rigid body on a curve: marker off its centre)."""
    spiral = mb.Curve(lambda s: (0.1 + 0.1 * s) * np.array([np.cos(s), np.sin(s), 0.0]), (0, 8))
    helix = mb.Curve(lambda s: np.array([0.4 * np.cos(s), 0.3 * np.sin(s), 0.2 * s]), (-1, 9))
    m = mb.Model("wheel", gravity=(0, -9.81, 0))
    wheel = m.add_body("wheel", 2.0, (0.1, 0.1, 0.2), angular_velocity=(0, 0, 3.0))
    m.add_revolute("axle", m.ground, wheel, (0, 0, 0), (0, 0, 1))
    bead = m.add_particle("bead", 0.3, position=spiral.point(0.5))
    m.add_point_on_curve("path", bead.add_marker("c"), wheel, spiral)
    P = helix.point(1.0)
    box = m.add_body("box", 1.0, (0.01, 0.02, 0.03), position=P + np.array([0.05, 0.0, 0.0]))
    m.add_point_on_curve("rail", box.add_marker("m", point=P), m.ground, helix)
    return m


def _screw_and_gears():
    m = mb.Model("mixed")
    m.add_body("nut", 1.0, inertia=(0.05, 0.05, 0.01), position=(0, 0, 0.1))
    m.add_screw("s", "ground", "nut", (0, 0, 0), (0, 0, 1), lead=0.01)
    m.add_body("g1", 1.0, inertia=(0.02, 0.02, 0.02), position=(1, 0, 0))
    m.add_body("g2", 1.0, inertia=(0.05, 0.05, 0.08), position=(1.15, 0, 0))
    m.add_revolute("p1", "ground", "g1", (1, 0, 0), (0, 0, 1))
    m.add_revolute("p2", "ground", "g2", (1.15, 0, 0), (0, 0, 1))
    m.add_gear("mesh", "p1", "p2", -0.5)
    return m


def _cv():
    beta = 0.4
    m = mb.Model("driveline")
    a_j = np.array([0.0, -np.sin(beta), np.cos(beta)])
    m.add_body("shaft1", 1.0, inertia=(0.1, 0.1, 0.02), position=(0, 0, -0.5))
    m.add_body("shaft2", 1.0, inertia=(0.1, 0.1, 0.02), position=0.5 * a_j)
    m.add_revolute("bearing1", "ground", "shaft1", (0, 0, -0.5), (0, 0, 1))
    m.add_constant_velocity("cv", "shaft1", "shaft2", (0, 0, 0), (0, 0, 1), a_j)
    m.add_parallel_axes("bearing2", "ground", "shaft2", a_j)
    m.add_motion("drive", "bearing1", velocity=2.0)
    return m


def _perturbed(sys, rng):
    q = np.array(sys.q0, dtype=float) + 0.05 * rng.standard_normal(sys.nq)
    for p in sys.p_idx:                      # unit quaternions, as the integrators keep them
        q[p] /= np.linalg.norm(q[p])
    return q, rng.standard_normal(sys.nv)


@pytest.mark.parametrize("build", [_wheel_with_bead, _screw_and_gears, _cv])
def test_mixed_terms_equal_the_numpy_reference(build):
    sys = assemble_system(build())
    assert sys.kernel_rows == (build is _cv)   # screw and CV rows are compiled; couplers and curves are not
    rng = np.random.default_rng(3)
    for t in (0.0, 0.37, 1.9):
        q, v = _perturbed(sys, rng)
        ref = constraint_terms_numpy(sys, q, v, t)
        got = constraint_terms(sys, q, v, t)
        mixed = _terms_mixed(sys, q, v, t, True)
        for name, a, b, c in zip(("phi", "phi_q", "nu", "gamma"), ref, got, mixed):
            scale = 1.0 + np.max(np.abs(a))
            assert np.max(np.abs(a - b)) < 1e-12 * scale, name
            assert np.max(np.abs(a - c)) < 1e-12 * scale, name
        assert np.max(np.abs(ref[0])) > 1e-3     # really off the manifold: rows not trivially zero

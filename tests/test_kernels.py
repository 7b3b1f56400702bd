"""The two paths through the one constraint-row implementation (`kernels.row_terms`) agree for every
row kind: the packed rows scattered into body-axes columns by the compiled `rows_kernel`, and the
group-by-group Rows (ground-axes rows from `kernels.ground_rows`) scattered by numpy.  Both are held
against finite differences in tests/test_core_jacobians.py; the frames, increment, qdot and inertial
kernels against rotation composition, differences and closed forms below."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.system import kernels
from mbdsim.system.assemble import assemble_system
from mbdsim.system.equations import _terms_compiled, constraint_terms_numpy
from mbdsim.system.frames import body_frames


def mixed_model():
    rng = np.random.default_rng(1)
    m = mb.Model("mix", gravity=(0, -9.81, 0))
    bs = [m.add_body(f"b{k}", 1.0, (1, 2, 3), position=rng.normal(size=3),
                     orientation=Rotation.random(random_state=k), angular_velocity=rng.normal(size=3),
                     velocity=rng.normal(size=3)) for k in range(5)]
    p = m.add_particle("p", 1.0, position=(0.3, 0.2, 0.1), velocity=(1, 2, 3))
    m.add_revolute("r", m.ground, bs[0], (0.1, 0.2, 0.3), (0.3, 0.4, 0.5))
    m.add_translational("tr", bs[0], bs[1], (0.5, 0.2, 0.3), (1, 0.4, 0.5))
    m.add_cylindrical("c", bs[1], bs[2], (0.5, 0.7, 0.3), (1, 0.4, -0.5))
    m.add_universal("u", bs[2], bs[3], (0.5, 0.7, 0.9), (1, 0, 0), (0, 1, 0))
    m.add_fixed("f", bs[3], bs[4], (0.2, 0.1, 0.0))
    m.add_spherical("s", bs[4], p, (0.3, 0.2, 0.1))
    m.add_planar("pl", bs[3], p, (0.3, 0.2, 0.1), (0, 0, 1))
    m.add_motion("m1", "r", displacement="0.3*sin(2*t)")
    m.add_motion("m2", "tr", displacement="0.1*t**2")
    m.add_motion("m3", "c", displacement="0.2*t", dof="rotation")
    return m


def test_packed_rows_match_group_rows():
    sys = assemble_system(mixed_model())
    rng = np.random.default_rng(2)
    for t in (0.0, 0.37, 1.9):
        q = sys.q0 + 0.05 * rng.normal(size=sys.nq)
        v = sys.v0 + rng.normal(size=sys.nv)
        for a, b in zip(_terms_compiled(sys, q, v, t, True), constraint_terms_numpy(sys, q, v, t, True)):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_frames_kernel_matches_numpy():
    sys = assemble_system(mixed_model())
    q, v = sys.q0 * 1.01, sys.v0 + 0.3
    a, b = body_frames(sys, q, v), body_frames(sys, q[None], v[None])
    for k in ("r", "A", "rd", "w"):
        np.testing.assert_allclose(getattr(a, k), getattr(b, k)[0], atol=1e-14)


def test_increment_kernel_matches_rotation_composition():
    """q (+) dx rotates each body by the body-axes rotation vector dx_w applied on the right."""
    from mbdsim.solvers.common import increment
    sys = assemble_system(mixed_model())
    rng = np.random.default_rng(3)
    for scale in (1.0, 1e-9):
        dx = scale * rng.normal(size=sys.nv)
        q = increment(sys, sys.q0, dx)
        np.testing.assert_allclose(q[sys.r_idx], sys.q0[sys.r_idx] + dx[sys.rd_idx], atol=1e-15)
        for p, p0, w in zip(q[sys.p_idx], sys.q0[sys.p_idx], dx[sys.w_idx]):
            R0 = Rotation.from_quat(np.roll(p0, -1))          # scalar-last for scipy
            expected = (R0 * Rotation.from_rotvec(w)).as_matrix()
            np.testing.assert_allclose(Rotation.from_quat(np.roll(p, -1)).as_matrix(), expected, atol=1e-14)


def test_qdot_kernel_is_the_derivative_of_the_increment():
    from mbdsim.solvers.common import increment, qdot
    sys = assemble_system(mixed_model())
    v = np.random.default_rng(4).normal(size=sys.nv)
    h = 1e-6
    fd = (increment(sys, sys.q0, h * v) - increment(sys, sys.q0, -h * v)) / (2 * h)
    np.testing.assert_allclose(qdot(sys, sys.q0, v), fd, atol=1e-9)


def test_inertial_forces_are_gravity_and_gyroscopic_terms():
    from mbdsim.system.dynamics import inertial_forces
    sys = assemble_system(mixed_model())
    fr = body_frames(sys, sys.q0, sys.v0 + 0.7)
    Q = inertial_forces(sys, fr)
    np.testing.assert_allclose(Q[sys.rd_idx], sys.mass[1:, None] * np.array([0, -9.81, 0]), atol=1e-13)
    for k, f in enumerate(sys.rigid_fid):
        wB = fr.A[f].T @ fr.w[f]
        np.testing.assert_allclose(Q[sys.w_idx[k]], -np.cross(wB, sys.inertia_B[f] @ wB), atol=1e-13)

"""Joint-coordinate fast path (system.jointtree, solvers.fasttree): trees of revolute, translational and
fixed joints integrated by the articulated-body algorithm, checked against the absolute-coordinate
equations of motion (KKT solve), closed forms and conservation."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.solvers import fastdyn, fasttree
from mbdsim.solvers.assembly import assemble_state
from mbdsim.system import compiled, jointtree
from mbdsim.system.assemble import assemble_system
from mbdsim.system.compiled import Work, compile_system
from mbdsim.system.equations import constraint_terms


def random_tree(seed=3, kinds=("revolute", "translational", "revolute", "fixed", "revolute", "translational",
                               "revolute"), branch=True):
    """A spatial tree: skew axes, rotated bodies with full inertia, initial velocities, a spring."""
    rng = np.random.default_rng(seed)
    m = mb.Model("tree", gravity=(0.3, -9.81, 1.1))
    prev, pts, bodies = m.ground, np.zeros(3), []
    for k, kind in enumerate(kinds):
        c = pts + rng.normal(size=3) * 0.3
        J = Rotation.random(random_state=seed + k).as_matrix()
        I = J @ np.diag(rng.uniform(0.12, 0.2, 3)) @ J.T   # principal moments meet the triangle inequality
        b = m.add_body(f"b{k}", rng.uniform(0.5, 2), inertia=I, position=c,
                       orientation=Rotation.random(random_state=k).as_matrix(),
                       velocity=rng.normal(size=3), angular_velocity=rng.normal(size=3))
        ax = rng.normal(size=3)
        jp = (pts + c) / 2
        parent = bodies[1] if branch and k == 4 else prev   # body 4 branches off body 1
        getattr(m, f"add_{kind}")(f"j{k}", parent, b, jp, *(() if kind == "fixed" else (ax / np.linalg.norm(ax),)))
        bodies.append(b)
        prev, pts = b, c
    m.add_spring_damper("s", (bodies[1], bodies[1].position), (bodies[-1], bodies[-1].position), 50.0, 2.0)
    return m, bodies


def _frames_scratch(nf):
    return np.zeros((nf, 3)), np.zeros((nf, 3, 3)), np.zeros((nf, 3)), np.zeros((nf, 3)), np.zeros((nf, 3)), \
        np.zeros((2, 3, 3))


def test_articulated_body_accelerations_equal_the_augmented_solve():
    """At a random joint state: ABA body accelerations = those of M vd + J^T lambda = F, J vd = c on the
    same (absolute) state, to round-off; the mapped state satisfies the constraints; round trip of the
    joint state through absolute coordinates."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m, _ = random_tree()
        sys_ = assemble_system(m)
        rep = assemble_state(sys_, sys_.q0, sys_.v0, 0.0)
    mode, tree = jointtree.tree_arrays(sys_, rep.rows, rep.q, rep.v)
    assert mode == 1
    nj = int((tree[7] >= 0).sum())
    y = jointtree.joint_state(sys_, tree, rep.q, rep.v)
    rng = np.random.default_rng(0)
    y[:nj] += rng.normal(size=nj) * 0.7
    y[nj:] += rng.normal(size=nj)
    cm = compile_system(sys_, rep.rows)
    a, w = cm.arrays(), Work.for_model(cm).arrays()
    nf = sys_.nbody + 1
    r, A, rd, ww, P, Rt = _frames_scratch(nf)
    fasttree.kinematics(tree, y, nj, r, A, rd, ww, P, Rt)
    F = np.zeros((nf, 6))
    fastdyn.loads_into(a, w, 0.0, y, r, A, rd, ww, F)
    tw = tuple(np.zeros(s) for s in ((nf, 6, 6), (nf, 6), (nf, 6), (nf, 6), (nf, 6), (nf, 6), nf, nf, (6, 6), 6))
    ydot = np.zeros(2 * nj)
    assert fasttree.aba(tree, y, nj, r, A, rd, ww, P, F, cm.mass, cm.inertia, tw, ydot)
    ymax = np.zeros(sys_.nq + sys_.nv)
    fasttree.to_maximal(tree, cm.p_idx, cm.r_idx, cm.rd_idx, cm.w_idx, cm.rigid_fid, r, A, rd, ww, ymax, ymax[:0])
    q, v = ymax[:sys_.nq], ymax[sys_.nq:]
    phi, J, nu, _ = constraint_terms(sys_, q, v, 0.0)
    assert np.abs(phi).max() < 1e-12 and np.abs(J @ v - nu).max() < 1e-12
    vd, lam = np.zeros(sys_.nv), np.zeros(sys_.nc)
    assert fastdyn.accelerations(a, w, 0.0, q, v, y, vd, lam) == 0   # loads read the joint state y
    acc = tw[5]
    for k in range(sys_.nbody):
        f, ad = k + 1, sys_.frame_v_adr[k + 1]
        assert np.allclose(acc[f, 3:], vd[ad:ad + 3], rtol=0, atol=1e-11)
        assert np.allclose(acc[f, :3], A[f] @ vd[ad + 3:ad + 6], rtol=0, atol=1e-11)
    y2 = np.zeros_like(y)
    fasttree.from_maximal(tree, nj, r, A, rd, ww, y2)
    d = y2 - y
    d[:nj] = (d[:nj] + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(d).max() < 1e-12


def test_tree_path_agrees_with_absolute_coordinates_and_conserves_energy():
    """The same spatial tree (no damping) in joint and in absolute coordinates: positions, reactions and
    accelerations agree to the tolerance; energy is conserved; Result.at between samples agrees."""
    res = {}
    for flag in (True, False):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            m, bodies = random_tree(seed=5, kinds=("revolute", "translational", "revolute", "revolute"),
                                    branch=False)
        m.forces["s"].damping = 0.0
        old = compiled.USE_TREE
        compiled.USE_TREE = flag
        try:
            res[flag] = (mb.simulate(m, 1.0, output_step=0.05, rtol=1e-11), bodies)
        finally:
            compiled.USE_TREE = old
    (a, ba), (b, bb) = res[True], res[False]
    assert a.success and b.success
    assert a.stats["formulation"].startswith("joint") and b.stats["formulation"].startswith("absolute")
    for x, y in zip(ba, bb):
        assert np.allclose(a.position(x), b.position(y), atol=1e-8)
        assert np.allclose(a.acceleration(x), b.acceleration(y), atol=1e-6)
        assert np.allclose(a.at([0.123, 0.777]).velocity(x), b.at([0.123, 0.777]).velocity(y), atol=1e-7)
    assert np.allclose(a.reaction_force("j2"), b.reaction_force("j2"), atol=1e-6)
    E = a.kinetic_energy() + a.potential_energy()
    assert np.abs(E - E[0]).max() < 1e-8 * max(1.0, np.abs(E).max())


def test_spinning_disc_turns_and_continuous_euler_parameters():
    """A disc spinning freely on a skew revolute (no gravity) turns at constant rate: angle = w t over many
    turns; its Euler parameters never jump between samples (continuous through 180 degrees)."""
    m = mb.Model("disc")
    ax = np.array([1.0, 2.0, 2.0]) / 3
    w0 = 7.0
    disc = m.add_body("disc", 1.0, inertia=(0.02, 0.02, 0.04), position=(0, 0, 0),
                      angular_velocity=w0 * ax)
    pin = m.add_revolute("pin", m.ground, disc, (0, 0, 0), ax)
    res = mb.simulate(m, 3.0, output_step=0.05)
    assert res.stats["formulation"].startswith("joint coordinates")
    t = res.time
    assert np.allclose(res.joint_velocity(pin), w0, atol=1e-9)
    assert np.allclose(res.joint_coordinate(pin), w0 * t, atol=1e-7)
    p = res.q[:, 3:7]
    assert np.min(np.sum(p[1:] * p[:-1], axis=1)) > 0.9
    R = res.orientation(disc)
    assert np.allclose(R[-1], Rotation.from_rotvec(ax * w0 * t[-1]).as_matrix(), atol=1e-7)


@pytest.mark.parametrize("what", ["loop", "motion", "spherical", "welded"])
def test_models_outside_the_tree_path_keep_absolute_coordinates(what):
    m = mb.Model("m", gravity=(0, -9.81, 0))
    a = m.add_body("a", 1.0, inertia=(0.01, 0.01, 0.01), position=(0.5, 0, 0))
    j = m.add_revolute("ja", m.ground, a, (0, 0, 0), (0, 0, 1)) if what != "spherical" else \
        m.add_spherical("ja", m.ground, a, (0, 0, 0))
    if what == "loop":
        b = m.add_body("b", 1.0, inertia=(0.01, 0.01, 0.01), position=(1.0, 0, 0))
        m.add_revolute("jb", a, b, (1.0, 0, 0), (0, 0, 1))
        m.add_translational("jc", m.ground, b, (1.0, 0, 0), (1, 0, 0))
    if what == "motion":
        m.add_motion("drive", j, displacement="sin(t)")
    if what == "welded":
        m.joints.clear()
        m.add_fixed("weld", m.ground, a, (0, 0, 0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sys_ = assemble_system(m)
        rep = assemble_state(sys_, sys_.q0, sys_.v0, 0.0)
    assert jointtree.tree_arrays(sys_, rep.rows, rep.q, rep.v)[0] == 0

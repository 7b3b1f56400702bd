"""Issue 35: assembly proper of large models without dense matrices (solvers.assembly_sparse).

In child processes under a 4 GB address-space limit, with the dense route switched off (DENSE_BYTES = 0:
it would refuse), so that success proves the sparse route took them:
- a 10,000-body chain drawn with gaps, every joint given an initial angle and rate, against the closed
  form of the chain's geometry and velocities (link k at the sum of the first k+1 angles);
- a 2,000-body ladder of spherical joints with 20 closed loops, one drawn with its rungs short (gaps),
  one drawn hanging and simulated: each top pin carries half the weight of the ladder (symmetry).
- a 3,000-body chain with a gear and held ball joints (rotation vectors and rates) under a 1.5 GB
  limit, against the closed form of its attitudes, positions and velocities.
In process: small models give the same assembled state on the sparse and the dense route, among them
couplers, gears, user constraints, a point-on-curve loop, friction lock rows and held rotation vectors
of spherical, universal and constant-velocity joints (the sparse run with the dense route refusing)."""
import json
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.solvers import assembly_sparse

MODELS = textwrap.dedent('''
    import numpy as np, mbdsim as mb

    def gapped_chain(N, theta=None, omega=None, gap=0.1):
        """Links of 1 m along x drawn `gap` apart, joined by revolutes (z) between markers at their ends;
        joint k (initial angle theta[k], rate omega[k]) between link k-1 (or a ground marker at the
        origin) and link k."""
        m = mb.Model("gapped", gravity=(0.0, -9.81, 0.0))
        prev = m.ground.add_marker("m0", (0.0, 0.0, 0.0))
        for k in range(N):
            x0 = k * (1.0 + gap) + gap
            b = m.add_body(f"b{k}", 1.0, inertia=(0.01, 0.1, 0.1), position=(x0 + 0.5, 0.0, 0.0))
            m.add_revolute(f"j{k}", prev, b.add_marker("a", (x0, 0.0, 0.0)),
                           initial_displacement=None if theta is None else float(theta[k]),
                           initial_velocity=None if omega is None else float(omega[k]))
            prev = b.add_marker("b", (x0 + 1.0, 0.0, 0.0))
        return m

    def ladder(n, every, gap=0.0, kind="spherical"):
        """Two rails of n links hanging from ground at x = 0 and 1, a rung (1 kg) every `every` links
        joined to both rails, its right end drawn `gap` short: closed loops (spherical joints: none
        redundant; revolutes (z): planar loops, 3 redundant rows each)."""
        m = mb.Model("ladder", gravity=(0.0, -9.81, 0.0))
        add = (lambda name, a, b, p: m.add_spherical(name, a, b, p)) if kind == "spherical" else \\
            (lambda name, a, b, p: m.add_revolute(name, a, b, p, (0, 0, 1)))
        for side, x in (("a", 0.0), ("b", 1.0)):
            prev = m.ground
            for k in range(n):
                b = m.add_body(f"{side}{k}", 1.0, inertia=(0.01, 0.01, 0.01), position=(x, -0.5 - k, 0.0))
                add(f"{side}j{k}", prev, b, (x, -float(k), 0.0))
                prev = b
        for k in range(every - 1, n, every):
            r = m.add_body(f"r{k}", 1.0, inertia=(0.01, 0.1, 0.1), position=(0.5, -0.5 - k, 0.0))
            add(f"ra{k}", f"a{k}", r, (0.0, -0.5 - k, 0.0))
            mi = r.add_marker("e", (1.0 - gap, -0.5 - k, 0.0))
            mj = m.bodies[f"b{k}"].add_marker("r", (1.0, -0.5 - k, 0.0))
            if kind == "spherical":
                m.add_spherical(f"rb{k}", mi, mj)
            else:
                m.add_revolute(f"rb{k}", mi, mj)
        return m
''')
exec(MODELS)   # the same model builders in process

CHILD = MODELS + textwrap.dedent('''
    import json, resource, sys, time, warnings
    resource.setrlimit(resource.RLIMIT_AS, (4 * 2**30, 4 * 2**30))
    from mbdsim.solvers import assembly
    assembly.DENSE_BYTES = 0   # the dense route refuses everything: only the sparse one can succeed
    out, t0 = {}, time.perf_counter()
    if sys.argv[1] == "chain":
        N = 10_000
        rng = np.random.default_rng(7)
        th, om = rng.uniform(-0.3, 0.3, N), rng.uniform(-1.0, 1.0, N)
        model = gapped_chain(N, th, om)
        with warnings.catch_warnings():
            warnings.simplefilter("error")   # nothing held may be changed
            rep = mb.assemble(model)
        s = rep.system
        r, p = rep.q[s.r_idx], rep.q[s.p_idx]
        rd, w = rep.v[s.rd_idx], rep.v[s.w_idx]
        phi = np.unwrap(2 * np.arctan2(p[:, 3], p[:, 0]))   # each link turned about z only
        d = np.stack([np.cos(phi), np.sin(phi), 0 * phi], -1)
        # closed form: link k at angle sum(th[:k+1]), left end at the sum of the links before it
        phi_ref = np.cumsum(th)
        d_ref = np.stack([np.cos(phi_ref), np.sin(phi_ref), 0 * phi_ref], -1)
        left = np.concatenate([np.zeros((1, 3)), np.cumsum(d_ref, 0)[:-1]])
        W = np.cumsum(om)   # absolute angular velocities [rad/s]
        perp = np.stack([-d_ref[:, 1], d_ref[:, 0], 0 * phi_ref], -1)
        v_left = np.concatenate([np.zeros((1, 3)), np.cumsum(W[:, None] * perp, 0)[:-1]])
        out.update(
            gap=float(np.abs((r[:-1] + 0.5 * d[:-1]) - (r[1:] - 0.5 * d[1:])).max()),   # joints open
            gap0=float(np.abs(r[0] - 0.5 * d[0]).max()),
            joint=float(np.abs(np.diff(np.concatenate([[0.0], phi])) - th).max()),
            off_plane=float(np.abs(r[:, 2]).max() + np.abs(p[:, 1:3]).max()),
            pos=float(np.abs(r - (left + 0.5 * d_ref)).max()),
            vel=float(np.abs(rd - (v_left + 0.5 * W[:, None] * perp)).max()),
            omega=float(np.abs(w[:, 2] - W).max() + np.abs(w[:, :2]).max()),
            residual=rep.residual, dof=rep.dof, nv=s.nv, moved=len(rep.moved))
    else:
        n, every = 1000, 50
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            rep = mb.assemble(ladder(n, every, gap=0.05))
        s, fr = rep.system, None
        from mbdsim.system.frames import body_frames
        fr = body_frames(s, rep.q)
        rungs = [k for k in range(every - 1, n, every)]
        ends = []
        for k in rungs:   # the rung's short end and the rail point it is joined to, in ground
            fe, fb = s.fid[s.model.bodies[f"r{k}"]], s.fid[s.model.bodies[f"b{k}"]]
            e = fr.r[fe] + fr.A[fe] @ np.array([0.5 - 0.05, 0.0, 0.0])
            pb = fr.r[fb]   # (the rail's marker is at its CM)
            ends.append(float(np.abs(e - pb).max()))
        out.update(rung_gap=max(ends), residual=rep.residual, dof=rep.dof, nbody=s.nbody, nv=s.nv, nc=s.nc,
                   moved=len(rep.moved), t_assemble=time.perf_counter() - t0)
        hanging = ladder(n, every)
        res = mb.simulate(hanging, 0.01, 0.005)
        out.update(success=bool(res.success), F_a=res.reaction_force("aj0", on="a0")[:, 1].tolist(),
                   F_b=res.reaction_force("bj0", on="b0")[:, 1].tolist(),
                   still=float(np.abs(res.q - res.q[:1]).max()),
                   weight=(2 * n + len(rungs)) * 9.81)
    out["time"] = time.perf_counter() - t0
    out["rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out))
''')


def _child(kind):
    proc = subprocess.run([sys.executable, "-c", CHILD, kind], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_10000_gapped_chain_with_joint_values_matches_the_closed_form():
    out = _child("chain")
    assert out["nv"] == 60_000 and out["dof"] == 10_000 and out["moved"] == 10_000
    assert out["residual"] < 1e-10 and out["gap"] < 1e-10 and out["gap0"] < 1e-10   # joints closed
    assert out["joint"] < 1e-10                      # every joint angle held
    assert out["off_plane"] < 1e-10
    assert out["pos"] < 1e-8 and out["vel"] < 1e-8   # closed form: chain 10 km long, rates summed
    assert out["omega"] < 1e-9
    assert out["rss_mb"] < 4096 and out["time"] < 200.0


def test_2000_body_ladder_with_loops_assembles_and_runs():
    out = _child("ladder")
    assert out["nbody"] == 2020 and out["nc"] == (2000 + 40) * 3
    assert out["dof"] == out["nv"] - out["nc"]       # 3D loops: no row dependent
    assert out["residual"] < 1e-10 and out["rung_gap"] < 1e-10 and out["moved"] > 0
    assert out["success"]
    # hanging at rest: each top pin carries half the ladder (symmetry), nothing moves
    assert out["F_a"] == pytest.approx([out["weight"] / 2] * 3, rel=1e-9)
    assert out["F_b"] == pytest.approx([out["weight"] / 2] * 3, rel=1e-9)
    assert out["still"] < 1e-9
    assert out["rss_mb"] < 4096 and out["time"] < 200.0


def _both_routes(make, monkeypatch):
    """(dense report, sparse report, their warnings) of fresh models from make()."""
    reps, caught = [], []
    for limit in (10**9, 0):
        monkeypatch.setattr(assembly_sparse, "SPARSE_NV", limit)
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            reps.append(mb.assemble(make()))
        caught.append(sorted({type(x.message).__name__ for x in w}))
    return reps, caught


@pytest.mark.parametrize("case", ["chain", "chain drawn", "ladder3d", "ladder planar", "given body velocities",
                                  "ladder given velocities"])
def test_small_models_same_state_on_both_routes(case, monkeypatch):
    rng = np.random.default_rng(3)
    th, om = rng.uniform(-0.6, 0.6, 7), rng.uniform(-1.0, 1.0, 7)
    make = {"chain": lambda: gapped_chain(7, th, om), "chain drawn": lambda: gapped_chain(7),
            "ladder3d": lambda: ladder(6, 3, gap=0.05),
            "ladder planar": lambda: ladder(6, 3, gap=0.05, kind="revolute"),
            "given body velocities": lambda: _with_velocities(gapped_chain(4, th[:4], None)),
            "ladder given velocities": lambda: _with_velocities(ladder(4, 2, gap=0.05))}[case]
    (dense, sparse), (wd, ws) = _both_routes(make, monkeypatch)
    assert dense.residual < 1e-12 and sparse.residual < 1e-12
    assert np.abs(dense.q - sparse.q).max() < 1e-10 and np.abs(dense.v - sparse.v).max() < 1e-10
    assert np.array_equal(dense.rows, sparse.rows) and dense.dof == sparse.dof
    assert wd == ws and dense.changed == sparse.changed == []
    assert list(dense.moved) == list(sparse.moved)
    if case == "ladder planar":
        assert wd == ["RedundantConstraintWarning"] and len(sparse.rows) == sparse.system.nc - 6


def _with_velocities(m):
    """Every body's velocity and angular velocity given (zero): held rows dependent on the joints and
    on each other, consistent."""
    for b in list(m.bodies.values())[1:]:
        b.velocity_given = b.angular_velocity_given = True
    return m


def test_inconsistent_held_values_warned_on_the_sparse_route(monkeypatch):
    """A joint rate and a body's angular velocity that contradict each other: the sparse route holds the
    joint's (the first given), changes the body's and says so, as the dense route warns."""
    monkeypatch.setattr(assembly_sparse, "SPARSE_NV", 0)
    m = gapped_chain(3, None, [0.5, 0.0, 0.0])
    m.bodies["b0"].angular_velocity = np.array([0.0, 0.0, 2.0])
    m.bodies["b0"].angular_velocity_given = True
    with pytest.warns(mb.InitialConditionWarning, match="body 'b0' angular_velocity given"):
        rep = mb.assemble(m)
    assert rep.v[rep.system.w_idx][0, 2] == pytest.approx(0.5, abs=1e-12)


def test_over_driven_four_bar_named_on_the_sparse_route(monkeypatch):
    """The sparse route drops rows it finds dependent and fails to close the loop: the dense route (the
    model being small enough) then names the over-driving motions, as without the sparse route."""
    sys.path.insert(0, __file__.rsplit("/", 1)[0])
    from test_marker_joints import four_bar
    monkeypatch.setattr(assembly_sparse, "SPARSE_NV", 0)
    model, _, _ = four_bar(offset=(0, 0, 0), turn=0.0, rocker_motion=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(mb.AssemblyError, match="over-driven") as err:
            mb.assemble(model)
    assert "drive" in err.value.joints and "rocker_drive" in err.value.joints


# ------------------------------------------------------------------------------ rows beyond the kernel's
def _chain(kinds, held=None, gap=0.1, gravity=(0.0, -9.81, 0.0)):
    """Links of 1 m along x drawn `gap` apart, joint k of kind kinds[k] (revolute and cylindrical about z,
    universal with axes z, y; constant velocity along x) between markers at the link ends; held[k]:
    the joint's initial_displacement / initial_velocity."""
    m = mb.Model("chain", gravity=gravity)
    prev = m.ground.add_marker("m0", (0.0, 0.0, 0.0))
    for k, kind in enumerate(kinds):
        x0 = k * (1.0 + gap) + gap
        b = m.add_body(f"b{k}", 1.0, inertia=(0.01, 0.1, 0.1), position=(x0 + 0.5, 0.0, 0.0))
        mi, mj = prev, b.add_marker("a", (x0, 0.0, 0.0))
        kw = (held or {}).get(k, {})
        if kind in ("universal", "constant_velocity"):
            mi = mi.body.add_marker(f"u{k}", mi.point, orientation=_axes(kind, True))
            mj = b.add_marker(f"v{k}", mj.point, orientation=_axes(kind, False))
            j = getattr(m, "add_" + kind)(f"j{k}", mi, mj)
            for f, x in kw.items():
                setattr(j, f, np.asarray(x, dtype=float))
        else:
            getattr(m, "add_" + kind)(f"j{k}", mi, mj, **kw)
        prev = b.add_marker("b", (x0 + 1.0, 0.0, 0.0))
    return m


def _axes(kind, first):
    """Marker axes (columns x, y, z in ground) of a universal joint (z axes: ground z, then y) or a
    constant-velocity joint (z axes both along the links, x along the bend axis z)."""
    if kind == "universal":
        return np.eye(3) if first else np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    return np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])


def _sparse_forced(make, monkeypatch):
    """(dense report, sparse report, warnings of each) of fresh models: the sparse run with the dense
    route refusing everything (DENSE_BYTES = 0), so that it cannot fall back."""
    from mbdsim.solvers import assembly
    reps, caught = [], []
    for limit, dense_bytes in ((10**9, assembly.DENSE_BYTES), (0, 0)):
        monkeypatch.setattr(assembly_sparse, "SPARSE_NV", limit)
        monkeypatch.setattr(assembly, "DENSE_BYTES", dense_bytes)
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            reps.append(mb.assemble(make()))
        caught.append(sorted({type(x.message).__name__ for x in w}))
    return reps, caught


RNG = np.random.default_rng(11)
SPH = {k: dict(initial_displacement=RNG.uniform(-0.5, 0.5, 3), initial_velocity=RNG.uniform(-1, 1, 3))
       for k in range(5)}


def _geared(kind):
    """Revolute chain with joint 0 held, joint 1 tied to it by a gear, a rack-and-pinion coupler (a
    translational joint's slide to a revolute's angle) or a user constraint."""
    def make():
        kinds = ["revolute", "revolute", "revolute", "translational" if kind == "coupler" else "revolute"]
        m = _chain(kinds, {0: dict(initial_displacement=0.3, initial_velocity=0.5)})
        if kind == "gear":
            m.add_gear("g", "j0", "j1", -2.0)
        elif kind == "coupler":
            m.add_coupler("rack", "j2", "j3", 0.2)
            m.joints["j2"].initial_displacement = np.array([0.4])
        else:
            m.add_user_constraint("u", "sin(j0) - 0.5*j1 + 0.1*j2")
        return m
    return make


def _on_curve():
    """A chain of 3 whose last link's tip is held on a circle on ground (a loop through the curve
    parameter), drawn 0.4 m off the circle (the rows independent as drawn: the tangent there is along
    the chain)."""
    m = _chain(["revolute", "spherical", "spherical"], {0: dict(initial_velocity=0.4)})
    circle = mb.Curve(lambda s: [3.3 + 0.5 * np.cos(s), 0.1 + 0.5 * np.sin(s), 0.0], (-4.0, 4.0),
                      d1=lambda s: [-0.5 * np.sin(s), 0.5 * np.cos(s), 0.0],
                      d2=lambda s: [-0.5 * np.cos(s), -0.5 * np.sin(s), 0.0])
    m.add_point_on_curve("path", m.bodies["b2"].markers["b"], m.ground, circle)
    return m


def _with_friction():
    m = _chain(["revolute", "translational", "revolute"], {0: dict(initial_displacement=0.2)})
    m.add_friction("f1", "j1", 0.3, 0.2)
    m.add_friction("f2", "j2", 0.3, 0.2, pin_radius=0.01)
    return m


CASES = {
    "spherical held": lambda: _chain(["spherical"] * 5, SPH),
    "spherical loop held": lambda: _with_rung(_chain(["spherical"] * 4, {1: SPH[1], 2: SPH[2]})),
    "universal held": lambda: _chain(["universal", "revolute", "universal"],
                                     {0: dict(initial_displacement=[0.0, 0.0, 0.4], initial_velocity=[0, 0, 0.7]),
                                      1: dict(initial_displacement=-0.2),
                                      2: dict(initial_displacement=[0.0, 0.3, 0.0], initial_velocity=[0, -0.5, 0])}),
    "cv held": lambda: _chain(["spherical", "constant_velocity"],
                              {1: dict(initial_displacement=[0.0, 0.0, 0.3], initial_velocity=[0.0, 0.0, 0.6])}),
    "gear": _geared("gear"), "coupler": _geared("coupler"), "user constraint": _geared("user"),
    "point on curve": _on_curve, "friction": _with_friction,
}


def _with_rung(m):
    """A link joined to the chain's tip and to ground by spherical joints: a closed loop (3D)."""
    r = m.add_body("rung", 1.0, inertia=(0.01, 0.1, 0.1), position=(4.4, -0.8, 0.0))
    m.add_spherical("ra", m.bodies["b3"].markers["b"], r.add_marker("e", (4.4, -0.05, 0.0)))
    m.add_spherical("rb", r.add_marker("f", (4.4, -1.55, 0.0)), m.ground.add_marker("g", (4.4, -1.6, 0.0)))
    return m


@pytest.mark.parametrize("case", list(CASES))
def test_sparse_route_carries_couplers_paths_friction_and_rotation_vectors(case, monkeypatch):
    """Each kind of row beyond the kernel's (couplers, gears, user constraints, the curve parameter of a
    point-on-curve constraint, friction lock rows) and the held rotation vectors of spherical,
    universal and constant-velocity joints: the sparse route (the dense one refusing) gives the dense
    route's state to round-off, every held value held."""
    (dense, sparse), (wd, ws) = _sparse_forced(CASES[case], monkeypatch)
    assert dense.residual < 1e-12 and sparse.residual < 1e-12
    assert np.abs(dense.q - sparse.q).max() < 1e-12 and np.abs(dense.v - sparse.v).max() < 1e-12
    assert np.array_equal(dense.rows, sparse.rows) and dense.dof == sparse.dof
    assert wd == ws == [] and dense.changed == sparse.changed == []
    assert list(dense.moved) == list(sparse.moved) and len(sparse.moved)
    s = sparse.system
    for jt in s.model.joints.values():   # the held values are met (the dense route's measure of them)
        from mbdsim.solvers.held import joint_values
        x, rate, _, _, _ = joint_values(s, jt, sparse.q, sparse.v)
        for given, got in ((jt.initial_displacement, x), (jt.initial_velocity, rate)):
            if given is not None:
                assert np.abs(np.asarray(got) - given).max() < 1e-12, jt.name


GEARED = textwrap.dedent('''
    import json, resource, sys, warnings
    import numpy as np
    resource.setrlimit(resource.RLIMIT_AS, (1536 * 2**20, 1536 * 2**20))   # one dense phi_q alone: 1.3 GB
    import mbdsim as mb
    from scipy.spatial.transform import Rotation
    from mbdsim.solvers import assembly
    assembly.DENSE_BYTES = 0   # the dense route refuses everything: only the sparse one can succeed
    N, gap = 3000, 0.1
    rng = np.random.default_rng(5)
    th, om = rng.uniform(-0.3, 0.3, (N, 3)), rng.uniform(-1.0, 1.0, (N, 3))
    m = mb.Model("geared", gravity=(0.0, -9.81, 0.0))
    prev = m.ground.add_marker("m0", (0.0, 0.0, 0.0))
    for k in range(N):
        x0 = k * (1.0 + gap) + gap
        b = m.add_body(f"b{k}", 1.0, inertia=(0.01, 0.1, 0.1), position=(x0 + 0.5, 0.0, 0.0))
        a = b.add_marker("a", (x0, 0.0, 0.0))
        if k == 0:
            m.add_revolute("j0", prev, a, initial_displacement=0.3, initial_velocity=0.5)
        elif k == 1:
            m.add_revolute("j1", prev, a)
        else:
            m.add_spherical(f"j{k}", prev, a, initial_displacement=th[k], initial_velocity=om[k])
        prev = b.add_marker("b", (x0 + 1.0, 0.0, 0.0))
    m.add_gear("g", "j0", "j1", -2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # nothing held may be changed
        rep = mb.assemble(m)
    s = rep.system
    # closed form: attitudes A_k (joint 1 at -2 x 0.3 rad about z by the gear, then each ball joint's
    # rotation vector in the link before), angular velocities W_k (ground), left ends P_k and their
    # velocities VP_k
    Rz = lambda a: Rotation.from_rotvec([0.0, 0.0, a]).as_matrix()
    A, W = np.zeros((N, 3, 3)), np.zeros((N, 3))
    A[0], W[0] = Rz(0.3), [0.0, 0.0, 0.5]
    A[1], W[1] = A[0] @ Rz(-0.6), W[0] + A[0] @ [0.0, 0.0, -1.0]
    R = Rotation.from_rotvec(th).as_matrix()
    for k in range(2, N):
        A[k], W[k] = A[k - 1] @ R[k], W[k - 1] + A[k - 1] @ om[k]
    e = A[:, :, 0]
    P = np.concatenate([np.zeros((1, 3)), np.cumsum(e, 0)[:-1]])
    VP = np.concatenate([np.zeros((1, 3)), np.cumsum(np.cross(W, e), 0)[:-1]])
    r, p, rd, wB = rep.q[s.r_idx], rep.q[s.p_idx], rep.v[s.rd_idx], rep.v[s.w_idx]
    vref = VP + 0.5 * np.cross(W, e)
    print(json.dumps(dict(
        pos=float(np.abs(r - (P + 0.5 * e)).max()),
        att=float(np.abs(Rotation.from_quat(p[:, [1, 2, 3, 0]]).as_matrix() - A).max()),
        vel=float(np.abs(rd - vref).max() / np.abs(vref).max()),
        omega=float(np.abs(np.einsum("kji,kj->ki", A, W) - wB).max() / np.abs(W).max()),
        psi=rep.q[s.aux_q_idx].tolist(), psid=rep.v[s.aux_v_idx].tolist(), residual=rep.residual,
        dof=rep.dof, nv=s.nv, nc=s.nc)))
''')


def test_3000_body_chain_with_a_gear_and_held_ball_joints_matches_the_closed_form():
    """A 3,000-body chain drawn with gaps: two revolutes tied by a gear (ratio -2, the first held at
    0.3 rad and 0.5 rad/s), then ball joints each given a rotation vector and a relative angular
    velocity; assembled in a child process under a 1.5 GB address-space limit (one dense phi_q would be
    1.3 GB) with the dense route refusing, against the closed form of the chain."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", GEARED], capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["nv"] == 6 * 3000 + 2 and out["nc"] == 2 * 5 + 2998 * 3 + 3 and out["dof"] == out["nv"] - out["nc"]
    assert out["residual"] < 1e-12
    assert out["psi"] == pytest.approx([0.3, -0.6], abs=1e-14) and out["psid"] == pytest.approx([0.5, -1.0], abs=1e-12)
    assert out["pos"] < 1e-10 and out["att"] < 1e-12   # 3.3 km of chain
    assert out["vel"] < 1e-12 and out["omega"] < 1e-12

"""Core engine, must-show 6 (part 1): every joint type's constraint equations against finite differences.

For each joint type and body combination (rigid-rigid, ground-rigid, rigid-ground, rigid-particle,
particle pairs for the spherical joint) and every motion driver (rotation, translation, cylindrical
both), at a generic configuration off the constraint manifold:
- phi_q against 5-point central differences of phi along each velocity direction, with the
  configuration moved by `solvers.common.increment` (CM translation, body-axes rotation vector);
- nu (= -phi_t) and gamma along the curve q(s) = q (+) (s v + s^2/2 vd), whose velocity variables at
  s = 0 are v and their derivatives vd: d phi/ds = phi_q v - nu, d^2 phi/ds^2 = phi_q vd - gamma.
Each joint also leaves exactly the motions it should (its kinematic null space).
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.solvers.common import increment
from mbdsim.system import assemble_system, equations

# the dispatching entry point (packed compiled rows) and the group-by-group rows scattered by numpy
IMPLS = {"dispatch": equations.constraint_terms,
         "numpy": getattr(equations, "constraint_terms_numpy", equations.constraint_terms)}
constraint_terms = equations.constraint_terms

KINDS = ["revolute", "translational", "cylindrical", "spherical", "universal", "planar", "fixed"]
ROWS_RIGID = {"revolute": 5, "translational": 5, "cylindrical": 4, "spherical": 3, "universal": 4,
              "planar": 3, "fixed": 6}
ROWS_PARTICLE_J = {"revolute": 3, "translational": 2, "cylindrical": 2, "spherical": 3, "universal": 3,
                   "planar": 1, "fixed": 3}
POINT = np.array([0.3, -0.2, 0.5])
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
AXIS_J = np.cross(AXIS, [0.0, 0.0, 1.0])
AXIS_J /= np.linalg.norm(AXIS_J)


def add_joint(model, kind, bi, bj, name="j"):
    if kind == "spherical":
        return model.add_spherical(name, bi, bj, POINT)
    if kind == "universal":
        return model.add_universal(name, bi, bj, POINT, AXIS, AXIS_J)
    if kind == "planar":
        return model.add_planar(name, bi, bj, POINT, AXIS)
    if kind == "fixed":
        return model.add_fixed(name, bi, bj, POINT)
    return getattr(model, f"add_{kind}")(name, bi, bj, POINT, AXIS)


def make_body(model, name, particle, seed):
    rng = np.random.default_rng(seed)
    pos = rng.normal(size=3)
    if particle:
        return model.add_particle(name, 1.0, position=pos)
    return model.add_body(name, 1.0, inertia=(0.1, 0.2, 0.3), position=pos,
                          orientation=Rotation.from_rotvec(rng.normal(size=3)))


def build(kind, pair):
    """pair: 'rigid-rigid', 'ground-rigid', 'rigid-ground', 'rigid-particle', 'particle-particle',
    'particle-rigid' (spherical only)."""
    model = mb.Model("jac")
    names = pair.split("-")
    bodies = [model.ground if n == "ground" else make_body(model, f"b{k}", n == "particle", 10 + k)
              for k, n in enumerate(names)]
    jt = add_joint(model, kind, *bodies)
    return model, jt


def fd(f, h, order):
    """5-point central difference of f(s) at s = 0 (first or second derivative)."""
    fm2, fm1, f0, f1, f2 = (np.asarray(f(k * h)) for k in (-2, -1, 0, 1, 2))
    if order == 1:
        return (fm2 - 8 * fm1 + 8 * f1 - f2) / (12 * h)
    return (-fm2 + 16 * fm1 - 30 * f0 + 16 * f1 - f2) / (12 * h * h)


def check_equations(model, t0=0.7, seed=1, impl="dispatch"):
    """phi_q, nu and gamma of the whole model against finite differences at a perturbed state."""
    constraint_terms = IMPLS[impl]
    sys = assemble_system(model)
    rng = np.random.default_rng(seed)
    q = increment(sys, sys.q0, 0.2 * rng.normal(size=sys.nv))          # off the manifold, generic
    v, vd = rng.normal(size=sys.nv), rng.normal(size=sys.nv)
    phi, J, nu, gamma = constraint_terms(sys, q, v, t0)
    assert phi.shape == (sys.nc,) and J.shape == (sys.nc, sys.nv)
    phi_of = lambda qq, t: constraint_terms(sys, qq, np.zeros(sys.nv), t, jacobian=False)[0]  # noqa: E731
    J_fd = np.stack([fd(lambda s: phi_of(increment(sys, q, s * np.eye(sys.nv)[k]), t0), 1e-3, 1)
                     for k in range(sys.nv)], -1)
    assert np.allclose(J, J_fd, rtol=0, atol=1e-8), np.abs(J - J_fd).max()
    curve = lambda s: phi_of(increment(sys, q, s * v + 0.5 * s * s * vd), t0 + s)  # noqa: E731
    assert np.allclose(fd(curve, 1e-3, 1), J @ v - nu, rtol=0, atol=1e-8)
    assert np.allclose(fd(curve, 2e-3, 2), J @ vd - gamma, rtol=0, atol=2e-7)
    # gamma is f''(t) of the drivers minus a term quadratic in the velocities
    d2 = _driver_d2(sys, t0)
    assert np.allclose(constraint_terms(sys, q, 2 * v, t0)[3] - d2, 4 * (gamma - d2), rtol=0, atol=1e-9)
    return sys


def _driver_d2(sys, t):
    """Driver f''(t) contribution to gamma (zero for joint rows)."""
    out = np.zeros(sys.nc)
    for m in sys.model.motions.values():
        out[sys.owner_rows[m.name]] = m.function.d2(t)
    return out


PAIRS = ([(k, "rigid-rigid") for k in KINDS] + [(k, "ground-rigid") for k in KINDS]
         + [(k, "rigid-ground") for k in KINDS] + [(k, "rigid-particle") for k in KINDS]
         + [("spherical", "particle-particle"), ("spherical", "particle-rigid"), ("revolute", "ground-particle")])


@pytest.mark.parametrize("impl", sorted(IMPLS))
@pytest.mark.parametrize("kind,pair", PAIRS)
def test_joint_jacobian_nu_gamma_against_finite_differences(kind, pair, impl):
    model, jt = build(kind, pair)
    sys = check_equations(model, impl=impl)
    if pair.endswith("-particle"):
        assert sys.nc == ROWS_PARTICLE_J[kind]
    else:
        assert sys.nc == (3 if pair.startswith("particle") else ROWS_RIGID[kind])
    # the joint is satisfied in the configuration it was defined in
    phi0 = constraint_terms(sys, sys.q0, sys.v0, 0.0)[0]
    assert np.abs(phi0).max() < 1e-12


DRIVEN = [("revolute", "rotation"), ("translational", "translation"), ("cylindrical", "rotation"),
          ("cylindrical", "translation")]


@pytest.mark.parametrize("kind,dof", DRIVEN)
@pytest.mark.parametrize("pair", ["rigid-rigid", "ground-rigid", "rigid-ground"])
@pytest.mark.parametrize("how", ["displacement", "velocity", "acceleration"])
@pytest.mark.parametrize("impl", sorted(IMPLS))
def test_driver_rows_against_finite_differences(kind, dof, pair, how, impl):
    model, jt = build(kind, pair)
    spec = {"displacement": "0.3*sin(2*t) + 0.1*t**2", "velocity": lambda t: 0.6 * np.cos(2 * t) + 0.2 * t,
            "acceleration": "-1.2*sin(2*t) + 0.2"}[how]
    model.add_motion("m", jt, initial_velocity=0.6 if how == "acceleration" else 0.0, dof=dof, **{how: spec})
    # all three give the same function: f = 0.3 sin 2t + 0.1 t^2 (f(0) = 0, f'(0) = 0.6)
    fn = model.motions["m"].function
    for t in (0.3, 0.7, 1.9):
        f = 0.3 * np.sin(2 * t) + 0.1 * t**2
        assert fn.value(t) == pytest.approx(f, abs=1e-9)
        assert fn.d1(t) == pytest.approx(0.6 * np.cos(2 * t) + 0.2 * t, abs=1e-8)
        assert fn.d2(t) == pytest.approx(-1.2 * np.sin(2 * t) + 0.2, abs=1e-6)
    check_equations(model, impl=impl)


@pytest.mark.parametrize("impl", sorted(IMPLS))
def test_translational_driver_on_particle(impl):
    model, jt = build("translational", "rigid-particle")
    model.add_motion("m", jt, displacement="0.5*t**3")
    check_equations(model, impl=impl)


# ----------------------------------------------------------------------------- allowed motions
def twists(kind):
    """Relative motions (w, v_P) a joint allows to body j, ground axes, with P the joint point."""
    h = AXIS
    f = np.cross(h, [1.0, 0.0, 0.0])
    f /= np.linalg.norm(f)
    g = np.cross(h, f)
    z = np.zeros(3)
    eye = np.eye(3)
    return {"revolute": [(h, z)], "translational": [(z, h)], "cylindrical": [(h, z), (z, h)],
            "spherical": [(eye[k], z) for k in range(3)], "universal": [(AXIS, z), (AXIS_J, z)],
            "planar": [(h, z), (z, f), (z, g)], "fixed": []}[kind]


@pytest.mark.parametrize("kind", KINDS)
def test_joint_leaves_exactly_its_degrees_of_freedom(kind):
    model, jt = build(kind, "ground-rigid")
    sys = assemble_system(model)
    _, J, _, _ = constraint_terms(sys, sys.q0, sys.v0, 0.0)
    body = jt.body_j
    A = body.orientation
    allowed = twists(kind)
    for w, vP in allowed:
        v = np.concatenate([vP + np.cross(w, body.position - POINT), A.T @ w])
        assert np.abs(J @ v).max() < 1e-12, (kind, w, vP)
    assert np.linalg.matrix_rank(J, tol=1e-9) == 6 - len(allowed) == 6 - mb.assemble(model).dof

"""Core engine, must-show 5: a planar four-bar built from four 3D revolute joints (redundant).

The redundancy is reported once, naming the joints; the free motion under gravity satisfies the
Freudenstein relation; the in-plane reactions and angular accelerations match a planar forward
Newton-Euler solution written here with numpy from the simulated state (angles and rates only).
"""
import warnings

import numpy as np
import pytest
from scipy.linalg import null_space
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.system import constraint_terms

G = 9.81
A_, B_, C_, D_ = 0.1, 0.3, 0.25, 0.3          # crank, coupler, rocker, ground link [m] (Grashof crank-rocker)
MASS = np.array([0.5, 1.2, 0.9])              # crank, coupler, rocker [kg]
IZZ = MASS * np.array([A_, B_, C_]) ** 2 / 12
TH1_0 = np.radians(60.0)


def e(th):
    return np.stack([np.cos(th), np.sin(th)], -1)


def closure(th1):
    """Coupler and rocker angles for crank angle th1 (open, y > 0 branch)."""
    A, C = A_ * e(th1), np.array([D_, 0.0])
    d = np.linalg.norm(C - A)
    x = (B_**2 - C_**2 + d**2) / (2 * d)
    u = (C - A) / d
    B = A + x * u + np.sqrt(B_**2 - x**2) * np.array([-u[1], u[0]])
    return np.arctan2(*(B - A)[::-1]), np.arctan2(*(B - C)[::-1])


def four_bar():
    model = mb.Model("four_bar", gravity=(0.0, -G, 0.0))
    th2, th3 = closure(TH1_0)
    A = A_ * e(TH1_0)
    B, C = A + B_ * e(th2), np.array([D_, 0.0])
    p3 = lambda v: (v[0], v[1], 0.0)  # noqa: E731
    rz = lambda a: Rotation.from_rotvec([0, 0, a])  # noqa: E731
    bodies = []
    for name, m, izz, cm, th in (("crank", MASS[0], IZZ[0], A / 2, TH1_0),
                                 ("coupler", MASS[1], IZZ[1], (A + B) / 2, th2),
                                 ("rocker", MASS[2], IZZ[2], (B + C) / 2, th3)):
        bodies.append(model.add_body(name, m, inertia=(izz / 20, izz, izz), position=p3(cm), orientation=rz(th)))
    crank, coupler, rocker = bodies
    z = (0, 0, 1)
    model.add_revolute("O", model.ground, crank, (0, 0, 0), z)
    model.add_revolute("A", crank, coupler, p3(A), z)
    model.add_revolute("B", coupler, rocker, p3(B), z)
    model.add_revolute("C", model.ground, rocker, p3(C), z)
    return model, (th2, th3)


@pytest.fixture(scope="module")
def run():
    model, angles0 = four_bar()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = mb.simulate(model, 2.0, output_step=0.02, method="dop853", rtol=1e-9, atol=1e-11)
    assert res.success, res.message
    return model, angles0, res, caught


def test_redundancy_reported_once_naming_the_joints(run):
    *_, caught = run
    red = [w for w in caught if issubclass(w.category, mb.RedundantConstraintWarning)]
    assert len(red) == 1
    msg = str(red[0].message)
    for name in ("O", "A", "B", "C"):
        assert name in msg.split("joints involved:")[1]
    # 4 x 5 = 20 equations for 3 bodies x 6 = 18 coordinates and 1 DOF: 3 equations are dependent
    assert "3 of 20 equations are dependent" in msg
    rep_model, _ = four_bar()
    with pytest.warns(mb.RedundantConstraintWarning, match="joints involved"):
        rep = mb.assemble(rep_model)
    assert rep.dof == 1 and set(rep.redundant) == {"O", "A", "B", "C"}


def test_motion_satisfies_freudenstein(run):
    model, (th2_0, th3_0), res, _ = run
    th1 = TH1_0 + res.joint_coordinate("O")
    th3 = th3_0 + res.joint_coordinate("C")
    assert np.ptp(th1) > 0.5                     # it swings
    K1, K2, K3 = D_ / A_, D_ / C_, (A_**2 - B_**2 + C_**2 + D_**2) / (2 * A_ * C_)
    assert np.abs(K1 * np.cos(th3) - K2 * np.cos(th1) + K3 - np.cos(th1 - th3)).max() < 1e-8
    # relative angle of the coupler w.r.t. the crank at A, and its rate
    th2 = th2_0 + res.joint_coordinate("O") + res.joint_coordinate("A")
    assert np.allclose(th2, [closure(t)[0] for t in th1], atol=1e-8)
    E = res.kinetic_energy() + res.potential_energy()
    assert np.ptp(E) < 1e-8 * np.ptp(res.kinetic_energy())


def planar_forward_dynamics(th, w):
    """Angular accelerations (3,) and pin forces on: crank at O, coupler at A, rocker at B, rocker at C.

    Unknowns x = [al1, al2, al3, FO, FA, FB, FC] (11); 9 Newton-Euler equations and 2 loop-closure
    acceleration equations a (al1 n1 - w1^2 e1) + b (al2 n2 - w2^2 e2) - c (al3 n3 - w3^2 e3) = 0."""
    ee, nn = e(th), e(th + np.pi / 2)
    A = A_ * ee[0]
    B, C = A + B_ * ee[1], np.array([D_, 0.0])
    r = np.array([A / 2, A + B_ / 2 * ee[1], C + C_ / 2 * ee[2]])
    # CM accelerations a_k = P_k @ alpha + q_k
    P, q = np.zeros((3, 2, 3)), np.zeros((3, 2))
    P[0][:, 0], q[0] = A_ / 2 * nn[0], -A_ / 2 * w[0] ** 2 * ee[0]
    P[1][:, 0], q[1] = A_ * nn[0], -A_ * w[0] ** 2 * ee[0]
    P[1][:, 1] = B_ / 2 * nn[1]
    q[1] -= B_ / 2 * w[1] ** 2 * ee[1]
    P[2][:, 2], q[2] = C_ / 2 * nn[2], -C_ / 2 * w[2] ** 2 * ee[2]
    K, rhs = np.zeros((11, 11)), np.zeros(11)
    mom = lambda p: np.array([-p[1], p[0]])  # noqa: E731   (p x F) = mom(p) . F
    # force columns: FO 3:5, FA 5:7, FB 7:9, FC 9:11; (body, column, sign, point)
    loads = {0: [(3, +1, np.zeros(2)), (5, -1, A)], 1: [(5, +1, A), (7, -1, B)], 2: [(7, +1, B), (9, +1, C)]}
    for k in range(3):
        K[3 * k:3 * k + 2, :3] = MASS[k] * P[k]
        rhs[3 * k:3 * k + 2] = MASS[k] * (np.array([0.0, -G]) - q[k])
        K[3 * k + 2, k] = IZZ[k]
        for col, sign, pt in loads[k]:
            K[3 * k:3 * k + 2, col:col + 2] -= sign * np.eye(2)
            K[3 * k + 2, col:col + 2] -= sign * mom(pt - r[k])
    K[9:11, 0], K[9:11, 1], K[9:11, 2] = A_ * nn[0], B_ * nn[1], -C_ * nn[2]
    rhs[9:11] = A_ * w[0] ** 2 * ee[0] + B_ * w[1] ** 2 * ee[1] - C_ * w[2] ** 2 * ee[2]
    x = np.linalg.solve(K, rhs)
    return x[:3], x[3:5], x[5:7], x[7:9], x[9:11], r


def test_in_plane_reactions_match_planar_hand_solution(run):
    model, _, res, _ = run
    bodies = [model.bodies[n] for n in ("crank", "coupler", "rocker")]
    th = np.stack([np.arctan2(res.orientation(b)[:, 1, 0], res.orientation(b)[:, 0, 0]) for b in bodies], -1)
    w = np.stack([res.angular_velocity(b)[:, 2] for b in bodies], -1)
    crank, coupler, rocker = bodies
    F = {n: (res.reaction_force(n, on=b), res.reaction_torque(n, on=b))
         for n, b in (("O", crank), ("A", coupler), ("B", rocker), ("C", rocker))}
    scale = G * MASS.sum()
    for n in range(len(res.time)):
        al, FO, FA, FB, FC, r = planar_forward_dynamics(th[n], w[n])
        for k, b in enumerate(bodies):
            assert np.allclose(res.position(b)[n, :2], r[k], atol=1e-9)
            assert res.angular_acceleration(b)[n, 2] == pytest.approx(al[k], abs=1e-7 * max(1, abs(al).max()))
        for name, ref in (("O", FO), ("A", FA), ("B", FB), ("C", FC)):
            assert np.allclose(F[name][0][n, :2], ref, rtol=0, atol=1e-7 * scale), (name, n)
            assert abs(F[name][1][n, 2]) < 1e-7 * scale * A_    # a revolute carries no torque about its axis
    # relative joint rates: coupler w.r.t. crank at A
    assert np.allclose(res.joint_velocity("A"), w[:, 1] - w[:, 0], atol=1e-9)
    al = np.stack([res.angular_acceleration(b)[:, 2] for b in bodies], -1)
    assert np.allclose(res.joint_acceleration("A"), al[:, 1] - al[:, 0], atol=1e-9)
    # indeterminate (out-of-plane) components: the minimum-norm multipliers, i.e. orthogonal to the null
    # space of phi_q^T (any multiple of a null vector would balance the same loads)
    sys = res.system
    for n in (0, len(res.time) // 2, len(res.time) - 1):
        J = constraint_terms(sys, res.q[n], res.v[n], res.time[n])[1]
        ns = null_space(J.T)
        assert ns.shape[1] == 3
        assert np.abs(ns.T @ res.lambda_[n]).max() < 1e-9 * np.abs(res.lambda_[n]).max()

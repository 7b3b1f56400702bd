"""Torsion springs in a closed loop on the compiled core (issue 29): the joint angle of a pin that is not
a tree coordinate is read from the frames and continued beyond +-pi in the kernel (its reference moved at
every accepted step), with no Python callback. Reference: an independent scipy solve of the planar
four-bar's one-degree-of-freedom equation of motion (crank angle th1; the coupler and rocker angles by the
loop closure, their rates and accelerations from its derivatives; virtual power of gravity, the crank
torque and the springs), to 1e-8 rad.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

import mbdsim as mb
from test_core_four_bar import A_, B_, C_, D_, G, IZZ, MASS, TH1_0, closure  # noqa: F401  (the same four-bar)

pytestmark = pytest.mark.filterwarnings("ignore::mbdsim.RedundantConstraintWarning")   # (3D revolutes: redundant)


def e(th):
    return np.array([np.cos(th), np.sin(th)])


def perp(th):
    return np.array([-np.sin(th), np.cos(th)])


def four_bar(springs, torque=0.0):
    """The four-bar of 3D revolutes (redundant) with torsion springs {joint: (stiffness, damping)} and a
    constant torque [N m] about z on the crank."""
    model = mb.Model("four_bar", gravity=(0.0, -G, 0.0))
    th2, th3 = closure(TH1_0)
    A = A_ * e(TH1_0)
    B, C = A + B_ * e(th2), np.array([D_, 0.0])
    p3 = lambda v: (v[0], v[1], 0.0)  # noqa: E731
    rz = lambda a: Rotation.from_rotvec([0, 0, a])  # noqa: E731
    for name, m, izz, cm, th in (("crank", MASS[0], IZZ[0], A / 2, TH1_0),
                                 ("coupler", MASS[1], IZZ[1], (A + B) / 2, th2),
                                 ("rocker", MASS[2], IZZ[2], (B + C) / 2, th3)):
        model.add_body(name, m, inertia=(izz / 20, izz, izz), position=p3(cm), orientation=rz(th))
    z = (0, 0, 1)
    model.add_revolute("O", "ground", "crank", (0, 0, 0), z)
    model.add_revolute("A", "crank", "coupler", p3(A), z)
    model.add_revolute("B", "coupler", "rocker", p3(B), z)
    model.add_revolute("C", "ground", "rocker", p3(C), z)
    for joint, (k, c) in springs.items():
        model.add_torsion_spring(f"k{joint}", joint, stiffness=k, damping=c)
    if torque:
        model.add_torque("motor", "crank", (0.0, 0.0, torque))
    return model


def reference(springs, torque, t_end, times):
    """th1(times) [rad] of the planar one-DOF equation of motion, continued (scipy DOP853, 1e-12)."""
    f, state, start = planar_equation(springs, torque)
    sol = solve_ivp(f, (0.0, t_end), [TH1_0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=times,
                    max_step=1e-3)
    state["b"] = start
    alpha = np.array([f(t, y)[1] for t, y in zip(sol.t, sol.y.T)])   # (in time order: the branch followed)
    return sol.y[0], alpha


def planar_equation(springs, torque):
    """(f, state, start): f(t, [th1, w1]) = [w1, crank acceleration] of the planar one-DOF equation of
    motion (Meff th1_dd = rhs; the last Meff in state["meff"]), following the assembly branch in state["b"] (reset it to `start`, the
    initial coupler and rocker angles, before a new sweep in time)."""
    g = np.array([0.0, -G])
    th20, th30 = closure(TH1_0)

    def angles(th1, branch):
        th2, th3 = closure(th1)
        return branch[0] + np.angle(np.exp(1j * (th2 - branch[0]))), branch[1] + np.angle(np.exp(1j * (th3 - branch[1])))

    state = {"b": (th20, th30)}

    def f(t, y):
        th1, w1 = y
        th2, th3 = angles(th1, state["b"])
        state["b"] = (th2, th3)
        Mv = np.column_stack([B_ * perp(th2), -C_ * perp(th3)])
        k2, k3 = np.linalg.solve(Mv, -A_ * perp(th1))           # rates per unit crank rate
        w2, w3 = k2 * w1, k3 * w1
        q2, q3 = np.linalg.solve(Mv, A_ * w1**2 * e(th1) + B_ * w2**2 * e(th2) - C_ * w3**2 * e(th3))
        # CM velocity coefficients J (per w1) and accelerations at zero crank acceleration c
        J = [A_ / 2 * perp(th1), A_ * perp(th1) + B_ / 2 * k2 * perp(th2), C_ / 2 * k3 * perp(th3)]
        c = [-A_ / 2 * w1**2 * e(th1),
             -A_ * w1**2 * e(th1) + B_ / 2 * (q2 * perp(th2) - w2**2 * e(th2)),
             C_ / 2 * (q3 * perp(th3) - w3**2 * e(th3))]
        kap, alf0 = [1.0, k2, k3], [0.0, q2, q3]
        rel = {"O": (th1 - TH1_0, w1, 1.0), "A": (th2 - th1 - (th20 - TH1_0), w2 - w1, k2 - 1.0),
               "B": (th3 - th2 - (th30 - th20), w3 - w2, k3 - k2), "C": (th3 - th30, w3, k3)}
        Meff = sum(MASS[i] * J[i] @ J[i] + IZZ[i] * kap[i] ** 2 for i in range(3))
        rhs = sum(MASS[i] * g @ J[i] - MASS[i] * c[i] @ J[i] - IZZ[i] * alf0[i] * kap[i] for i in range(3))
        rhs += torque
        for joint, (k, cd) in springs.items():
            x, xd, dx = rel[joint]
            rhs -= (k * x + cd * xd) * dx
        state["meff"] = Meff
        return [w1, rhs / Meff]

    return f, state, (th20, th30)


def crank_angle(res):
    R = res.orientation("crank")
    return np.unwrap(np.arctan2(R[:, 1, 0], R[:, 0, 0]))


@pytest.mark.parametrize("method", ["auto", "radau"])
def test_coupler_pin_spring_in_the_loop_runs_compiled_against_the_planar_ode(method):
    """A torsion spring and damper on the coupler-side pin A (not a tree coordinate: the loop runs in
    absolute coordinates) and one on the rocker pin C: compiled, no Python callback, th1 to 1e-8 rad."""
    springs = {"A": (3.0, 0.02), "C": (1.5, 0.0)}
    rtol = 1e-10 if method == "auto" else 1e-9
    res = mb.simulate(four_bar(springs), 1.0, output_step=0.01, method=method, rtol=rtol)
    assert res.success, res.message
    assert "compiled" in res.stats["method"] and res.stats["called_back"] == ()
    ref, _ = reference(springs, 0.0, 1.0, res.time)
    err = np.max(np.abs(crank_angle(res) - ref))
    assert err < (1e-8 if method == "auto" else 1e-7), err
    assert np.ptp(ref) > 0.1   # the mechanism moves


def test_crank_turning_several_revolutions_winds_the_loop_springs_beyond_pi():
    """A constant torque turns the crank about two and a half revolutions in 1.2 s against springs on the
    ground pin O and the coupler pin A, whose angles wind past +-pi (by -2 pi per turn at A): the springs'
    torques follow the continued angles (the planar ODE to 1e-8 rad), and the Result's spring angle is the
    continued one."""
    springs = {"O": (0.02, 0.0), "A": (0.03, 0.001)}
    res = mb.simulate(four_bar(springs, torque=0.6), 1.2, output_step=0.005, method="dop853", rtol=1e-10,
                      atol=1e-12)
    assert res.success, res.message
    assert "compiled" in res.stats["method"] and res.stats["called_back"] == ()
    ref, alpha = reference(springs, 0.6, 1.2, res.time)
    assert ref[-1] - TH1_0 > 4 * np.pi          # more than two revolutions
    err = np.max(np.abs(crank_angle(res) - ref))
    assert err < 1e-8, err
    # the accelerations at the outputs (solved on demand after the run, each output's angles continued
    # from the run's steps) see the wound springs too
    acc = res.angular_acceleration("crank")[:, 2]
    assert np.max(np.abs(acc - alpha)) < 1e-6 * np.max(np.abs(alpha))
    x = res.spring_length("kA")   # the spring's continued angle (res.spring_force: its torque)
    assert x[-1] < -4 * np.pi


def test_driven_four_bar_with_wound_loop_springs_in_the_compiled_kinematic_sweep():
    """mb.kinematics of the four-bar driven at 40 rad/s (20 rad, several turns, between outputs) with
    springs on the coupler pins A and B (loop joints: angles continued in the kernel, A winding by
    -2 pi per crank turn) and on O: the compiled sweep, its driver torque against the planar equation at
    constant speed (tau = -Meff x the free crank's acceleration) at the outputs and, by the same solve
    restarted from each output's angle references, at times between them (dense output)."""
    springs = {"A": (2.0, 0.05), "B": (3.0, 0.1), "O": (1.0, 0.0)}
    speed = 40.0
    model = four_bar(springs)
    model.add_motion("drive", "O", displacement=f"{speed!r}*t")
    res = mb.kinematics(model, 3.0, 0.5)
    assert res.success and res.stats["method"] == "kinematic (compiled sweep)", res.stats

    def torque(times):
        f, state, _ = planar_equation(springs, 0.0)
        out = []
        for t in times:   # in time order, each sample a fraction of a turn past the last (branch followed)
            for tt in np.linspace(out[-1][0] if out else 0.0, t, 40):
                acc = f(tt, [TH1_0 + speed * tt, speed])[1]
            out.append((t, -state["meff"] * acc))
        return np.array([x[1] for x in out])
    tau = res.driver_effort("drive")
    ref = torque(res.time)
    assert np.max(np.abs(tau - ref)) < 1e-8 * np.max(np.abs(ref)), np.max(np.abs(tau - ref))
    ts = np.array([0.137, 1.01, 2.3, 2.96])
    between = res.at(ts).driver_effort("drive")
    ref_b = torque(ts)
    assert np.max(np.abs(between - ref_b)) < 1e-8 * np.max(np.abs(ref_b)), np.max(np.abs(between - ref_b))
    assert res.spring_length("kA")[-1] < -5 * 2 * np.pi   # wound: the continued angle, many turns


def test_an_expression_reading_the_angle_of_a_joint_onto_a_particle_is_refused_naming_it():
    """A pin whose body_j is a particle has no angle (the particle has no orientation): a load expression
    reading it is a ModelError naming the load, the field and the joint, as a torsion spring on it is;
    the pin's slide-free rate variable is refused the same way, a body's angle on another joint is fine."""
    m = mb.Model("pj", gravity=(0, -9.81, 0))
    b = m.add_body("b", 1.0, inertia=(0.1, 0.1, 0.1))
    p = m.add_particle("p", 0.5, position=(1, 0, 0))
    m.add_revolute("hub", m.ground, b, (0, 0, 0), (0, 0, 1))
    m.add_revolute("pin", b, p, (1, 0, 0), (0, 0, 1))
    for text in ("-2*pin", "-0.1*pin_dot"):
        with pytest.raises(mb.ModelError) as err:
            m.add_torque("tq", b, ("0", "0", text))
        assert err.value.entity == "torque 'tq'" and err.value.field == "torque[2]"
        assert "joint 'pin'" in str(err.value) and "particle" in str(err.value)
    with pytest.raises(mb.ModelError):
        m.add_torsion_spring("k", "pin", 10.0)
    m.add_torque("tq", b, ("0", "0", "-2*hub"))
    res = mb.simulate(m, 0.2, 0.1)
    assert res.success and "compiled" in res.stats["method"]

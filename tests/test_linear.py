"""mb.linearize against closed forms: spring-mass chain, pendulums, a four-bar against an independent
one-coordinate Lagrange derivation (redundant and non-redundant joint sets), a fast top's nutation and
precession, a damped oscillator's damping ratio and transfer function."""
import warnings

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import minimize_scalar
from scipy.spatial.transform import Rotation

import mbdsim as mb

G = 9.81


def hz(w):
    return w / (2 * np.pi)


def oscillating(lin):
    """Rows of modes() with a non-zero frequency."""
    df = lin.modes()
    return df[df["frequency [Hz]"] > 0]


# ----------------------------------------------------------------------------- spring-mass chain
def test_spring_mass_chain_frequencies_are_the_eigenvalues_of_K_and_M():
    m = np.array([1.0, 2.0, 0.5])
    k = np.array([100.0, 50.0, 80.0])
    model = mb.Model("chain")
    prev = (model.ground, (0.0, 0.0, 0.0))
    for i in range(3):
        p = model.add_particle(f"p{i}", m[i], position=(i + 1.0, 0, 0))
        model.add_translational(f"slide{i}", model.ground, p, (i + 1.0, 0, 0), (1, 0, 0))
        model.add_spring_damper(f"k{i}", prev, p, k[i])
        prev = p
    K = np.array([[k[0] + k[1], -k[1], 0], [-k[1], k[1] + k[2], -k[2]], [0, -k[2], k[2]]])
    w = np.sqrt(sla.eigh(K, np.diag(m), eigvals_only=True))
    lin = mb.linearize(model)
    assert lin.A.shape == (6, 6) and lin.dof == 3
    df = lin.modes()
    assert len(df) == 3
    assert np.allclose(df["frequency [Hz]"], hz(w), rtol=1e-7)
    assert np.allclose(df["damping ratio"], 0.0, atol=1e-7)
    # mode shapes: x displacements proportional to the generalized eigenvectors of (K, M)
    _, vec = sla.eigh(K, np.diag(m))
    for i in range(3):
        sh = lin.mode_shape(i)["x"].to_numpy()
        ref = vec[:, i] / vec[np.argmax(np.abs(vec[:, i])), i]
        assert np.allclose(sh.real, ref, atol=1e-6) and np.allclose(sh.imag, 0, atol=1e-9)


# ----------------------------------------------------------------------------- pendulums
def rod_pendulum(th0, m=2.0, L=1.0, inertia=None):
    model = mb.Model("pendulum", gravity=(0.0, -G, 0.0))
    c, s = np.cos(th0), np.sin(th0)
    inertia = (0.01, m * L**2 / 12, m * L**2 / 12) if inertia is None else inertia
    rod = model.add_body("rod", m, inertia=inertia, position=(L / 2 * c, L / 2 * s, 0),
                         orientation=Rotation.from_rotvec([0, 0, th0]))
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1))
    return model, rod, pin


def test_point_mass_pendulum_sqrt_g_over_l():
    l = 0.7
    model = mb.Model("point", gravity=(0.0, -G, 0.0))
    bob = model.add_body("bob", 1.3, inertia=(0.0, 0.0, 0.0), position=(0, -l, 0))   # a point mass
    model.add_revolute("pin", model.ground, bob, (0, 0, 0), (0, 0, 1))
    lin = mb.linearize(model)
    assert np.allclose(np.sort(lin.eigenvalues.imag), [-np.sqrt(G / l), np.sqrt(G / l)], rtol=1e-8)
    assert np.allclose(lin.eigenvalues.real, 0.0, atol=1e-8)
    assert len(lin.modes()) == 1
    assert lin.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(np.sqrt(G / l)), rel=1e-8)


def test_physical_pendulum_from_a_horizontal_start_with_torque_input_and_angle_output():
    """Rod (m, L) on a pin: w = sqrt(m g L/2 / (m L^2 / 3)); the static gain angle / torque is 1 / (m g L/2)."""
    m, L = 2.0, 1.0
    model, rod, pin = rod_pendulum(0.0, m, L)        # horizontal: statics must find the hanging position
    model.add_torque("motor", rod, (0.0, 0.0, 0.0))
    tip = rod.add_marker("tip", (L, 0, 0))
    lin = mb.linearize(model, at="equilibrium", inputs=["motor.z"],
                       outputs={"angle": lambda r: r.joint_coordinate(pin),
                                "tip_x": lambda r: r.position(tip)[:, 0]})
    w = np.sqrt(m * G * L / 2 / (m * L**2 / 3))
    assert lin.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(w), rel=1e-8)
    assert lin.input_names == ["motor.z [N m]"] and lin.output_names == ["angle", "tip_x"]
    gain = (lin.D - lin.C @ np.linalg.solve(lin.A, lin.B))
    assert gain[0, 0] == pytest.approx(1 / (m * G * L / 2), rel=1e-6)
    assert gain[1, 0] == pytest.approx(L / (m * G * L / 2), rel=1e-6)   # hanging: the tip moves along +x
    assert np.allclose(lin.D, 0.0, atol=1e-9)
    assert lin.y0[0] == pytest.approx(-np.pi / 2, abs=1e-8)            # the hanging angle from the start


def test_inverted_pendulum_has_a_real_unstable_pair():
    m, L = 2.0, 1.0
    model, rod, pin = rod_pendulum(np.pi / 2, m, L)                      # exactly upright
    lin = mb.linearize(model)
    a = np.sqrt(m * G * L / 2 / (m * L**2 / 3))
    assert np.allclose(np.sort(lin.eigenvalues.real), [-a, a], rtol=1e-7)
    df = lin.modes()
    assert len(df) == 2 and np.allclose(np.sort(df["damping ratio"]), [-1, 1])
    with pytest.warns(mb.UnstableEquilibriumWarning, match="rod"):
        lin2 = mb.linearize(model, at="equilibrium")
    assert np.allclose(np.sort(lin2.eigenvalues.real), [-a, a], rtol=1e-7)


# ----------------------------------------------------------------------------- four-bar
A_, D_ = np.array([0.0, 0.0]), np.array([1.0, 0.0])
LEN = np.array([0.4, 0.9, 0.6])          # crank AB, coupler BC, rocker DC
MASS = np.array([1.0, 1.5, 0.8])


def fourbar_points(th):
    """B and C of the four-bar for crank angle th, C on the lower branch (below the line BD)."""
    B = A_ + LEN[0] * np.array([np.cos(th), np.sin(th)])
    d = D_ - B
    dist = np.linalg.norm(d)
    a = (LEN[1] ** 2 - LEN[2] ** 2 + dist**2) / (2 * dist)
    h = np.sqrt(LEN[1] ** 2 - a**2)
    e = d / dist
    C = B + a * e - h * np.array([-e[1], e[0]])
    return B, C


def fourbar_links(th):
    """(CM (2,), angle) of crank, coupler, rocker."""
    B, C = fourbar_points(th)
    ang = lambda p, q: np.arctan2(q[1] - p[1], q[0] - p[0])  # noqa: E731
    return [((A_ + B) / 2, ang(A_, B)), ((B + C) / 2, ang(B, C)), ((D_ + C) / 2, ang(D_, C))]


def lagrange_fourbar():
    """Independent reference: V(th) and the generalized mass m(th) with one coordinate, derivatives by
    central differences; w^2 = V''(th0) / m(th0) at the minimum of V."""
    def V(th):
        return sum(G * MASS[i] * fourbar_links(th)[i][0][1] for i in range(3))

    def meff(th, h=1e-6):
        lp, lm = fourbar_links(th + h), fourbar_links(th - h)
        out = 0.0
        for i in range(3):
            dr = (lp[i][0] - lm[i][0]) / (2 * h)
            dphi = (lp[i][1] - lm[i][1]) / (2 * h)
            out += MASS[i] * dr @ dr + MASS[i] * LEN[i] ** 2 / 12 * dphi**2
        return out
    th0 = minimize_scalar(V, bounds=(-2.6, -0.8), method="bounded", options={"xatol": 1e-12}).x
    h = 1e-4
    V2 = (V(th0 + h) - 2 * V(th0) + V(th0 - h)) / h**2
    return th0, np.sqrt(V2 / meff(th0))


def fourbar_model(th, redundant):
    model = mb.Model("fourbar", gravity=(0.0, -G, 0.0))
    links = []
    for i, (name, (cm, ang)) in enumerate(zip(("crank", "coupler", "rocker"), fourbar_links(th))):
        links.append(model.add_body(name, MASS[i], inertia=(1e-3, MASS[i] * LEN[i] ** 2 / 12, MASS[i] * LEN[i] ** 2 / 12),
                                    position=(cm[0], cm[1], 0), orientation=Rotation.from_rotvec([0, 0, ang])))
    B, C = fourbar_points(th)
    z = (0, 0, 1)
    model.add_revolute("A", model.ground, links[0], (0, 0, 0), z)
    model.add_revolute("D", model.ground, links[2], (D_[0], D_[1], 0), z)
    if redundant:
        model.add_revolute("B", links[0], links[1], (B[0], B[1], 0), z)
        model.add_revolute("C", links[1], links[2], (C[0], C[1], 0), z)
    else:                    # R-S-U-R: 17 independent equations for 18 velocity variables
        e = (C - B) / np.linalg.norm(C - B)
        model.add_spherical("B", links[0], links[1], (B[0], B[1], 0))
        model.add_universal("C", links[1], links[2], (C[0], C[1], 0), z, (-e[1], e[0], 0))
    return model


def test_closed_loop_fourbar_hanging_against_one_coordinate_lagrange():
    th0, w = lagrange_fourbar()
    with warnings.catch_warnings():
        warnings.simplefilter("error")                    # the R-S-U-R set is not redundant
        lin = mb.linearize(fourbar_model(th0, redundant=False))
    assert lin.dof == 1
    assert lin.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(w), rel=1e-6)
    with pytest.warns(mb.RedundantConstraintWarning):
        lin_r = mb.linearize(fourbar_model(th0, redundant=True))
    assert lin_r.dof == 1
    assert lin_r.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(w), rel=1e-6)
    # statics of the closed loop from 0.6 rad away, then linearized there: the same mode
    model = fourbar_model(th0 + 0.6, redundant=False)
    res = mb.equilibrium(model)
    assert res.stats["stable"]
    B = res.position("crank")[0, :2] * 2
    assert np.arctan2(B[1], B[0]) == pytest.approx(th0, abs=1e-7)
    lin_e = mb.linearize(model, at="equilibrium")
    assert lin_e.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(w), rel=1e-6)
    shape = lin_e.mode_shape(0)
    assert set(shape.index) == {"crank", "coupler", "rocker"}
    assert np.allclose(shape[["z", "rx", "ry"]].to_numpy(), 0, atol=1e-6)   # a planar mode


# ----------------------------------------------------------------------------- spinning top
def top_model(w3, m=1.0, l=0.1, I1=0.002, I3=0.004):
    model = mb.Model("top", gravity=(0.0, 0.0, -G))
    top = model.add_body("top", m, inertia=(I1, I1, I3), position=(0, 0, l), angular_velocity=(0, 0, w3))
    model.add_spherical("tip", model.ground, top, (0, 0, 0))
    return model


def test_sleeping_top_nutation_and_precession_in_ground():
    """Upright top spinning at w3: I1' w^2 - I3 w3 w + m g l = 0 (I1' about the tip), so a fast top nutates
    at about I3 w3 / I1' and precesses at about m g l / (I3 w3)."""
    m, l, I1, I3, w3 = 1.0, 0.1, 0.002, 0.004, 150.0
    I1p = I1 + m * l**2
    disc = np.sqrt((I3 * w3) ** 2 - 4 * I1p * m * G * l)
    fast, slow = (I3 * w3 + disc) / (2 * I1p), (I3 * w3 - disc) / (2 * I1p)
    assert fast == pytest.approx(I3 * w3 / I1p, rel=0.05) and slow == pytest.approx(m * G * l / (I3 * w3), rel=0.05)
    model = top_model(w3)
    lin = mb.linearize(model)
    df = lin.modes()
    assert len(df) == 3 and df["frequency [Hz]"].iloc[0] == 0.0          # the spin: a rigid-body mode
    assert np.allclose(oscillating(lin)["frequency [Hz]"], hz(np.array([slow, fast])), rtol=1e-7)
    assert np.allclose(oscillating(lin)["damping ratio"], 0.0, atol=1e-7)
    # the spin about the vertical carries on unchanged: the same modes 0.2 s later (dense output)
    res = mb.simulate(model, 0.2, 0.1)
    lin2 = mb.linearize(model, at=(res, 0.15))
    assert np.allclose(oscillating(lin2)["frequency [Hz]"], hz(np.array([slow, fast])), rtol=1e-6)
    # too slow to sleep: the tilt grows (an eigenvalue with positive real part)
    assert np.max(mb.linearize(top_model(30.0)).eigenvalues.real) > 1.0


# ----------------------------------------------------------------------------- damped oscillator
def test_damped_oscillator_damping_ratio_and_transfer_function():
    m, k, c = 2.0, 800.0, 12.0
    model = mb.Model("osc")
    p = model.add_particle("mass", m, position=(0.5, 0, 0))
    model.add_translational("slide", model.ground, p, (0.5, 0, 0), (1, 0, 0))
    model.add_spring_damper("kc", (model.ground, (0, 0, 0)), p, k, damping=c)
    model.add_force("push", p, (0.0, 0.0, 0.0))
    lin = mb.linearize(model, inputs="push.x",
                       outputs=[lambda r: r.position(p)[:, 0], lambda r: r.acceleration(p)[:, 0]])
    row = lin.modes().iloc[0]
    assert row["damping ratio"] == pytest.approx(c / (2 * np.sqrt(k * m)), rel=1e-8)
    assert row["frequency [Hz]"] == pytest.approx(hz(np.sqrt(k / m)), rel=1e-8)
    assert row["damped frequency [Hz]"] == pytest.approx(hz(np.sqrt(k / m) * np.sqrt(1 - c**2 / (4 * k * m))), rel=1e-8)
    s = 7j
    H = lin.C @ np.linalg.solve(s * np.eye(2) - lin.A, lin.B) + lin.D
    assert H[0, 0] == pytest.approx(1 / (m * s**2 + c * s + k), rel=1e-7)
    assert H[1, 0] == pytest.approx(s**2 / (m * s**2 + c * s + k), rel=1e-7)
    assert lin.D[1, 0] == pytest.approx(1 / m, rel=1e-8) and lin.D[0, 0] == pytest.approx(0, abs=1e-12)
    ss = lin.to_scipy()
    assert ss.A.shape == (2, 2)


def test_free_body_has_six_rigid_body_modes():
    model = mb.Model("free")
    model.add_body("b", 1.0, inertia=(0.1, 0.2, 0.3))
    df = mb.linearize(model).modes()
    assert len(df) == 6 and np.all(df["frequency [Hz]"] == 0)


def test_bad_arguments_name_the_field():
    model, rod, pin = rod_pendulum(-np.pi / 2)
    model.add_spring_damper("spring", (model.ground, (0, 0, 0)), rod, 10.0)
    for kwargs, field in (({"inputs": ["spring"]}, "inputs"), ({"inputs": ["nothing"]}, "inputs"),
                          ({"outputs": [3.0]}, "outputs"), ({"at": "start"}, "at"), ({"at": 2.0}, "at")):
        with pytest.raises(mb.ModelError) as err:
            mb.linearize(model, **kwargs)
        assert err.value.field == field
    lin = mb.linearize(model)
    with pytest.raises(mb.ModelError) as err:
        lin.mode_shape(5)
    assert err.value.field == "i"


def test_motion_input_is_the_base_acceleration_of_a_shaken_oscillator():
    """Base driven along x (motion input: its acceleration), mass on a spring-damper to the base:
    X / U = (c s + k) / (s^2 (m s^2 + c s + k)); the base itself 1 / s^2."""
    m, k, c = 0.5, 200.0, 3.0
    model = mb.Model("shaker", gravity=(0.0, -G, 0.0))
    base = model.add_body("base", 4.0, inertia=(0.1, 0.1, 0.1))
    rail = model.add_translational("rail", model.ground, base, (0, 0, 0), (1, 0, 0))
    model.add_motion("shake", rail, displacement=0.0)
    p = model.add_particle("mass", m, position=(0.5, 0, 0))
    model.add_translational("slide", model.ground, p, (0.5, 0, 0), (1, 0, 0))
    model.add_spring_damper("kc", base, p, k, damping=c)
    lin = mb.linearize(model, inputs=["shake"], outputs={"x": lambda r: r.position(p)[:, 0],
                                                          "b": lambda r: r.position(base)[:, 0],
                                                          "b_acc": lambda r: r.acceleration(base)[:, 0]})
    assert lin.A.shape == (4, 4) and lin.input_names == ["shake [m/s^2]"]
    row = lin.modes().iloc[0]
    assert len(lin.modes()) == 1 and row["damping ratio"] == pytest.approx(c / (2 * np.sqrt(k * m)), rel=1e-7)
    for s in (3j, 25j, 0.5 + 8j):
        H = lin.C @ np.linalg.solve(s * np.eye(4) - lin.A, lin.B) + lin.D
        assert H[0, 0] == pytest.approx((c * s + k) / (s**2 * (m * s**2 + c * s + k)), rel=1e-6)
        assert H[1, 0] == pytest.approx(1 / s**2, rel=1e-8)
        assert H[2, 0] == pytest.approx(1.0, rel=1e-8)


def governor(W, l=0.5):
    """Point mass on a hinge (axis z) carried round a vertical shaft driven at W [rad/s]."""
    model = mb.Model("governor", gravity=(0.0, -G, 0.0))
    shaft = model.add_body("shaft", 1.0, inertia=(0.1, 0.1, 0.1), angular_velocity=(0, W, 0))
    bob = model.add_body("bob", 1.0, inertia=(0.0, 0.0, 0.0), position=(0, -l, 0), angular_velocity=(0, W, 0))
    axle = model.add_revolute("axle", model.ground, shaft, (0, 0, 0), (0, 1, 0))
    model.add_motion("spin", axle, displacement=f"{W}*t")
    model.add_revolute("hinge", shaft, bob, (0, 0, 0), (0, 0, 1))
    return model


def test_pendulum_carried_round_by_a_driven_shaft():
    """theta'' + (g/l - W^2) theta = 0 about the hanging position: the hinge axis turns with the shaft (the
    basis is transported along the reference motion); above W^2 = g/l the hanging position is unstable."""
    l, W = 0.5, 2.0
    model = governor(W, l)
    lin = mb.linearize(model)
    assert lin.dof == 1
    assert np.allclose(np.sort(lin.eigenvalues.imag), [-np.sqrt(G / l - W**2), np.sqrt(G / l - W**2)], rtol=1e-7)
    res = mb.simulate(model, 0.5, 0.1)
    lin2 = mb.linearize(model, at=(res, 0.35))          # the shaft has turned 0.7 rad: the same mode
    assert lin2.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(np.sqrt(G / l - W**2)), rel=1e-7)
    fast = mb.linearize(governor(5.0, l))
    assert np.max(fast.eigenvalues.real) == pytest.approx(np.sqrt(25.0 - G / l), rel=1e-6)


def test_bead_on_a_vertical_ring_path_constraint():
    """Point-on-curve (auxiliary curve parameter): statics from 2.5 rad up the ring, then sqrt(g / R)."""
    R = 0.8
    circle = mb.Curve(lambda s: R * np.array([np.sin(s), -np.cos(s), 0.0]), (-np.pi, np.pi))
    model = mb.Model("ring", gravity=(0.0, -G, 0.0))
    bead = model.add_particle("bead", 0.4, position=circle.point(2.5))
    model.add_point_on_curve("ring", bead.add_marker("c"), model.ground, circle)
    lin = mb.linearize(model, at="equilibrium")
    assert np.allclose(lin.q[:3], [0.0, -R, 0.0], atol=1e-9)
    assert lin.modes()["frequency [Hz]"].iloc[0] == pytest.approx(hz(np.sqrt(G / R)), rel=1e-7)


def test_outputs_named_by_result_columns():
    """Outputs given as to_dataframe() column names (and a labelled pair): static gains of the hanging rod
    to a torque: angle 1 / (m g L/2), CM x (L/2) / (m g L/2), CM y 0 (second order)."""
    m, L = 2.0, 1.0
    model, rod, pin = rod_pendulum(-np.pi / 2, m, L)
    model.add_torque("motor", rod, (0.0, 0.0, 0.0))
    lin = mb.linearize(model, inputs="motor.z",
                       outputs=["pin.angle", "rod.x", ("cm height [m]", lambda r: r.position(rod)[:, 1])])
    assert lin.output_names == ["pin.angle", "rod.x", "cm height [m]"]
    gain = lin.D - lin.C @ np.linalg.solve(lin.A, lin.B)
    k = m * G * L / 2
    assert gain[:, 0] == pytest.approx([1 / k, (L / 2) / k, 0.0], abs=1e-9)
    assert lin.y0 == pytest.approx([0.0, 0.0, -L / 2], abs=1e-12)        # the angle counts from as drawn
    with pytest.raises(mb.ModelError) as err:
        mb.linearize(model, outputs=["nothing.x"])
    assert err.value.field == "outputs"


def test_a_row_of_modes_gives_real_numbers():
    """I th'' + c th' + k th = 0 on a torsion spring: each row's frequency and damping ratio are floats."""
    import math
    I, k, c = 0.2, 50.0, 0.8
    model = mb.Model("torsion")
    disk = model.add_body("disk", 3.0, inertia=(0.1, 0.1, I))
    model.add_revolute("axle", model.ground, disk, (0, 0, 0), (0, 0, 1))
    model.add_torsion_spring("ks", "axle", k, damping=c)
    df = mb.linearize(model).modes()
    row = df.iloc[0]
    assert isinstance(row["frequency [Hz]"], float) and isinstance(row["damping ratio"], float)
    assert math.isclose(row["frequency [Hz]"], hz(np.sqrt(k / I)), rel_tol=1e-8)
    assert math.isclose(row["damping ratio"], c / (2 * np.sqrt(k * I)), rel_tol=1e-8)
    assert row["eigenvalue"] == pytest.approx(complex(-c / (2 * I), np.sqrt(k / I - (c / (2 * I)) ** 2)), rel=1e-8)
    assert df["frequency [Hz]"].dtype == float

"""Adams dataset import, the statements issue 31 left untested or missing: RACKPIN, a three-joint COUPLER,
HOOKE crosspin axes, PART WX..WZ / VX..VZ with WM/VM markers, ICROT/ICTRAN, a coupled (6x6) FIELD,
SPLINE with AKISPL/CUBSPL, IF and MOD.  References: closed forms, scipy integrations of equations written
here by hand, numpy (np.fmod, np.where), conservation of momentum; conventions from the Adams/Solver
statement pages (PART: WX about the WM marker's axes; HOOKE: crosspin x_I and y_J; FIELD: matrices by
columns; SPLINE: parabolic extrapolation over the end three points)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import mbdsim as mb
from mbdsim.errors import ModelFileError
from mbdsim.importers.adm_expr import Context, translate


def adm(tmp_path, text, name="m.adm"):
    path = tmp_path / name
    path.write_text("title\n" + text.strip() + "\nEND\n")
    return mb.from_adm(path)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


# ---------------------------------------------------------------- joints
def test_rackpin_rolls_without_slip(tmp_path):
    """Pinion (PD 80 mm) turned at 2 rad/s about ground z, rack on a rail along x below it (J at the pitch
    point, z_J along x_I as Adams asks): the rack moves at w PD/2 (v = w z x (-PD/2 y))."""
    m = adm(tmp_path, """
UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND
PART/1, GROUND
MARKER/10, PART=1
MARKER/11, PART=1, QP=0, -40, 0, REULER=90D, 90D, 0
PART/2, MASS=1, CM=20, IP=1000, 1000, 1000
MARKER/20, PART=2
PART/3, MASS=2, CM=30, IP=1000, 1000, 1000, QG=0, -40, 0
MARKER/30, PART=3
MARKER/31, PART=3, REULER=90D, 90D, 0
JOINT/1, REVOLUTE, I=20, J=10
JOINT/2, TRANSLATIONAL, I=31, J=11
JOINT/3, RACKPIN, I=20, J=31, PD=80
MOTION/1, JOINT=1, FUNCTION=2*TIME
""")
    res = mb.simulate(m, 0.2, output_step=0.05, rtol=1e-10, atol=1e-12)
    x = res.position("PART_3")[:, 0]
    assert np.abs(x - 2.0 * res.time * 0.04).max() < 1e-9
    assert np.abs(res.position("PART_3")[:, 1] + 0.04).max() < 1e-12


def test_three_joint_coupler_holds_its_sum(tmp_path):
    """COUPLER/1, JOINTS=1,2,3, TYPE=R:R:T, SCALES=1,2,-1 in a millimetre dataset: theta1 + 2 theta2 - s3[mm]
    = 0 (Adams: sum of scale * joint displacement in dataset units); with theta1 = 3t, theta2 = -t^2/2
    driven, the slide follows: s3 = (3t - t^2) mm."""
    m = adm(tmp_path, """
UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND
PART/1, GROUND
MARKER/10, PART=1
MARKER/11, PART=1, QP=500, 0, 0
MARKER/12, PART=1, QP=0, 500, 0, REULER=0, 90D, 0
PART/2, MASS=1, CM=20, IP=1000, 1000, 1000
MARKER/20, PART=2
PART/3, MASS=1, CM=30, IP=1000, 1000, 1000, QG=500, 0, 0
MARKER/30, PART=3
PART/4, MASS=1, CM=40, IP=1000, 1000, 1000, QG=0, 500, 0
MARKER/40, PART=4, REULER=0, 90D, 0
JOINT/1, REVOLUTE, I=20, J=10
JOINT/2, REVOLUTE, I=30, J=11
JOINT/3, TRANSLATIONAL, I=40, J=12
COUPLER/1, JOINTS=1, 2, 3, TYPE=R:R:T, SCALES=1, 2, -1
MOTION/1, JOINT=1, FUNCTION=3*TIME
MOTION/2, JOINT=2, FUNCTION=-0.5*TIME**2
""")
    res = mb.simulate(m, 0.2, output_step=0.05, rtol=1e-10, atol=1e-12)
    t = res.time
    s3 = res.joint_coordinate("JOINT_3")
    assert np.abs(s3 - (3 * t - t ** 2) / 1000).max() < 1e-10
    assert np.ptp(s3) > 1e-4


def test_hooke_crosspin_axes_are_x_i_and_y_j(tmp_path):
    """HOOKE: the cross pins are x_I (fixed in the I part) and y_J (fixed in the J part), as the Adams manual
    states ("the X-axis of the I marker perpendicular to the Y-axis of the J marker ... outline the
    crosspiece").  Here x_I = ground X and y_J = ground Z (J turned 90 deg about x): the part may turn about
    X and Z but not about Y, so a torque about ground Y holds it at rest (z_I/z_J pins, the UNIVERSAL
    convention, would forbid X instead, and y_I/x_J would forbid Z)."""
    m = adm(tmp_path, """
PART/1, GROUND
MARKER/10, PART=1, REULER=0, 90D, 0
PART/2, MASS=1, CM=20, IP=0.01, 0.01, 0.01
MARKER/20, PART=2
JOINT/1, HOOKE, I=20, J=10
""")
    jt = m.joints["JOINT_1"]
    pins = {tuple(np.round(jt.marker_i.orientation[:, 2], 12)), tuple(np.round(jt.marker_j.orientation[:, 2], 12))}
    assert pins == {(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)}, pins
    m.add_torque("ty", "PART_2", (0.0, 1.0, 0.0))
    res = mb.simulate(m, 0.1, output_step=0.05, rtol=1e-10, atol=1e-12)
    assert np.abs(res.angular_velocity("PART_2")).max() < 1e-9
    m2 = adm(tmp_path, """
PART/1, GROUND
MARKER/10, PART=1, REULER=0, 90D, 0
PART/2, MASS=1, CM=20, IP=0.01, 0.01, 0.01
MARKER/20, PART=2
JOINT/1, HOOKE, I=20, J=10
""", "m2.adm")
    m2.add_torque("tz", "PART_2", (0.0, 0.0, 0.5))    # about the ground pin: free, w = T t / I
    res = mb.simulate(m2, 0.1, output_step=0.05, rtol=1e-10, atol=1e-12)
    assert np.abs(res.angular_velocity("PART_2")[:, 2] - 50.0 * res.time).max() < 1e-8


def test_part_velocities_in_the_wm_and_vm_axes(tmp_path):
    """Adams' PART: WX..WZ are about the axes of the WM marker (default the CM marker's), VX..VZ the CM's
    velocity along the axes of the VM marker (default ground's).  A free, isotropic part keeps them."""
    m = adm(tmp_path, """
PART/1, GROUND
PART/2, MASS=2, CM=20, IP=0.1, 0.1, 0.1, WM=21, VM=22, WZ=3, VX=1, VZ=2
MARKER/20, PART=2, REULER=30D, 0, 0
MARKER/21, PART=2, REULER=0, 90D, 0
MARKER/22, PART=2, QP=0, 0.5, 0, REULER=90D, 0, 0
PART/3, MASS=2, CM=30, IP=0.1, 0.1, 0.1, WX=1, VY=4, QG=1, 0, 0
MARKER/30, PART=3, REULER=90D, 0, 0
""")
    res = mb.simulate(m, 0.1, output_step=0.05, rtol=1e-10, atol=1e-12)
    # PART_2: z of MARKER/21 (x turned 90 deg) is -Y; MARKER/22's x is Y and z is Z
    assert np.allclose(res.angular_velocity("PART_2"), [0.0, -3.0, 0.0], atol=1e-9)
    assert np.allclose(res.velocity("PART_2"), [0.0, 1.0, 2.0], atol=1e-9)
    # PART_3 defaults: WX about the CM marker's x (= Y), VY along ground Y
    assert np.allclose(res.angular_velocity("PART_3"), [0.0, 1.0, 0.0], atol=1e-9)
    assert np.allclose(res.velocity("PART_3"), [0.0, 4.0, 0.0], atol=1e-9)


def test_icrot_ictran_start_the_joints(tmp_path):
    """ICROT = angle, rate on a REVOLUTE; ICTRAN = slide, rate on a TRANSLATIONAL (mm): no forces, so
    theta = 0.3 + 2 t and s = 0.01 - 0.05 t (m)."""
    m = adm(tmp_path, """
UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND
PART/1, GROUND
MARKER/10, PART=1
MARKER/11, PART=1, QP=500, 0, 0
PART/2, MASS=1, CM=20, IP=1000, 1000, 1000
MARKER/20, PART=2
PART/3, MASS=1, CM=30, IP=1000, 1000, 1000, QG=500, 0, 0
MARKER/30, PART=3
JOINT/1, REVOLUTE, I=20, J=10, ICROT=0.3, 2
JOINT/2, TRANSLATIONAL, I=30, J=11, ICTRAN=10, -50
""")
    res = mb.simulate(m, 0.2, output_step=0.05, rtol=1e-10, atol=1e-12)
    t = res.time
    assert np.abs(res.joint_coordinate("JOINT_1") - (0.3 + 2 * t)).max() < 1e-9
    assert np.abs(res.joint_coordinate("JOINT_2") - (0.01 - 0.05 * t)).max() < 1e-9


# ---------------------------------------------------------------- FIELD
K6 = np.array([[2000.0, 300.0, -100.0, 0, 0, 0], [-500.0, 1500.0, 200.0, 0, 0, 0],
               [100.0, 0.0, 3000.0, 0, 0, 0], [0, 0, 0, 10.0, 1.0, 0], [0, 0, 0, 0, 10.0, 0], [0, 0, 0, 0, 0, 10.0]])
C6 = np.array([[2.0, 0.5, 0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0], [-0.3, 0, 3.0, 0, 0, 0], [0] * 6, [0] * 6, [0] * 6])


def _by_columns(M):
    return ", ".join(repr(float(v)) for v in np.asarray(M).T.ravel())


def test_coupled_field_translation_against_its_linear_equations(tmp_path):
    """A FIELD with off-diagonal (and unsymmetric) K and C between a part and a turned ground marker, the
    part's orientation held (JPRIM ORIENTATION), LENGTH and FORCE preloads: m x'' = R (-K (R^T x - L) -
    C R^T x' + F0) in the J marker's axes R, integrated by scipy; the matrices given by columns."""
    L, F0 = [0.01, 0.0, -0.02, 0, 0, 0], [5.0, -3.0, 0.0, 0, 0, 0]
    m = adm(tmp_path, f"""
PART/1, GROUND
MARKER/10, PART=1, REULER=30D, 20D, 0
PART/2, MASS=1.5, CM=20, IP=0.01, 0.01, 0.01
MARKER/20, PART=2, REULER=30D, 20D, 0
JPRIM/1, ORIENTATION, I=20, J=10
FIELD/1, I=20, J=10, KMATRIX={_by_columns(K6)}
, CMATRIX={_by_columns(C6)}, LENGTH={', '.join(map(str, L))}, FORCE={', '.join(map(str, F0))}
""")
    assert any("coupled FIELD" in n for n in m.import_notes)
    R = _rz(np.radians(30)) @ np.array([[1, 0, 0], [0, np.cos(np.radians(20)), -np.sin(np.radians(20))],
                                          [0, np.sin(np.radians(20)), np.cos(np.radians(20))]])
    K, C = K6[:3, :3], C6[:3, :3]

    def rhs(t, y):
        x, v = y[:3], y[3:]
        f = R @ (-K @ (R.T @ x - L[:3]) - C @ (R.T @ v) + F0[:3])
        return np.concatenate([v, f / 1.5])
    res = mb.simulate(m, 0.3, output_step=0.01, rtol=1e-11, atol=1e-13)
    ref = solve_ivp(rhs, (0, 0.3), np.zeros(6), method="DOP853", rtol=1e-12, atol=1e-14, t_eval=res.time).y[:3].T
    err = np.abs(res.position("PART_2") - ref).max()
    assert err < 1e-9, err
    assert np.ptp(ref, axis=0).max() > 5e-3


@pytest.mark.filterwarnings("ignore::mbdsim.MonitorWarning")   # an unsymmetric K does work: no energy balance
def test_coupled_field_between_free_parts_conserves_momentum(tmp_path):
    """Two free parts joined by a coupled FIELD (rotational coupling too), no gravity: the loads are an exact
    action-reaction pair (force and moment about a common point), so linear and angular momentum stay."""
    m = adm(tmp_path, f"""
PART/1, GROUND
PART/2, MASS=1.0, CM=20, IP=0.02, 0.03, 0.04, VX=0.2, WZ=1.0
MARKER/20, PART=2
PART/3, MASS=2.0, CM=30, IP=0.05, 0.04, 0.03, QG=0.3, 0.1, 0
MARKER/30, PART=3
MARKER/31, PART=3, QP=-0.2, 0, 0, REULER=10D, 0, 0
FIELD/1, I=20, J=31, KMATRIX={_by_columns(K6)}
, CMATRIX={_by_columns(C6)}
""")
    res = mb.simulate(m, 0.3, output_step=0.05, rtol=1e-11, atol=1e-13)
    P = sum(mb_.mass * res.velocity(n) for n, mb_ in ((n, m.bodies[n]) for n in ("PART_2", "PART_3")))
    H = 0
    for n in ("PART_2", "PART_3"):
        b = m.bodies[n]
        Rb = res.orientation(n)
        J = np.asarray(b.inertia)
        Hs = np.einsum("kij,jl,kml,km->ki", Rb, J, Rb, res.angular_velocity(n))
        H = H + Hs + b.mass * np.cross(res.position(n), res.velocity(n))
    assert np.abs(P - P[0]).max() < 1e-9 and np.abs(H - H[0]).max() < 1e-9
    assert np.ptp(res.angular_velocity("PART_2")[:, 2]) > 1e-3


# ---------------------------------------------------------------- SPLINE, IF, MOD
def test_akispl_of_linear_data_is_a_linear_spring(tmp_path):
    """SFORCE = -AKISPL(DZ(I, J, J), 0, 5) [N of mm] on linear data y = 20 x (20 N/mm, beyond the data by
    Adams' end parabola, here a line): a harmonic oscillator, z = z0 cos(w t) with w = sqrt(20000/2)."""
    m = adm(tmp_path, """
UNITS/FORCE=NEWTON, MASS=KILOGRAM, LENGTH=MILLIMETER, TIME=SECOND
PART/1, GROUND
MARKER/11, PART=1
PART/2, MASS=2, CM=20, IP=1000, 1000, 1000
MARKER/20, PART=2
MARKER/21, PART=2
JOINT/1, TRANSLATIONAL, I=21, J=11, ICTRAN=5, 0
SPLINE/5, X=-10, -4, 0, 1, 3, 10, Y=-200, -80, 0, 20, 60, 200
SFORCE/1, TRANSLATIONAL, ACTIONONLY, I=21, J=11, FUNCTION=-AKISPL(DZ(21,11,11), 0, 5)
""")
    assert "AKISPL_5" in m.tables
    res = mb.simulate(m, 0.1, output_step=0.005, rtol=1e-11, atol=1e-13)
    w = np.sqrt(20000.0 / 2.0)
    err = np.abs(res.joint_coordinate("JOINT_1") - 0.005 * np.cos(w * res.time)).max()
    assert err < 1e-9, err


def test_spline_tables_interpolate_and_extrapolate_as_adams():
    """CUBSPL (not-a-knot) reproduces cubic data exactly; beyond the data the parabola through the last
    three points (LINEAR_EXTRAPOLATE: the line through the last two); derivatives by iord."""
    from mbdsim.importers.adm_spline import AdamsSpline
    xs = np.array([0.0, 1.0, 2.5, 3.0, 4.0])
    f = lambda x: x ** 3 - 2 * x  # noqa: E731
    sp = AdamsSpline(xs, f(xs), "CUBSPL")
    x = np.linspace(0.1, 3.9, 17)
    assert np.abs(sp(x) - f(x)).max() < 1e-12 and np.abs(sp(x, 1) - (3 * x ** 2 - 2)).max() < 1e-11
    p = np.polyfit(xs[-3:], f(xs[-3:]), 2)
    for xe in (4.5, 7.0, 20.0):
        assert abs(sp(xe) - np.polyval(p, xe)) < 1e-9 * max(1, abs(np.polyval(p, xe)))
    p = np.polyfit(xs[:3], f(xs[:3]), 2)
    assert abs(sp(-3.0) - np.polyval(p, -3.0)) < 1e-10
    lin = AdamsSpline(xs, f(xs), "AKISPL", linear=True)
    slope = (f(4.0) - f(3.0)) / 1.0
    assert abs(lin(6.0) - (f(4.0) + 2 * slope)) < 1e-10 and abs(lin(2.5) - f(2.5)) < 1e-12


def _ctx():
    return Context("SFORCE/1", "m.adm", 3, lambda i: "ground", {})


@pytest.mark.parametrize("a, b", [(7.3, 2.0), (-7.3, 2.0), (7.3, -2.0), (-0.4, 0.3), (123.456, 0.7), (4.0, 2.0),
                                  (6.0, 3.0), (-9.0, 3.0), (0.0, 1.5)])
def test_mod_is_fortran_mod(a, b):
    """MOD(a, b) = a - b*int(a/b) (np.fmod), exact multiples included."""
    text = translate(f"MOD(TIME, {b})", _ctx())
    got = mb.parse(text, ("TIME",))(a)
    assert abs(got - np.fmod(a, b)) < 1e-12 * max(1.0, abs(a)), (got, np.fmod(a, b))


def test_if_picks_its_branch_exactly():
    text = translate("IF(TIME - 1: 1E20, -3, TIME**2)", _ctx())
    e = mb.parse(text, ("TIME",))
    for t in (0.0, 0.5, 1.0, 1.5, 3.0):
        assert e(t) == (1e20 if t < 1 else -3.0 if t == 1 else t * t)


def test_if_and_mod_drive_a_mass(tmp_path):
    """F = IF(TIME - 0.1: 0, 0, 2) + MOD(TIME, 0.05)*40 [N] on 2 kg (no gravity): x'' integrated in closed
    form piecewise (a sawtooth and a step)."""
    m = adm(tmp_path, """
PART/1, GROUND
MARKER/11, PART=1
PART/2, MASS=2, CM=20, IP=1, 1, 1
MARKER/20, PART=2
JOINT/1, TRANSLATIONAL, I=20, J=11
SFORCE/1, TRANSLATIONAL, ACTIONONLY, I=20, J=11, FUNCTION=IF(TIME - 0.1: 0, 0, 2) + MOD(TIME, 0.05)*40
""")
    res = mb.simulate(m, 0.23, output_step=0.01, rtol=1e-11, atol=1e-13)
    t = res.time

    def x_exact(t):
        P, n = 0.05, np.floor(t / 0.05)
        # sawtooth s = t - nP: its double integral from 0 (each full period adds P^2/2 to the velocity)
        tau = t - n * P
        v_saw = n * P ** 2 / 2 + tau ** 2 / 2
        x_saw = sum(((t - (k + 1) * P) * P ** 2 / 2 + P ** 3 / 6) for k in range(int(n))) + tau ** 3 / 6
        step = np.where(t > 0.1, (t - 0.1) ** 2 / 2, 0.0) * 2
        return 40 * x_saw / 2 + step / 2, v_saw
    ref = np.array([x_exact(tt)[0] for tt in t])
    err = np.abs(res.joint_coordinate("JOINT_1") - ref).max()
    assert err < 1e-8, err


def test_spline_in_a_motion_and_unknown_spline_are_refused(tmp_path):
    base = """
PART/1, GROUND
MARKER/11, PART=1
PART/2, MASS=2, CM=20, IP=1, 1, 1
MARKER/20, PART=2
JOINT/1, TRANSLATIONAL, I=20, J=11
SPLINE/5, X=0, 1, 2, 3, Y=0, 1, 4, 9
"""
    with pytest.raises(ModelFileError, match=r"m.adm, line 8.*MOTION/1.*AKISPL.*not supported in a MOTION"):
        adm(tmp_path, base + "MOTION/1, JOINT=1, FUNCTION=AKISPL(TIME, 0, 5)")
    with pytest.raises(ModelFileError, match=r"line 8.*no SPLINE/6"):
        adm(tmp_path, base + "SFORCE/1, TRANSLATIONAL, ACTIONONLY, I=20, J=11, FUNCTION=CUBSPL(TIME, 0, 6)")
    with pytest.raises(ModelFileError, match=r"line 8.*IF is written"):
        adm(tmp_path, base + "SFORCE/1, TRANSLATIONAL, ACTIONONLY, I=20, J=11, FUNCTION=IF(TIME, 1, 2, 3)")


def test_spline_tables_survive_a_model_file(tmp_path):
    """save_model writes the SPLINE tables (section `tables`), load_model rebuilds them: the same run."""
    m = adm(tmp_path, """
PART/1, GROUND
MARKER/11, PART=1
PART/2, MASS=2, CM=20, IP=1, 1, 1
MARKER/20, PART=2
JOINT/1, TRANSLATIONAL, I=20, J=11, ICTRAN=0.3, 0
SPLINE/5, X=-1, 0, 0.5, 1, Y=-30, 0, 8, 25, LINEAR_EXTRAPOLATE
SFORCE/1, TRANSLATIONAL, ACTIONONLY, I=20, J=11, FUNCTION=-CUBSPL(DZ(20, 11, 11), 0, 5) - CUBSPL(TIME, 0, 5, 1)
""")
    mb.save_model(m, tmp_path / "out.yaml")
    assert "CUBSPL_5" in (tmp_path / "out.yaml").read_text()
    m2 = mb.load_model(tmp_path / "out.yaml")
    a, b = (mb.simulate(x, 0.2, output_step=0.02, rtol=1e-10, atol=1e-12) for x in (m, m2))
    assert np.abs(a.joint_coordinate("JOINT_1") - b.joint_coordinate("JOINT_1")).max() < 1e-12
    assert np.ptp(a.joint_coordinate("JOINT_1")) > 0.1

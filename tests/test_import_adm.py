"""Adams dataset import (issue 31): examples/slider_crank.adm (mm, MOTION in degrees, SFORCE of AZ and WZ,
SPRINGDAMPER, BUSHING) against closed forms and the same machine built through the API; units, inertia
conventions, joint types, action-reaction loads (momentum), errors with file and line, the CLI."""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

import mbdsim as mb
from mbdsim.errors import ModelFileError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "slider_crank.adm"
R, L, W0 = 0.1, 0.3, 2 * np.pi                 # crank, rod [m]; drive 360 deg/s
K, C, MF, D0 = 40e3 + 20e3, 500.0 + 250.0, 0.8, 0.15  # spring + bushing on the follower (SI)
MA, DA, IA, KT, CT = 0.3, 0.04, 3e-4, 2.0, 0.05   # arm: mass, CM offset, Izz, SFORCE gains (SI)
END = 0.5


@pytest.fixture(scope="module")
def imported():
    m = mb.from_adm(EXAMPLE)
    return m, mb.simulate(m, END, output_step=0.01, rtol=1e-10, atol=1e-12)


def _slider(t):
    th = W0 * t
    s = np.sqrt(L ** 2 - (R * np.sin(th)) ** 2)
    return R * np.cos(th) + s, -R * W0 * np.sin(th) - R * R * W0 * np.sin(th) * np.cos(th) / s


def test_slider_crank_against_closed_forms(imported):
    """Slider: r cos(th) + sqrt(l^2 - r^2 sin^2 th) with th = 360D*TIME; follower and arm: their 1-DOF
    equations of motion (written by hand, SI) integrated by scipy at rtol 1e-12."""
    m, res = imported
    t = res.time
    assert np.abs(res.position("slider")[:, 0] - _slider(t)[0]).max() < 1e-9

    def follower(t, y):
        s, sd = _slider(t)
        return [y[1], (-K * (y[0] - s - D0) - C * (y[1] - sd)) / MF]
    ref = solve_ivp(follower, (0, END), [0.55, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t).y[0]
    err_f = np.abs(res.position("follower")[:, 0] - ref).max()
    assert err_f < 1e-8, err_f
    assert np.ptp(ref) > 0.1                      # it does move

    def arm(t, y):                                # about the crank pin, which turns at W0 on radius R
        th = W0 * t
        tau = -KT * (y[0] - th) - CT * (y[1] - W0)
        return [y[1], (tau + MA * DA * R * W0 ** 2 * np.sin(th - y[0])) / (IA + MA * DA ** 2)]
    ref = solve_ivp(arm, (0, END), [np.pi / 6, W0], method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t).y[0]
    p, th = res.position("arm"), W0 * t
    psi = np.unwrap(np.arctan2(p[:, 1] - R * np.sin(th), p[:, 0] - R * np.cos(th)))
    err_a = np.abs(psi - ref).max()
    assert err_a < 1e-8, err_a
    assert np.ptp(psi - th) > 0.2                 # the relative swing is not trivial


def _api_model():
    """The same machine through the API in SI, with mbdsim's own elements (torsion spring, no expression)."""
    m = mb.Model("api", gravity=(0, 0, -9.80665))
    m.add_body("crank", mass=1.0, inertia=(1e-3, 3.5e-3, 3.5e-3), position=(0.05, 0, 0))
    m.add_body("rod", mass=2.0, inertia=(2e-3, 15e-3, 15e-3), position=(0.25, 0, 0))
    m.add_body("slider", mass=0.5, inertia=(1e-4,) * 3, position=(0.4, 0, 0))
    m.add_body("follower", mass=0.8, inertia=(2e-4,) * 3, position=(0.55, 0, 0))
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    m.add_body("arm", mass=MA, inertia=(5e-5, 3e-4, 3e-4), position=(0.1 + DA * c, DA * s, 0), orientation=Rz,
               angular_velocity=(0, 0, W0))
    m.add_revolute("pivot", "ground", "crank", (0, 0, 0), (0, 0, 1))
    m.add_spherical("crank_rod", "crank", "rod", (0.1, 0, 0))
    m.add_universal("rod_slider", "slider", "rod", (0.4, 0, 0), (0, 0, 1), (0, 1, 0))
    m.add_translational("rail", "ground", "slider", (0.4, 0, 0), (1, 0, 0))
    m.add_translational("rail2", "ground", "follower", (0.55, 0, 0), (1, 0, 0))
    m.add_revolute("arm_pin", "crank", "arm", (0.1, 0, 0), (0, 0, 1))
    m.add_motion("drive", "pivot", "2*pi*t")
    m.add_torsion_spring("arm_spring", "arm_pin", KT, CT, free_angle=-np.pi / 6)
    m.add_spring_damper("spring", ("follower", (0.55, 0, 0)), ("slider", (0.4, 0, 0)), 40e3, 500.0, 0.15)
    m.add_bushing("bushing", ("slider", (0.55, 0, 0)), ("follower", (0.55, 0, 0)), (20e3,) * 3 + (0,) * 3,
                  (250.0,) * 3 + (0,) * 3)
    return m


def test_same_as_api_model(imported):
    m, res = imported
    api = mb.simulate(_api_model(), END, output_step=0.01, rtol=1e-10, atol=1e-12)
    for body in ("crank", "rod", "slider", "follower", "arm"):
        assert np.abs(res.position(body) - api.position(body)).max() < 1e-9, body
        assert np.abs(res.angular_velocity(body) - api.angular_velocity(body)).max() < 1e-7, body
    # the motion's effort carries every load of the machine: the same driver torque
    assert np.abs(res.driver_effort("drive") - api.driver_effort("drive")).max() < 1e-6


def test_names_units_and_save(imported, tmp_path):
    m, res = imported
    assert set(m.bodies) == {"ground", "crank", "rod", "slider", "follower", "arm"}
    assert set(m.joints) == {"crank_pivot", "crank_rod", "rod_slider", "slider_rail", "follower_rail", "arm_pin"}
    assert np.allclose(m.gravity, (0, 0, -9.80665))
    assert np.allclose(m.bodies["crank"].inertia, np.diag([1e-3, 3.5e-3, 3.5e-3]))
    assert m.forces["coupling_spring"].stiffness == pytest.approx(40e3)
    assert any("OUTPUT" in n for n in m.import_notes)
    mb.save_model(m, tmp_path / "m.json")       # an ordinary model: saved and read back
    again = mb.simulate(mb.load_model(tmp_path / "m.json"), 0.1, output_step=0.01, rtol=1e-10, atol=1e-12)
    assert np.abs(again.position("arm") - res.at(again.time).position("arm")).max() < 1e-7


def _adm(tmp_path, body, name="t.adm"):
    p = tmp_path / name
    p.write_text("test dataset\n" + body.strip() + "\nEND\n")
    return p


def test_inertia_products_im_marker_and_units(tmp_path):
    """IP about a rotated, offset IM marker in g and cm, written from a known CM inertia with Adams' positive
    product integrals (tensor -Ixy ...): read back rotated into the CM marker's axes and shifted to the CM."""
    J_cm = np.array([[1.0e5, -2.0e3, 1.5e3], [-2.0e3, 1.5e5, 3.0e3], [1.5e3, 3.0e3, 2.0e5]])   # g cm^2, CM axes
    r, mass = np.array([10.0, 0, 0]), 2000.0                                                   # IM offset [cm]
    Rim = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])             # REULER 0, 90D, 0: 90 deg about x
    J_im = Rim.T @ (J_cm + mass * (r @ r * np.eye(3) - np.outer(r, r))) @ Rim
    ip = [J_im[0, 0], J_im[1, 1], J_im[2, 2], -J_im[0, 1], -J_im[0, 2], -J_im[1, 2]]
    p = _adm(tmp_path, f"""
UNITS/FORCE=DYNE, MASS=GRAM, LENGTH=CENTIMETER, TIME=SECOND
PART/1, GROUND
PART/2, MASS={mass}, CM=3, IM=4, QG=1, 2, 3
, IP={', '.join(repr(float(x)) for x in ip)}
MARKER/3, PART=2
MARKER/4, PART=2, QP=10, 0, 0, REULER=0, 90D, 0
ACCGRAV/JGRAV=-981
""")
    m = mb.from_adm(p)
    b = m.bodies["PART_2"]
    assert b.mass == pytest.approx(2.0) and np.allclose(b.position, (0.01, 0.02, 0.03))
    assert np.allclose(b.inertia, J_cm * 1e-7, rtol=0, atol=1e-15)          # g cm^2 -> kg m^2
    assert np.allclose(m.gravity, (0, -9.81, 0))


def test_joint_types_gear_and_coupler(tmp_path):
    """Every JOINT type and JPRIM builds; a GEAR (CV at the pitch point) and a COUPLER drive in their ratios."""
    p = _adm(tmp_path, """
UNITS/SYSTEM=MKS
PART/1, GROUND
MARKER/10, PART=1
MARKER/11, PART=1, QP=0.3, 0, 0
MARKER/12, PART=1, QP=0.1, 0, 0, ZP=0.1, 1, 0
MARKER/13, PART=1, QP=0, 1, 0
PART/2, MASS=1, IP=1, 1, 1
MARKER/20, PART=2
PART/3, MASS=1, IP=1, 1, 1, QG=0.3, 0, 0
MARKER/30, PART=3
PART/4, MASS=1, IP=1, 1, 1, QG=0, 1, 0
MARKER/40, PART=4
MARKER/41, PART=4, ZP=1, 0, 0
MARKER/42, PART=4, REULER=0, 90D, 0
PART/5, MASS=1, IP=1, 1, 1, QG=0, 1, 0
MARKER/50, PART=5
PART/6, MASS=1, IP=1, 1, 1, QG=0, 2, 0
MARKER/60, PART=6, REULER=0, -90D, 0
MARKER/14, PART=1, QP=0, 2, 0, REULER=0, 90D, 0
PART/7, MASS=1, IP=1, 1, 1, QG=0, 3, 0
MARKER/70, PART=7
MARKER/15, PART=1, QP=0, 3, 0
JOINT/1, REVOLUTE, I=20, J=10
JOINT/2, REVOLUTE, I=30, J=11
GEAR/1, JOINTS=1, 2, CV=12
JOINT/3, CYLINDRICAL, I=40, J=13
JOINT/4, SCREW, I=40, J=13, PITCH=0.01
MOTION/1, JOINT=1, FUNCTION=90D*TIME
MOTION/2, JOINT=3, ROTATION, VELOCITY, FUNCTION=2*PI
JOINT/5, HOOKE, I=50, J=41
JOINT/6, CONVEL, I=60, J=14
JPRIM/1, INPLANE, I=70, J=15
""")
    m = mb.from_adm(p)
    assert {j.kind for j in m.joints.values()} >= {"revolute", "cylindrical", "universal", "constant_velocity",
                                                   "inplane"}
    res = mb.simulate(m, 1.0, output_step=0.25, rtol=1e-10, atol=1e-12)
    th1 = res.joint_coordinate("JOINT_1")
    assert np.allclose(th1, np.pi / 2 * res.time, atol=1e-9)
    assert np.allclose(res.joint_coordinate("JOINT_2"), -0.5 * th1, atol=1e-8)       # r1 = 0.1, r2 = 0.2
    cyl = res.joint_coordinate("JOINT_3")
    assert np.allclose(cyl[:, 0], 2 * np.pi * res.time, atol=1e-8)
    assert np.allclose(cyl[:, 1], 0.01 * res.time, atol=1e-9)                         # one pitch per turn


def test_gforce_reaction_conserves_momentum(tmp_path):
    """GFORCE between two free parts (JFLOAT on the second, components in a marker of the first): the
    action-reaction pair conserves linear and angular momentum whatever the loads."""
    p = _adm(tmp_path, """
PART/1, GROUND
PART/2, MASS=2, CM=20, IP=0.1, 0.2, 0.3, QG=0, 0, 0, VX=0.3, WZ=1.5, WX=0.4
MARKER/20, PART=2
MARKER/21, PART=2, QP=0.2, 0.1, 0, REULER=30D, 20D, 0
PART/3, MASS=3, CM=30, IP=0.2, 0.3, 0.4, QG=1, 0.5, 0, WY=-0.7
MARKER/30, PART=3
MARKER/31, PART=3, FLOATING
GFORCE/1, I=21, JFLOAT=31, RM=21
, FX=2*SIN(TIME)\\ FY=STEP(TIME, 0, 0, 0.5, 3)\\ FZ=-DX(21, 30)\\
, TX=0.5\\ TY=-WZ(21)\\ TZ=VARVAL(1)
VARIABLE/1, FUNCTION=0.2*COS(3*TIME)
""")
    m = mb.from_adm(p)
    res = mb.simulate(m, 1.0, output_step=0.05, rtol=1e-11, atol=1e-12)

    def momenta():
        P, H = 0.0, 0.0
        for name in ("PART_2", "PART_3"):
            b = m.bodies[name]
            x, v, w = res.position(name), res.velocity(name), res.angular_velocity(name)
            Rm = res.orientation(name)
            P = P + b.mass * v
            H = H + b.mass * np.cross(x, v) + np.einsum("nij,jk,nlk,nl->ni", Rm, b.inertia, Rm, w)
        return P, H
    P, H = momenta()
    assert np.abs(np.diff(P, axis=0)).max() < 1e-7
    assert np.abs(H - H[0]).max() < 1e-7
    assert np.ptp(res.position("PART_3")[:, 2]) > 1e-3    # the loads did act


@pytest.mark.parametrize("body, line, words", [
    ("PART/1, GROUND\nFOO/3, BAR=1", 3, "unknown statement 'FOO'"),
    ("PART/1, GROUND\nMARKER/2, PART=1\nSFORCE/1, I=2, J=2, TRANSLATIONAL\n, FUNCTION=FROB(TIME)", 5, "FROB"),
    ("PART/1, GROUND\nMARKER/2, PART=1\nJOINT/1, REVOLUTE, I=2, J=9", 4, "MARKER/9"),
    ("PART/1, GROUND\nMARKER/2, PART=1, QQ=1", 3, "unknown or unsupported argument 'QQ'"),
    (", PART=1", 2, "continuation"),
    ("PART/1, GROUND\nBEAM/1, I=1, J=2", 3, "BEAM"),
    ("PART/1, GROUND\nMARKER/2, PART=1\nSFORCE/1, I=2, J=2, ROTATION, FUNCTION=USER(1, 2)", 4, "USER"),
    ("UNITS/LENGTH=FURLONG", 2, "FURLONG"),
    ("PART/1, GROUND\nPART/1, MASS=1", 3, "defined twice"),
])
def test_errors_name_file_and_line(tmp_path, body, line, words):
    p = _adm(tmp_path, body, "broken.adm")
    with pytest.raises(ModelFileError) as exc:
        mb.from_adm(p)
    assert exc.value.file == "broken.adm" and exc.value.line == line, str(exc.value)
    assert words in str(exc.value)


def test_cli_run_and_info(tmp_path):
    from mbdsim.cli.app import app
    out = tmp_path / "r.csv"
    r = CliRunner().invoke(app, ["run", str(EXAMPLE), "--end", "0.05", "--step", "0.01", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert out.stat().st_size > 0 and "slider.x" in out.read_text().splitlines()[0]
    bad = _adm(tmp_path, "PART/1, GROUND\nWIDGET/1", "bad.adm")
    r = CliRunner().invoke(app, ["info", str(bad)])
    assert r.exit_code == 2 and "bad.adm, line 3" in r.output and "WIDGET" in r.output


GROUND_MM = r"""
UNITS/SYSTEM=MMKS
ACCGRAV/KGRAVITY=-9810
PART/1, GROUND
MARKER/10, PART=1
MARKER/11, PART=1, QP=0, 500, 0
MARKER/12, PART=1, QP=0, 1000, 0, REULER=90D, 90D, 0
MARKER/13, PART=1, QP=0, 1500, 0
"""
BALL = GROUND_MM + r"""
PART/2, MASS=1, CM=20, IP=400, 400, 400, QG=0, 0, 20
MARKER/20, PART=2
GRAPHICS/1, ELLIPSOID, CM=20, XSCALE=40, YSCALE=40, ZSCALE=40
GRAPHICS/2, PLANE, RM=10, XMIN=-100, XMAX=100, YMIN=-100, YMAX=100
CONTACT/1, IGEOM=1, JGEOM=2, IMPACT, STIFFNESS=1E5, EXPONENT=1.5, DAMPING=10, DMAX=0.1
"""
PARTS = GROUND_MM + r"""
! torsional oscillator about z
PART/3, MASS=1, CM=30, IP=1000, 1000, 2000, QG=0, 500, 0
MARKER/30, PART=3
JOINT/1, REVOLUTE, I=30, J=11
SPRINGDAMPER/1, ROTATIONAL, I=30, J=11, KT=8000, CT=0, ANGLE=10D
! block on a rail along x with friction and a push
PART/4, MASS=2, CM=40, IP=100, 100, 100, QG=0, 1000, 0
MARKER/40, PART=4
MARKER/41, PART=4, REULER=90D, 90D, 0
JOINT/2, TRANSLATIONAL, I=41, J=12
FRICTION/1, JOINT=2, MU_STATIC=0.5, MU_DYNAMIC=0.4, STICTION_TRANSITION_VELOCITY=1
SFORCE/1, I=40, J=12, TRANSLATIONAL, ACTIONONLY, FUNCTION=5
! slider driven by a velocity motion in mm/s, a VFORCE and a VTORQUE
PART/5, MASS=1, CM=50, IP=100, 100, 100, QG=0, 1500, 0
MARKER/50, PART=5
MARKER/51, PART=5, REULER=90D, 90D, 0
MARKER/52, PART=1, QP=0, 1500, 0, REULER=90D, 90D, 0
JOINT/3, TRANSLATIONAL, I=51, J=52
MOTION/1, JOINT=3, TRANSLATION, VELOCITY, FUNCTION=100
VFORCE/1, I=50, JFLOAT=13, RM=10, FX=0\ FY=1\ FZ=0
VTORQUE/1, I=50, JFLOAT=13, RM=10, TX=0\ TY=0\ TZ=0.5
FIELD/1, I=50, J=13, KMATRIX=10,0,0,0,0,0, 0,10,0,0,0,0, 0,0,10,0,0,0, 0,0,0,0,0,0, 0,0,0,0,0,0, 0,0,0,0,0,0
"""


def test_contact_in_millimetres(tmp_path):
    """A ball resting on a plane (GRAPHICS ELLIPSOID and PLANE, IMPACT contact in N/mm^1.5): its rest
    penetration is (m g / k)^(1/e)."""
    m = mb.from_adm(_adm(tmp_path, BALL))
    with warnings.catch_warnings():   # the stiff contact hands over to the compiled Radau at the target rtol
        warnings.simplefilter("error", mb.AccuracyWarning)
        res = mb.simulate(m, 1.0, output_step=0.01)
    k = 1e5 * 1e-3 ** -1.5                                      # N/mm^1.5 -> N/m^1.5
    assert res.position("PART_2")[-1, 2] == pytest.approx(0.02 - (9.81 / k) ** (1 / 1.5), abs=1e-8)


def test_springdamper_friction_motion_closed_forms(tmp_path):
    """In millimetres: a rotational SPRINGDAMPER (theta = a0 (1 - cos w t)), FRICTION holding a block against
    a 5 N ACTIONONLY SFORCE below mu_s m g, a VELOCITY motion of 100 mm/s; VFORCE, VTORQUE and a diagonal
    FIELD are read."""
    m = mb.from_adm(_adm(tmp_path, PARTS))
    assert any("FIELD" in n for n in m.import_notes) and any("STICTION" in n for n in m.import_notes)
    res = mb.simulate(m, 1.0, output_step=0.01)
    w = np.sqrt(8.0 / 2e-3)                                     # KT 8000 N mm/rad, Izz 2000 kg mm^2
    # the default method's target: 1e-7 of the amplitude (the model runs compiled since issue 29, in absolute
    # coordinates because of the friction; the reference path it took before happened to reach 5e-10)
    assert np.abs(res.joint_coordinate("JOINT_1") - np.radians(10) * (1 - np.cos(w * res.time))).max() < 1e-7 * np.radians(20)
    assert np.abs(res.position("PART_4")[:, 0]).max() < 1e-12
    assert res.friction_force("FRICTION_1")[-1] == pytest.approx(-5.0)
    assert res.joint_coordinate("JOINT_3")[-1] == pytest.approx(0.1, abs=1e-9)

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


def test_part_velocities_in_the_wm_axes_and_at_the_vm_marker(tmp_path):
    """PART WX..WZ are about the axes of the WM marker (default CM); VX..VZ (ground axes) are the velocity of
    the VM marker: v_cm = v_vm + w x (r_cm - r_vm).  A free, spherical (isotropic) part keeps them."""
    m = adm(tmp_path, """
PART/1, GROUND
PART/2, MASS=2, CM=20, IP=0.1, 0.1, 0.1, WM=21, VM=22, WX=0, WY=0, WZ=3, VX=1, VY=0, VZ=0, QG=0, 0, 0
MARKER/20, PART=2, REULER=30D, 0, 0
MARKER/21, PART=2, REULER=0, 90D, 0
MARKER/22, PART=2, QP=0, 0.5, 0
""")
    w_expect = 3.0 * np.array([0.0, -1.0, 0.0])           # z of MARKER/21 (x rotated 90 deg): -y
    v_expect = np.array([1.0, 0, 0]) + np.cross(w_expect, [0.0, -0.5, 0.0])
    res = mb.simulate(m, 0.1, output_step=0.05, rtol=1e-10, atol=1e-12)
    assert np.allclose(res.angular_velocity("PART_2"), w_expect, atol=1e-9)
    assert np.allclose(res.velocity("PART_2"), v_expect, atol=1e-9)


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

"""to_dataframe / to_parquet / to_csv, driver efforts, reactions by name, crossings at the start of a
signal, the cylindrical joint's default DOF.

Column values are checked against closed forms (driven pendulum torque m g l cos(theta), rotor angle)
or against the Result measure of the same name (the column naming contract).
"""
import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb
from mbdsim.errors import ModelError

TIGHT = dict(method="dop853", rtol=1e-11, atol=1e-12)
G = 9.81


def motor_pendulum(w=3.0, m=2.0, L=1.0):
    model = mb.Model("motor", gravity=(0, -G, 0))
    rod = model.add_body("rod", m, (0.01, m * L**2 / 12, m * L**2 / 12), position=(L / 2, 0, 0))
    rod.add_marker("tip", point=(L, 0, 0), orientation=Rotation.from_euler("z", 0.3).as_matrix())
    pin = model.add_revolute("pin", model.ground, rod, (0, 0, 0), (0, 0, 1))
    model.add_motion("motor", pin, displacement=f"{w}*t")
    return model, rod, pin


def test_driver_effort_is_the_torque_holding_a_pendulum_at_constant_speed():
    """theta = w t, theta'' = 0: the motor supplies m g (L/2) cos(theta) about +z."""
    model, rod, pin = motor_pendulum()
    res = mb.kinematics(model, 2.0, 0.05)
    th = 3.0 * res.time
    np.testing.assert_allclose(res.driver_effort("motor"), 2.0 * G * 0.5 * np.cos(th), rtol=0, atol=1e-9)
    df = res.to_dataframe()
    np.testing.assert_allclose(df["motor.effort [N m]"], 2.0 * G * 0.5 * np.cos(th), atol=1e-9)
    with pytest.raises(ModelError, match="motion 'nope'"):
        res.driver_effort("nope")


def test_translational_driver_effort_lifts_a_block():
    model = mb.Model("lift", gravity=(0, 0, -G))
    b = model.add_body("block", 3.0, (1, 1, 1))
    rail = model.add_translational("rail", model.ground, b, (0, 0, 0), (0, 0, 1))
    model.add_motion("jack", rail, displacement="0.5*t**2")          # a = 1 m/s^2 upwards
    res = mb.kinematics(model, 1.0, 0.1)
    np.testing.assert_allclose(res.driver_effort("jack"), 3.0 * (G + 1.0), atol=1e-9)
    assert "jack.effort [N]" in res.to_dataframe().columns


def test_reactions_take_a_body_a_name_or_a_marker_and_any_frame():
    model, rod, pin = motor_pendulum()
    res = mb.kinematics(model, 1.0, 0.1)
    F = res.reaction_force(pin, on=rod)
    np.testing.assert_array_equal(res.reaction_force(pin, on="rod"), F)
    np.testing.assert_array_equal(res.reaction_force("pin", on="rod.tip"), F)
    np.testing.assert_array_equal(res.reaction_force(pin, on="ground"), res.reaction_force(pin, on=model.ground))
    np.testing.assert_allclose(res.reaction_force(pin, on="ground"), -F, atol=1e-12)
    R_tip = res.orientation("rod.tip")
    np.testing.assert_allclose(res.reaction_torque(pin, frame="rod.tip"),
                               np.einsum("nji,nj->ni", R_tip, res.reaction_torque(pin)), atol=1e-12)
    with pytest.raises(ModelError, match=r"'elsewhere'\.on"):
        res.reaction_force(pin, on="elsewhere")
    with pytest.raises(ModelError, match=r"'rod\.nose'\.frame"):
        res.reaction_force(pin, frame="rod.nose")


def test_orientation_columns_round_trip_through_scipy():
    model, rod, pin = motor_pendulum()
    res = mb.kinematics(model, 3.0, 0.1)            # turns past pi: columns stay continuous
    df = res.to_dataframe(markers=True, euler="ZYX")
    q = df[["rod.qw [-]", "rod.qx [-]", "rod.qy [-]", "rod.qz [-]"]].to_numpy()
    R = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    np.testing.assert_allclose(R, res.orientation(rod), atol=1e-12)
    assert np.max(np.abs(np.diff(q, axis=0))) < 0.2                     # no sign flips between samples
    yaw = df["rod.ZYX_1 [rad]"].to_numpy()
    np.testing.assert_allclose(yaw, 3.0 * res.time, atol=1e-10)         # continuous past pi
    np.testing.assert_allclose(df["rod.tip.ZYX_1 [rad]"], 3.0 * res.time + 0.3, atol=1e-10)
    np.testing.assert_allclose(df[["rod.tip.x [m]", "rod.tip.y [m]"]].to_numpy(),
                               np.stack([np.cos(3 * res.time), np.sin(3 * res.time)], -1), atol=1e-10)
    np.testing.assert_allclose(df["rod.alphaz [rad/s^2]"], 0.0, atol=1e-10)
    assert "rod.tip.x [m]" not in res.to_dataframe().columns           # markers on request only


def every_joint_kind():
    """One small subsystem per joint kind, all in one model."""
    m = mb.Model("zoo", gravity=(0, -G, 0))
    pend = m.add_body("pend", 1.0, (0.01, 0.1, 0.1), position=(0.3, 0, 0))
    m.add_revolute("rev", m.ground, pend, (0, 0, 0), (0, 0, 1))
    ball = m.add_body("ball", 1.0, (0.1, 0.2, 0.3), position=(2, -0.5, 0), angular_velocity=(1, 2, 3))
    m.add_spherical("sph", m.ground, ball, (2, 0, 0))
    card = m.add_body("card", 1.0, (0.1, 0.1, 0.1), position=(4, -0.4, 0.1), angular_velocity=(0, 2, 0))
    m.add_universal("uni", m.ground, card, (4, 0, 0), (1, 0, 0), (0, 0, 1))
    puck = m.add_body("puck", 0.5, (1e-3, 1e-3, 2e-3), position=(6, 0, 0), velocity=(1, 0, 0),
                      angular_velocity=(0, 0, 5))
    m.add_planar("pla", m.ground, puck, (6, 0, 0), (0, 0, 1), u_axis=(1, 0, 0))
    sled = m.add_body("sled", 1.0, (0.1, 0.1, 0.1), position=(8, 0, 0), velocity=(0.5, 0, 0))
    m.add_translational("tra", m.ground, sled, (8, 0, 0), (1, 0, 0))
    shaft = m.add_body("shaft", 1.0, (0.1, 0.1, 0.1), position=(10, 0, 0), angular_velocity=(0, 1, 0))
    cyl = m.add_cylindrical("cyl", m.ground, shaft, (10, 0, 0), (0, 1, 0))
    lump = m.add_body("lump", 1.0, (0.1, 0.1, 0.1), position=(10, 0.5, 0))
    m.add_fixed("weld", shaft, lump)
    m.add_torsion_spring("tsp", cyl, stiffness=2.0)
    m.add_spring_damper("sd", (sled, (8, 0, 0)), (m.ground, (9, 0, 0)), stiffness=10.0, damping=0.5)
    return m


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_every_joint_kind_has_named_columns_equal_to_the_measures(tmp_path):
    m = every_joint_kind()
    res = mb.simulate(m, 0.5, 0.05, **TIGHT)
    df = res.to_dataframe()
    expect = {
        "rev": ["angle [rad]", "angle_rate [rad/s]"],
        "sph": ["rx [rad]", "ry [rad]", "rz [rad]", "wx [rad/s]", "wy [rad/s]", "wz [rad/s]"],
        "uni": ["rx [rad]", "wz [rad/s]", "angle1 [rad]", "angle2 [rad]", "angle1_rate [rad/s]",
                "angle2_rate [rad/s]"],
        "pla": ["u [m]", "v [m]", "angle [rad]", "u_rate [m/s]", "v_rate [m/s]", "angle_rate [rad/s]"],
        "tra": ["displacement [m]", "displacement_rate [m/s]"],
        "cyl": ["angle [rad]", "displacement [m]", "angle_rate [rad/s]", "displacement_rate [m/s]"],
        "weld": ["rx [rad]"],
    }
    for joint, names in expect.items():
        for n in names + ["Fx [N]", "Fy [N]", "Fz [N]", "Tx [N m]", "Ty [N m]", "Tz [N m]"]:
            assert f"{joint}.{n}" in df.columns, (joint, n)
    np.testing.assert_array_equal(df["sph.ry [rad]"], res.joint_coordinate("sph")[:, 1])
    np.testing.assert_array_equal(df["uni.angle2 [rad]"], res.joint_coordinate("uni", kind="angles")[:, 1])
    np.testing.assert_array_equal(df["pla.v_rate [m/s]"], res.joint_velocity("pla")[:, 1])
    np.testing.assert_array_equal(df["rev.Fy [N]"], res.reaction_force("rev")[:, 1])
    np.testing.assert_array_equal(df["cyl.Tz [N m]"], res.reaction_torque("cyl")[:, 2])
    np.testing.assert_allclose(df["pla.u [m]"], res.time, atol=1e-9)      # free puck at 1 m/s along u
    np.testing.assert_allclose(df["pla.angle [rad]"], 5 * res.time, atol=1e-9)
    np.testing.assert_array_equal(df["sd.force [N]"], res.spring_force("sd"))
    np.testing.assert_array_equal(df["tsp.torque [N m]"], res.spring_force("tsp"))
    for c in df.columns:
        assert c.endswith(("[s]", "[m]", "[m/s]", "[m/s^2]", "[rad]", "[rad/s]", "[rad/s^2]", "[-]", "[N]",
                           "[N m]")), c
    # files: the same table back
    res.to_parquet(tmp_path / "r.parquet")
    res.to_csv(tmp_path / "r.csv")
    back_pq = pd.read_parquet(tmp_path / "r.parquet")
    back_csv = pd.read_csv(tmp_path / "r.csv")
    assert list(back_pq.columns) == list(df.columns) == list(back_csv.columns)
    np.testing.assert_array_equal(back_pq.to_numpy(), df.to_numpy())
    np.testing.assert_allclose(back_csv.to_numpy(), df.to_numpy(), rtol=1e-15, atol=0)


def test_bushing_columns_are_its_loads_in_marker_i_axes():
    m = mb.Model("bush")
    b = m.add_body("b", 2.0, (0.1, 0.1, 0.1), position=(0, 0, 0.01))
    m.add_bushing("bu", (m.ground, (0, 0, 0)), (b, (0, 0, 0.01)), stiffness=(1e3, 1e3, 400, 50, 50, 50))
    res = mb.simulate(m, 0.1, 0.05, **TIGHT)
    df = res.to_dataframe()
    z = res.position(b)[:, 2]
    np.testing.assert_allclose(df["bu.Fz [N]"], -400 * z, atol=1e-9)    # marker_j starts 0.01 m above
    assert "bu.Tz [N m]" in df.columns


# ----------------------------------------------------------------------------- crossings convention
def test_crossings_at_the_start_and_the_end_of_a_signal():
    """sin(3t) starts at 0: not a crossing at t = 0; its crossings are k pi / 3; a signal arriving at the
    level on the last sample is one, in its direction only."""
    model, rod, pin = motor_pendulum(w=3.0)
    res = mb.kinematics(model, np.pi / 3 * 2, np.pi / 3 / 10)          # ends at exactly 2 pi / 3
    sig = lambda r: np.round(np.sin(r.joint_coordinate("pin")), 15)    # noqa: E731 - exact zeros at samples
    both = res.crossings(sig, 0.0)
    np.testing.assert_allclose(both, [np.pi / 3, 2 * np.pi / 3], atol=1e-12)
    np.testing.assert_allclose(res.crossings(sig, 0.0, direction=-1), [np.pi / 3], atol=1e-12)
    np.testing.assert_allclose(res.crossings(sig, 0.0, direction=+1), [2 * np.pi / 3], atol=1e-12)
    # a level met between samples is refined on the dense output
    np.testing.assert_allclose(res.crossings(lambda r: r.joint_coordinate("pin"), 1.0), [1.0 / 3.0], atol=1e-12)


# ----------------------------------------------------------------------------- cylindrical default DOF
def test_cylindrical_joint_default_dof_is_rotation_for_every_call():
    m = mb.Model()
    b = m.add_body("b", 1.0, (1, 1, 1))
    cyl = m.add_cylindrical("cyl", m.ground, b, (0, 0, 0), (0, 0, 1))
    assert m.add_motion("spin", cyl, displacement="t").dof == "rotation"
    assert m.add_stop("st", cyl, upper=1.0, stiffness=1e3).dof == "rotation"
    assert m.add_stop("st2", cyl, upper=1.0, stiffness=1e3, dof="translation").dof == "translation"

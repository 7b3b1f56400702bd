"""Issue 31 with issue 30: collision geometry of URDF and MJCF files attached for contact on request
(collision=True).  A box dropped on a floor comes to rest at the penetration the IMPACT law predicts
(closed form: four corners share the weight, k delta^e = m g / 4)."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.importers.collision import DEFAULT_CONTACT, mujoco_impact, resting_penetration

G, A, M = 9.81, 0.1, 1.0

URDF = f"""<robot name="drop">
  <link name="world">
    <collision><origin xyz="0 0 -0.05"/><geometry><box size="2 2 0.1"/></geometry></collision>
  </link>
  <link name="cube">
    <inertial><mass value="{M}"/><inertia ixx="{M * A * A / 6}" iyy="{M * A * A / 6}" izz="{M * A * A / 6}"
      ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="{A} {A} {A}"/></geometry></visual>
    <collision><geometry><box size="{A} {A} {A}"/></geometry></collision>
  </link>
  <joint name="free" type="floating"><parent link="world"/><child link="cube"/><origin xyz="0 0 0.12"/></joint>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><sphere radius="0.02"/></geometry></collision></link>
  <joint name="pin" type="revolute"><parent link="world"/><child link="arm"/><origin xyz="1 0 0.01"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""

MJCF = f"""<mujoco model="drop">
  <option gravity="0 0 -{G}"/>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="cube" pos="0 0 0.12">
      <freejoint/>
      <geom name="cube" type="box" size="{A / 2} {A / 2} {A / 2}" mass="{M}"/>
      <geom name="ghost" type="sphere" size="0.01" pos="0 0 0.2" contype="0" conaffinity="0" mass="0"/>
    </body>
  </worldbody>
</mujoco>
"""


def rest_height(model, body="cube", t_end=0.6):
    res = mb.simulate(model, t_end, 0.01)
    assert res.success
    z = res.position(body)[:, 2]
    assert np.max(np.abs(np.diff(z[-10:]))) < 1e-9   # at rest
    return z[-1]


def test_urdf_collision_box_rests_at_the_impact_penetration(tmp_path):
    path = tmp_path / "drop.urdf"
    path.write_text(URDF)
    with pytest.warns(mb.ImportApproximationWarning):
        plain = mb.from_urdf(path)
    assert not any(type(e).__name__ == "ShapeContact" for e in plain.forces.values())
    with pytest.warns(mb.ImportApproximationWarning):
        model = mb.from_urdf(path, collision=True)
    contacts = [e for e in model.forces.values() if type(e).__name__ == "ShapeContact"]
    # the cube against the floor and the arm's sphere; not the arm (through the floor) against the floor it is
    # jointed to
    assert sorted(c.name for c in contacts) == ["contact_cube_arm", "contact_world_cube"]
    assert any("IMPACT" in n for n in model.import_notes)
    k, e = DEFAULT_CONTACT["stiffness"], DEFAULT_CONTACT["exponent"]
    delta = (M * G / 4 / k) ** (1 / e)
    z = rest_height(model)
    assert abs(z - (A / 2 - delta)) < 1e-3 * delta, (z, A / 2 - delta)


def test_urdf_contact_parameters_are_the_users(tmp_path):
    path = tmp_path / "drop.urdf"
    path.write_text(URDF)
    with pytest.warns(mb.ImportApproximationWarning):
        model = mb.from_urdf(path, collision=True, contact={"stiffness": 2e5, "exponent": 1.0, "damping": 800.0})
    c = model.forces["contact_world_cube"]
    assert (c.stiffness, c.exponent, c.damping, c.penetration) == (2e5, 1.0, 800.0, DEFAULT_CONTACT["penetration"])
    z = rest_height(model)
    delta = M * G / 4 / 2e5
    assert abs(z - (A / 2 - delta)) < 1e-3 * delta


def test_mjcf_box_on_plane_rests_at_the_mapped_impact_penetration(tmp_path):
    pytest.importorskip("mujoco")
    path = tmp_path / "drop.xml"
    path.write_text(MJCF)
    with pytest.warns(mb.ImportApproximationWarning):
        model = mb.from_mjcf(path, collision=True)
    contacts = [e for e in model.forces.values() if type(e).__name__ == "ShapeContact"]
    assert len(contacts) == 1                      # the ghost geom (contype=conaffinity=0) collides with nothing
    c = contacts[0]
    r = resting_penetration(G, (0.02, 1.0), (0.9, 0.95, 0.001, 0.5, 2.0))   # MuJoCo's defaults
    assert c.stiffness == pytest.approx(M * G / r, rel=1e-12) and c.exponent == 1.0
    assert c.damping == pytest.approx(2 * np.sqrt(c.stiffness * M), rel=1e-12)   # dampratio 1
    assert c.penetration == pytest.approx(0.1 * r) and c.mu == 1.0               # MuJoCo's default friction
    z = rest_height(model)
    delta = M * G / 4 / c.stiffness                # four corners share the weight
    assert abs(z - (A / 2 - delta)) < 1e-3 * delta, (z, A / 2 - delta)


SPHERE = f"""<mujoco><option gravity="0 0 -{G}" timestep="0.001"/><worldbody>
  <geom name="floor" type="plane" size="2 2 0.1" solref="{{solref}}" solimp="{{solimp}}"/>
  <body name="ball" pos="0 0 0.05"><freejoint/><geom name="ball" type="sphere" size="0.05" mass="{{mass}}"
    solref="{{solref}}" solimp="{{solimp}}"/></body>
</worldbody></mujoco>"""


@pytest.mark.parametrize("solref, solimp, mass", [("0.02 1", "0.9 0.95 0.001 0.5 2", 1.0),
                                                   ("0.01 0.7", "0.8 0.99 0.004 0.3 3", 3.0),
                                                   ("-20000 -300", "0.9 0.95 0.001 0.5 2", 2.0)])
def test_a_sphere_rests_at_mujocos_own_penetration(tmp_path, solref, solimp, mass):
    """One contact: the mapped IMPACT spring holds the sphere at the penetration MuJoCo's soft contact
    gives it, measured by running MuJoCo itself (an independent engine) on the same file."""
    mujoco = pytest.importorskip("mujoco")
    text = SPHERE.format(solref=solref, solimp=solimp, mass=mass)
    mj = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(mj)
    for _ in range(4000):
        mujoco.mj_step(mj, d)
    assert abs(d.qvel[2]) < 1e-9 and d.ncon == 1
    r_mujoco = 0.05 - d.qpos[2]
    path = tmp_path / "ball.xml"
    path.write_text(text)
    with pytest.warns(mb.ImportApproximationWarning):
        model = mb.from_mjcf(path, collision=True)
    z = rest_height(model, "ball", t_end=1.0)
    assert abs((0.05 - z) / r_mujoco - 1) < 1e-7, (0.05 - z, r_mujoco)   # measured: 1e-9


def test_frictionless_condim_and_direct_solref_damping():
    p = mujoco_impact(2.0, G, (-1000.0, -20.0), (0.5, 0.95, 0.001, 0.5, 2), (0.7, 0.005, 1e-4), 1)
    assert p["mu"] == 0.0
    # damping ratio B / (2 sqrt K) with K = 1000 / dwidth^2, B = 20 / dwidth: 20 / (2 sqrt(1000))
    assert p["damping"] == pytest.approx(2 * 20 / (2 * np.sqrt(1000)) * np.sqrt(p["stiffness"] * 2.0), rel=1e-12)


def test_mjcf_contact_pairs_and_exclusions(tmp_path):
    pytest.importorskip("mujoco")
    text = MJCF.replace('<geom name="floor" type="plane" size="2 2 0.1"/>',
                        '<geom name="floor" type="plane" size="2 2 0.1"/>'
                        '<body name="b2" pos="1 0 0.12"><freejoint/><geom name="s2" type="sphere" size="0.05"/></body>')
    text = text.replace("</worldbody>", """</worldbody>
  <contact><exclude body1="cube" body2="b2"/><pair geom1="ghost" geom2="s2" friction="0.3 0.3 0.005 1e-4 1e-4"/></contact>""")
    path = tmp_path / "pairs.xml"
    path.write_text(text)
    with pytest.warns(mb.ImportApproximationWarning):
        model = mb.from_mjcf(path, collision=True)
    names = sorted(n for n, e in model.forces.items() if type(e).__name__ == "ShapeContact")
    assert names == ["contact_floor_cube", "contact_floor_s2", "contact_s2_ghost"], names
    assert model.forces["contact_s2_ghost"].mu == 0.3

"""Adams CONTACT between GRAPHICS shapes (issue 31): a box PART resting on a ground BOX in mm at the IMPACT
closed-form penetration; a CYLINDER PART rolling down an inclined PLANE at g sin(theta) / (1 + I/(m r^2));
a malformed GRAPHICS and a missing EXTERNAL mesh file each give one error naming file and line."""
from __future__ import annotations

import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelFileError

G = 9.81


def _adm(tmp_path, body, name="t.adm"):
    p = tmp_path / name
    p.write_text("test dataset\n" + body.strip() + "\nEND\n")
    return p


def test_box_rests_flat_on_a_ground_box_at_the_impact_penetration(tmp_path):
    """100 mm cube of 1 kg on a 1000 x 1000 x 100 mm ground box whose top is z = 0; STIFFNESS in N/mm^1.5.
    Four corners share the weight: delta = (m g / (4 k))^(1/e)."""
    k_mm, e, a = 100.0, 1.5, 0.1
    k = k_mm * 1e-3 ** -e                                       # N/mm^1.5 -> N/m^1.5
    delta = (G / (4 * k)) ** (1 / e)
    z0_mm = 1e3 * (a / 2 - delta) + 0.02                        # released 20 micrometres above rest
    m = mb.from_adm(_adm(tmp_path, f"""
UNITS/SYSTEM=MMKS
ACCGRAV/KGRAVITY=-9810
PART/1, GROUND
MARKER/10, PART=1, QP=-500, -500, -100
GRAPHICS/1, BOX, CORNER=10, X=1000, Y=1000, Z=100
PART/2, MASS=1, CM=20, IP=1666.667, 1666.667, 1666.667, QG=0, 0, {z0_mm!r}
MARKER/20, PART=2
MARKER/21, PART=2, QP=50, 50, 50, REULER=180D, 0, 0
GRAPHICS/2, BOX, CORNER=21, X=100, Y=100, Z=-100
CONTACT/1, IGEOM=2, JGEOM=1, IMPACT, STIFFNESS={k_mm!r}, EXPONENT={e!r}, DAMPING=0.1, DMAX=0.01,
, COULOMB_FRICTION=ON, MU_STATIC=0.5, MU_DYNAMIC=0.4, STICTION_TRANSITION_VELOCITY=0.1,
, FRICTION_TRANSITION_VELOCITY=1
"""))
    box = m.bodies["PART_2"].shapes["GRAPHICS_2"]               # corner + half the lengths = the CM
    assert np.allclose(box.s_B, 0.0, atol=1e-12) and np.allclose(box.geometry.size, a)
    res = mb.simulate(m, 1.0, 0.01)
    assert res.success
    z = res.position("PART_2")[-1, 2]
    assert abs(z - (a / 2 - delta)) < 1e-3 * delta, (z, a / 2 - delta)
    R = res.orientation("PART_2")[-1]
    assert abs(R[2, 2]) > 1 - 1e-9                              # flat
    assert np.linalg.norm(res.velocity("PART_2")[-1]) < 1e-4


def test_cylinder_rolls_down_an_inclined_plane(tmp_path):
    """Solid cylinder (r 50 mm, L 100 mm, 1 kg, axis along ground x via its CM marker at the base) on a plane
    tilted 15 deg about x, Adams friction (MU_STATIC/MU_DYNAMIC, transition velocities in mm/s): rolling
    without slipping, a = g sin(theta) / (1 + I/(m r^2)) with I = m r^2 / 2."""
    theta, r, L, mass = np.radians(15), 0.05, 0.1, 1.0
    k = 1e6                                                     # 1000 N/mm, exponent 1
    n = np.array([0.0, -np.sin(theta), np.cos(theta)])
    t = -np.array([0.0, np.cos(theta), np.sin(theta)])         # downhill
    delta = mass * G * np.cos(theta) / (2 * k)                 # line contact: a point at each end
    c0 = 1e3 * n * (r - delta)
    I_axis, I_tr = mass * r * r / 2, mass * (3 * r * r + L * L) / 12
    m = mb.from_adm(_adm(tmp_path, f"""
UNITS/SYSTEM=MMKS
ACCGRAV/KGRAVITY=-9810
PART/1, GROUND
MARKER/10, PART=1, REULER=0, {float(np.degrees(theta))!r}D, 0
GRAPHICS/1, PLANE, RM=10
PART/2, MASS={mass!r}, CM=20, IP={I_axis * 1e6!r}, {I_tr * 1e6!r}, {I_tr * 1e6!r}, QG={float(c0[0])!r}, {float(c0[1])!r}, {float(c0[2])!r}
MARKER/20, PART=2
MARKER/21, PART=2, QP=-50, 0, 0, REULER=90D, 90D, 0
GRAPHICS/2, CYLINDER, CM=21, LENGTH=100, RADIUS=50
CONTACT/1, IGEOM=2, JGEOM=1, IMPACT, STIFFNESS=1000, EXPONENT=1, DAMPING=0.2, DMAX=0.1,
, COULOMB_FRICTION=ON, MU_STATIC=0.6, MU_DYNAMIC=0.5, STICTION_TRANSITION_VELOCITY=0.01,
, FRICTION_TRANSITION_VELOCITY=0.1
"""))
    cyl = m.bodies["PART_2"].shapes["GRAPHICS_2"]               # CM marker at the base, extending along its z
    assert np.allclose(cyl.s_B, 0.0, atol=1e-12) and np.allclose(cyl.R_BG[:, 2], (1, 0, 0))
    res = mb.simulate(m, 0.4, 0.005, method="dop853", rtol=1e-8)
    assert res.success
    s = res.position("PART_2") @ t
    keep = res.time >= 0.1
    acc = 2.0 * np.polyfit(res.time[keep], s[keep], 2)[0]
    ref = G * np.sin(theta) / (1 + I_axis / (mass * r * r))
    assert abs(acc / ref - 1) < 1e-3, (acc, ref)


GROUND = """
UNITS/SYSTEM=MMKS
PART/1, GROUND
MARKER/10, PART=1
GRAPHICS/1, PLANE, RM=10
PART/2, MASS=1, CM=20, IP=1, 1, 1, QG=0, 0, 100
MARKER/20, PART=2
"""


@pytest.mark.parametrize("graphics, line, words", [
    ("GRAPHICS/2, CYLINDER, CM=20, RADIUS=10", 8, ("GRAPHICS/2", "LENGTH")),
    ("GRAPHICS/2, EXTERNAL, RM=20, FILE=missing.stl", 8, ("GRAPHICS/2", "FILE", "missing.stl")),
    ("GRAPHICS/2, FRUSTUM, CM=20, LENGTH=10, TOP=5, BOTTOM=10", 8, ("GRAPHICS/2", "TOP", "FRUSTUM")),
])
def test_bad_graphics_name_file_and_line(tmp_path, graphics, line, words):
    path = _adm(tmp_path, GROUND + graphics + "\nCONTACT/1, IGEOM=2, JGEOM=1, IMPACT, STIFFNESS=1E3, EXPONENT=1")
    with pytest.raises(ModelFileError) as exc:
        mb.from_adm(path)
    msg = str(exc.value)
    assert f"t.adm, line {line}" in msg, msg
    assert all(w in msg for w in words), msg


def test_external_mesh_in_dataset_units(tmp_path):
    """EXTERNAL FILE relative to the dataset, coordinates in mm: the mesh reaches 50 mm = 0.05 m."""
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box((100.0, 100.0, 100.0)).export(tmp_path / "cube.stl")
    m = mb.from_adm(_adm(tmp_path, GROUND + "GRAPHICS/2, EXTERNAL, RM=20, FILE=cube.stl\n"
                         "CONTACT/1, IGEOM=2, JGEOM=1, IMPACT, STIFFNESS=1E3, EXPONENT=1"))
    shape = m.bodies["PART_2"].shapes["GRAPHICS_2"] if hasattr(m.bodies["PART_2"], "shapes") else None
    assert shape is not None
    assert np.isclose(np.abs(shape.geometry.vertices).max(), 0.05)

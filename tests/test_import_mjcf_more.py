"""MJCF import (issue 31), checked against MuJoCo's own computation: armature (joint-space rotor inertia,
mj_forward's qacc at a keyframe state) and site-based connect / weld equalities (the loop closes exactly,
and MuJoCo's own equality residual efc_pos is zero at mbdsim's states)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mbdsim as mb

mujoco = pytest.importorskip("mujoco")
FILES = Path(__file__).parent / "import_files"
pytestmark = pytest.mark.filterwarnings("ignore::mbdsim.ImportApproximationWarning")


def test_armature_matches_mujoco_qacc():
    """Armature on a hinge at the world, on a hinge whose parent turns (where a rotor on the parent would
    add cross terms) and on a slide, with damping and gravity, at a keyframe with velocities: the joint
    accelerations equal mj_forward's qacc."""
    path = FILES / "armature.xml"
    m = mb.from_mjcf(path)
    res = mb.simulate(m, 1e-4, output_step=1e-4, rtol=1e-12, atol=1e-14)
    qdd = np.array([res.joint_acceleration(n)[0] for n in ("j1", "j2", "s3")]).ravel()
    mj = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(mj)
    mujoco.mj_resetDataKeyframe(mj, d, 0)
    mujoco.mj_forward(mj, d)
    assert np.abs(qdd - d.qacc).max() < 1e-9, (qdd, d.qacc)
    d0 = mujoco.MjData(mj)                      # the armature matters here: without it qacc differs
    mj.dof_armature[:] = 0.0
    mujoco.mj_resetDataKeyframe(mj, d0, 0)
    mujoco.mj_forward(mj, d0)
    assert np.abs(d0.qacc - d.qacc).max() > 0.1


def _qpos(mj, res, k):
    q = np.zeros(mj.nq)
    q[0] = res.joint_coordinate("swing")[k]
    for body, adr in (("bob", 1), ("plate", 8)):
        q[adr:adr + 3] = res.position(body)[k]
        x, y, z, w = Rotation.from_matrix(res.orientation(body)[k]).as_quat()
        q[adr + 3:adr + 7] = [w, x, y, z]
    return q


def test_site_connect_and_weld_close_exactly_as_mujoco_defines_them():
    """A pendulum carries a free ball by a site connect and a free plate by a site weld, the sites drawn
    1 cm apart: after assembly the site origins (connect) and frames (weld) coincide to < 1e-9 over the
    run, and MuJoCo's own equality residual (efc_pos of the equality rows) is < 1e-9 at mbdsim's states."""
    path = FILES / "sites.xml"
    m = mb.from_mjcf(path)
    assert {m.joints["hang"].kind, m.joints["glue"].kind} == {"spherical", "fixed"}
    res = mb.simulate(m, 0.3, output_step=0.05, rtol=1e-10, atol=1e-12)
    assert np.abs(res.position("bob.hook") - res.position("arm.tip")).max() < 1e-9
    assert np.abs(res.position("plate.foot") - res.position("arm.mount")).max() < 1e-9
    assert np.abs(res.orientation("plate.foot") - res.orientation("arm.mount")).max() < 1e-9
    assert np.ptp(res.joint_coordinate("swing")) > 0.1            # it swings
    mj = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(mj)
    for k in (0, len(res.time) - 1):
        d.qpos[:] = _qpos(mj, res, k)
        mujoco.mj_forward(mj, d)
        eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        assert eq.sum() == 9 and np.abs(d.efc_pos[eq]).max() < 1e-9
    d.qpos[:] = mj.qpos0                                           # as drawn, MuJoCo's residual is 1 cm
    mujoco.mj_forward(mj, d)
    assert np.abs(d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]).max() > 5e-3

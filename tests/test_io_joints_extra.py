"""Model files round-trip the issue-11 elements: joint primitives, screw and constant-velocity joints,
couplers, gears, user constraints, sensors and the planar flag (save -> load -> the same model data)."""
import numpy as np
import pytest

import mbdsim as mb
from mbdsim.errors import ModelError


def model():
    m = mb.Model("extra", gravity=(0, -9.81, 0), planar=True)
    for k in range(8):
        m.add_body(f"b{k}", 1.0, inertia=(0.02, 0.02, 0.03), position=(k, 0, 0))
    m.add_revolute("p1", "ground", "b0", (0, 0, 0), (0, 0, 1))
    m.add_revolute("p2", "ground", "b1", (1, 0, 0), (0, 0, 1))
    m.add_translational("s3", "ground", "b2", (2, 0, 0), (1, 0, 0))
    m.add_gear("mesh", "p1", "p2", -0.5)
    m.add_coupler("rack", "p2", "s3", 0.05)
    m.add_screw("sc", "ground", "b3", (3, 0, 0), (0, 1, 0), lead=0.01)
    m.add_inline("il", "ground", "b4", (4, 0, 0), (0, 0, 1))
    m.add_orientation("or", "ground", "b4")
    m.add_inplane("ip", "ground", "b5", (5, 0, 0), normal=(0, 0, 1))
    m.add_parallel_axes("pa", "ground", "b5", (0, 0, 1))
    m.add_atpoint("ap", "ground", "b6", (6, 0, 0))
    m.add_perpendicular("pp", "ground", "b6", (1, 0, 0), (0, 1, 0))
    m.add_revolute("p7", "ground", "b7", (7, 0, 0), (0, 0, 1))
    m.add_user_constraint("uc", "sin(p7) - 0.2*s3")
    m.add_constant_velocity("cv", "b6", "b7", (6.5, 0, 0), (1, 0, 0), (0.8, 0.6, 0))
    m.add_torque("T", "b0", (0, 0, 0.1))
    m.add_sensor("turn", "p1 - 0.5", direction=1, action="record")
    return m


@pytest.mark.parametrize("ext", ["yaml", "json"])
def test_round_trip(tmp_path, ext):
    m = model()
    path = mb.save_model(m, tmp_path / f"m.{ext}")
    m2 = mb.load_model(path)
    assert mb.io.model_to_dict(m2) == mb.io.model_to_dict(m)
    assert {j.kind for j in m2.joints.values()} >= {"screw", "inline", "orientation", "inplane", "parallel_axes",
                                                    "atpoint", "perpendicular", "constant_velocity"}
    assert np.allclose(m2.planar, [0, 0, 1]) and m2.sensors["turn"].direction == 1
    assert m2.coord_constraints["mesh"].kind == "gear" and m2.joints["sc"].lead == 0.01


def test_callable_sensor_cannot_be_saved(tmp_path):
    m = model()
    m.add_sensor("cb", lambda t, s: t - 1.0)
    with pytest.raises(ModelError, match="sensor 'cb'.*signal"):
        mb.save_model(m, tmp_path / "m.yaml")

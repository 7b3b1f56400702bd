"""Export of a Result to a pandas DataFrame: one row per output time, SI units in the column names.

Columns: "time [s]"; per body or particle (ground axes) "<body>.x [m]", ".y", ".z", "<body>.vx [m/s]",
".vy", ".vz", and for rigid bodies "<body>.wx [rad/s]", ".wy", ".wz"; per joint with a coordinate
"<joint>.angle [rad]" (revolute, cylindrical) and/or "<joint>.displacement [m]" (translational,
cylindrical), each with its rate "<joint>.angle_rate [rad/s]" / "<joint>.displacement_rate [m/s]".
"""
from __future__ import annotations

import numpy as np


def _body_columns(res, body):
    cols = {}
    for key, data, unit in (("", res.position(body), "m"), ("v", res.velocity(body), "m/s")):
        for k, axis in enumerate("xyz"):
            cols[f"{body.name}.{key}{axis} [{unit}]"] = data[:, k]
    if not body.is_particle:
        w = res.angular_velocity(body)
        for k, axis in enumerate("xyz"):
            cols[f"{body.name}.w{axis} [rad/s]"] = w[:, k]
    return cols


def _joint_columns(res, joint):
    kinds = {"revolute": ("angle",), "translational": ("displacement",),
             "cylindrical": ("angle", "displacement")}.get(joint.kind, ())
    if joint.body_j.is_particle:
        kinds = tuple(k for k in kinds if k != "angle")
    if not kinds:
        return {}
    x, xd = np.asarray(res.joint_coordinate(joint)), np.asarray(res.joint_velocity(joint))
    if len(kinds) == 1 and x.ndim == 2:        # cylindrical joint on a particle: keep the slide column
        x, xd = x[:, 1], xd[:, 1]
    x, xd = x.reshape(len(res.time), -1), xd.reshape(len(res.time), -1)
    units = {"angle": "rad", "displacement": "m"}
    cols = {}
    for k, name in enumerate(kinds):
        cols[f"{joint.name}.{name} [{units[name]}]"] = x[:, k]
        cols[f"{joint.name}.{name}_rate [{units[name]}/s]"] = xd[:, k]
    return cols


def to_dataframe(res):
    """Tidy (wide) pandas DataFrame of a Result: time, body positions/velocities, joint coordinates."""
    import pandas as pd

    cols = {"time [s]": np.asarray(res.time, dtype=float)}
    for body in res.system.bodies:
        cols.update(_body_columns(res, body))
    for joint in res.system.model.joints.values():
        cols.update(_joint_columns(res, joint))
    return pd.DataFrame(cols)

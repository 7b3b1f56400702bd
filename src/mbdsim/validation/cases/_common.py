"""Measurement helpers shared by validation cases."""
from __future__ import annotations

import numpy as np


def one_revolution(model, crank_joint, omega):
    """Kinematics over 1.25 revolutions of a crank turning at |omega| [rad/s]; returns (res, t) with t [s]
    the instant the crank has turned exactly one revolution (2 pi, root-found on the dense output), i.e.
    the configuration of the figure again with every transient of the start behind it."""
    import mbdsim as mb

    period = 2 * np.pi / abs(omega)
    res = mb.kinematics(model, end_time=1.25 * period, output_step=period / 100)
    return res, float(res.crossings(lambda r: r.joint_coordinate(crank_joint), 2 * np.pi)[0])

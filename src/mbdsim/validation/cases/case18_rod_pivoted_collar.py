"""Case 18: rod BD driven by crank OB and sliding through a pivoted collar at C; angular acceleration of BD.

Meriam & Kraige 7th ed., p.408, Problem 5/204.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); the compared quantity is in rad/s^2.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.cases._common import one_revolution
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
OMEGA0 = 5.0                  # crank OB [rad/s], constant, clockwise
OB, OC = 0.25, 0.60           # crank length and pivot distance [m] (beta = atan(250/600)), OB normal to OC

MANUAL = {"alpha_BD": (-6.25, -6.24)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=18,
    slug="rod_pivoted_collar",
    title="Rod sliding through a pivoted collar: angular acceleration of BD",
    reference="Meriam & Kraige, Dynamics 7th ed., p.408, Problem 5/204",
    analysis="kinematics",
    statement=(
        "The crank OB (250 mm) turns clockwise at a constant 5 rad/s. The rod BD, pinned to the "
        "crank at B, slides through a collar pivoted at the fixed point C (OC = 600 mm, at right "
        "angles to OB at the instant shown). Find the angular acceleration of BD at that instant."
    ),
    reconstruction=(
        "* beta = atan(250/600) = 22.62 deg and r_A/B = -0.65 i with 0.65 = sqrt(0.25^2 + 0.6^2): "
        "the triangle O-B-C has its right angle at O. The manual's axes are turned so that the rod "
        "is along x: O = (0, 0), B = 0.25(sin beta, cos beta) = (0.0962, 0.2308), C = B - 0.65 i = "
        "0.6(-cos beta, sin beta). The same axes are used here (alpha_z does not depend on them).\n"
        "* Check: v_B = -5 k x r_OB = 1.154 i - 0.481 j (1.154, -0.481), |v_B| = 1.25; v_A = 1.25 cos "
        "beta = 1.153846 (1.154); omega_BD = -1.25 sin beta/0.65 = -0.739645 (-0.74); a_B = "
        "-25 r_OB = -2.403846 i - 5.769231 j (-2.404, -5.769); omega^2 r = 0.3556 i (0.356); "
        "Coriolis 2 omega x v_rel = -1.706873 j (-1.708); alpha = (-5.769231 + 1.706873)/0.65 = "
        "-6.249781 (-6.248, table -6.25).\n"
        "* Model: crank, rod BD (1 m, B at one end) and collar bodies (nominal masses); revolutes "
        "at O (axis -z, driven 5 t), B (crank-rod) and C (ground-collar), translational joint "
        "collar-rod along the rod. The crank turns fully (0.25 < 0.6); alpha_z of BD is read one "
        "revolution after the start (driven coordinate = 2 pi), i.e. at the same configuration."
    ),
    discrepancies=[
        "The relative-acceleration equation is first evaluated with v_rel = 0 and a_rel = 0, which "
        "is wrong for a rod sliding through the collar (v_rel = 1.154 m/s along the rod); the "
        "Coriolis term 2 omega x v_rel is then added separately. The final result is right.",
        "Rounded theory: with omega_BD rounded to 0.74 the Coriolis term is -1.708 and alpha = "
        "-6.248; exactly -1.706873 m/s^2 and alpha_BD = -6.249781 rad/s^2 (table -6.25). RecurDyn's "
        "-6.24 is 0.157 % off.",
        "Unit slips: 'omega_dot_AB = -6.248 rad/s' and 'alpha = -6.248 k rad/s' are in rad/s^2.",
    ],
    notes=["Exact rigid-body kinematics with the prescribed constant crank speed; no approximation."],
)


def geometry():
    """O, B, C [m] in the manual's axes (rod BD along x at the instant shown)."""
    beta = np.arctan2(OB, OC)
    O = np.zeros(3)
    B = OB * np.array([np.sin(beta), np.cos(beta), 0.0])
    C = OC * np.array([-np.cos(beta), np.sin(beta), 0.0])
    return O, B, C


def theory() -> dict:
    """The manual's relative-velocity / relative-acceleration solution, full precision [rad/s^2]."""
    O, B, C = geometry()
    beta = np.arctan2(OB, OC)
    r_AB = np.linalg.norm(C - B)                  # 0.65
    v_B = OMEGA0 * OB
    v_A = v_B * np.cos(beta)                      # along the rod = v_rel
    w_BD = -v_B * np.sin(beta) / r_AB             # clockwise
    a_By = -OMEGA0**2 * B[1]                      # a_B = omega0 x (omega0 x r_OB), j component
    a_cor = 2 * w_BD * v_A                        # 2 omega x v_rel, j component
    return {"alpha_BD": float((a_By - a_cor) / r_AB)}


def build_model():
    """The mechanism at the instant shown, crank driven clockwise at OMEGA0."""
    import mbdsim as mb

    O, B, C = geometry()
    rod_len = 1.0
    u = (C - B) / np.linalg.norm(C - B)           # -x
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    model = mb.Model("case18_pivoted_collar", gravity=(0.0, 0.0, 0.0))
    crank = model.add_body("crank_OB", mass=0.5, inertia=(1e-5, 0.5 * OB**2 / 12, 0.5 * OB**2 / 12),
                           position=B / 2, orientation=rz(np.arctan2(B[1], B[0])))
    rod = model.add_body("rod_BD", mass=1.0, inertia=(1e-5, rod_len**2 / 12, rod_len**2 / 12),
                         position=B + 0.5 * rod_len * u, orientation=rz(np.arctan2(u[1], u[0])))
    collar = model.add_body("collar_C", mass=0.2, inertia=(1e-4, 1e-4, 1e-4), position=C,
                            orientation=rz(np.arctan2(u[1], u[0])))
    model.add_revolute("rev_O", model.ground, crank, point=O, axis=(0, 0, -1))
    model.add_revolute("rev_B", crank, rod, point=B, axis=(0, 0, 1))
    model.add_revolute("rev_C", model.ground, collar, point=C, axis=(0, 0, 1))
    model.add_translational("collar_slide", collar, rod, point=C, axis=u)
    model.add_motion("crank_drive", "rev_O", displacement="5*t")
    return model


def run() -> CaseOutcome:
    model = build_model()
    rod, crank_joint = model.bodies["rod_BD"], model.joints["rev_O"]
    res, t1 = one_revolution(model, crank_joint, OMEGA0)
    a = float(res.at(t1).angular_acceleration(rod)[0, 2])
    th = theory()
    q = [Quantity("alpha_BD", "rad/s^2", th["alpha_BD"], *MANUAL["alpha_BD"], a,
                  note="z component at the configuration shown (one crank revolution after t = 0)")]
    plots = [Plot("Angular acceleration (Z) of BD", res.time, res.angular_acceleration(rod)[:, 2],
                  "time [s]", "alpha_BD [rad/s^2]", mark=(t1, a), mark_label="configuration shown")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)

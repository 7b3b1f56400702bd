"""Case 12: crank driving a pivoted slotted arm (absolute-motion analysis).

Meriam & Kraige 7th ed., p.346, Problem 5/54.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); the compared quantity is in rad/s.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.cases._common import one_revolution
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
# The values the derivation actually uses (the given-data table disagrees, see discrepancies).
OMEGA = 3.0                   # crank speed theta_dot [rad/s], constant
R = 0.1                       # crank length r [m]
L = 0.2                       # distance l between the crank pivot and the arm pivot [m]
THETA = np.radians(45.0)      # crank angle theta at the instant considered

MANUAL = {"omega_AB": (0.572, 0.572)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=12,
    slug="slotted_arm",
    title="Crank and pivoted slotted arm: angular velocity of the arm",
    reference="Meriam & Kraige, Dynamics 7th ed., p.346, Problem 5/54",
    analysis="kinematics",
    statement=(
        "A crank of length r = 0.1 m turns at the constant rate theta_dot = 3 rad/s about a fixed "
        "pivot; its pin slides in the slot of an arm pivoted at a second fixed point at distance "
        "l = 0.2 m from the crank pivot. Find the angular velocity omega = beta_dot of the arm "
        "when the crank angle theta (between the crank and the line of the two pivots) is 45 deg."
    ),
    reconstruction=(
        "* The derivation's triangle: side l (the fixed line of the pivots) and side r (the crank) "
        "enclose theta; beta is the angle of the arm at its pivot, so r sin(theta+beta) = l sin beta "
        "and tan beta = r sin theta/(l - r cos theta). The third side (pivot of the arm to the pin) "
        "varies, i.e. the pin slides along the arm.\n"
        "* Ground frame: crank pivot at the origin, arm pivot P = (-l, 0), pin "
        "C = r(-cos theta, sin theta); the crank turns clockwise (theta increasing), so the arm "
        "angle beta (measured from +x at P) increases and its rotation is counter-clockwise (+z), "
        "the sign the manual's table shows for RecurDyn's Z component.\n"
        "* Check: beta = atan(0.1 sin45/(0.2 - 0.1 cos45)) = 28.675 deg (printed 28.68); omega = "
        "0.1*3*cos 73.675/(0.2 cos 28.675 - 0.1 cos 73.675) = 0.57223 (0.572).\n"
        "* Model: crank, arm and a slider block at the pin (nominal masses); revolutes crank-ground "
        "(axis -z, driven 3 t, so the coordinate is the clockwise crank angle), arm-ground at P, "
        "block-crank at C, and a translational joint block-arm along the arm. The crank turns "
        "fully (r < l); the value is read one revolution after the start (driven coordinate = 2 pi), "
        "i.e. again at theta = 45 deg."
    ),
    discrepancies=[
        "Given-data table disagrees with the derivation: it lists omega = 0.5 rad/s, 'BC' r = 0.2 m "
        "and 'AB' l = 0.1 m, while the derivation uses theta_dot = 3 rad/s, l = 0.2 m, r = 0.1 m "
        "(and the printed result 0.572 rad/s follows only from the latter). With the table's data "
        "the same formulas give beta = 106.32 deg and omega = -0.5954 rad/s. We follow the "
        "derivation.",
        "Point labels are inconsistent (table: 'ABC angle', 'BC', 'AB'; derivation: omega_OA, "
        "omega_AB); the arm's rate is reported under the table's label omega_AB.",
    ],
    notes=["Exact rigid-body kinematics with the prescribed constant crank speed; no approximation."],
)


def geometry(theta: float = THETA):
    """Crank pivot O, arm pivot P and pin C [m] in ground; arm angle beta [rad] from +x at P."""
    beta = np.arctan2(R * np.sin(theta), L - R * np.cos(theta))
    return np.zeros(3), np.array([-L, 0.0, 0.0]), np.array([-R * np.cos(theta), R * np.sin(theta), 0.0]), beta


def theory() -> dict:
    """omega = beta_dot from the differentiated sine rule, in full precision [rad/s]."""
    beta = np.arctan(R * np.sin(THETA) / (L - R * np.cos(THETA)))
    omega = R * OMEGA * np.cos(THETA + beta) / (L * np.cos(beta) - R * np.cos(THETA + beta))
    return {"omega_AB": float(omega)}


def build_model(theta0: float = THETA):
    """Crank + slotted arm at crank angle theta0 [rad], crank driven clockwise at OMEGA."""
    import mbdsim as mb

    O, P, C, beta = geometry(theta0)
    u = np.array([np.cos(beta), np.sin(beta), 0.0])          # arm direction
    rz = lambda a: np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])
    model = mb.Model("case12_slotted_arm", gravity=(0.0, 0.0, 0.0))
    crank = model.add_body("crank", mass=0.5, inertia=(1e-5, 5e-4, 5e-4), position=(O + C) / 2,
                           orientation=rz(np.pi - theta0))
    arm_len = 0.3
    arm = model.add_body("arm", mass=1.0, inertia=(1e-5, arm_len**2 / 12, arm_len**2 / 12),
                         position=P + 0.5 * arm_len * u, orientation=rz(beta))
    block = model.add_body("block", mass=0.1, inertia=(1e-5, 1e-5, 1e-5), position=C, orientation=rz(beta))
    model.add_revolute("rev_O", model.ground, crank, point=O, axis=(0, 0, -1))
    model.add_revolute("rev_P", model.ground, arm, point=P, axis=(0, 0, 1))
    model.add_revolute("rev_C", crank, block, point=C, axis=(0, 0, 1))
    model.add_translational("slot", arm, block, point=C, axis=u)
    model.add_motion("crank_drive", "rev_O", displacement="3*t")
    return model


def run() -> CaseOutcome:
    model = build_model()
    arm, crank_joint = model.bodies["arm"], model.joints["rev_O"]
    res, t45 = one_revolution(model, crank_joint, OMEGA)
    w = float(res.at(t45).angular_velocity(arm)[0, 2])
    th = theory()
    q = [Quantity("omega_AB", "rad/s", th["omega_AB"], *MANUAL["omega_AB"], w,
                  note="z component of the slotted arm's angular velocity at theta = 45 deg")]
    plots = [Plot("Angular velocity of the slotted arm", res.time, res.angular_velocity(arm)[:, 2],
                  "time [s]", "omega_z [rad/s]", mark=(t45, w), mark_label="theta = 45 deg")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)

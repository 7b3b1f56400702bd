"""Case 3: pin of a rotating crank sliding in a slotted link (Meriam & Kraige 7th ed., P2.161).

Planar, ground x-y plane: slotted link pivoted at O (origin), crank pivoted at C = (0.3, 0, 0) m.
Kinematic analysis; SI units internally, table units m/s, m/s^2, rad/s, rad/s^2.
"""
from __future__ import annotations

import numpy as np

import mbdsim as mb
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

OC = 0.300                  # [m] distance between the pivots O (slotted link) and C (crank)
CA = 0.090                  # [m] crank length
BETA0 = np.radians(30.0)    # [rad] crank angle, measured at C from the line C->O
BETA_DOT = 60.0             # [rad/s] constant

MANUAL = {  # name -> (unit, manual theory, manual RecurDyn, note)
    "r_dot": ("m/s", 3.58, 3.58, "table row labelled 'r'; it is r_dot"),
    "r_ddot": ("m/s^2", 315.0, 315.12, "table row labelled 'r_dot'; it is r_ddot"),
    "theta_dot": ("rad/s", 17.88, 17.86, "manual theory misprinted 17.88; its derivation gives 17.86"),
    "theta_ddot": ("rad/s^2", -1510.0, -1510.43, ""),
}

CASE = CaseInfo(
    number=3,
    slug="slotted_link",
    title="Crank pin sliding in a slotted link: r_dot, r_ddot, theta_dot, theta_ddot",
    reference="Meriam & Kraige, Dynamics 7th ed., p.77, P2.161",
    analysis="kinematics (particle, polar coordinates)",
    statement=(
        "The crank CA (90 mm) turns at the constant rate beta_dot = 60 rad/s; its pin A slides in the "
        "slot of the link pivoted at O, 300 mm from C. For beta = 30 deg find r = OA, its rates r_dot "
        "and r_ddot, and the angular velocity theta_dot and angular acceleration theta_ddot of the slotted link."
    ),
    reconstruction=(
        "From the geometric constraint r cos(theta) + 90 cos(beta) = 300, r sin(theta) = 90 sin(beta): "
        "O = (0, 0), C = (0.3, 0) m, A = C + 0.09 (-cos beta, sin beta), beta measured at C from the line "
        "C->O and increasing clockwise (the crank turns clockwise at 60 rad/s, A moves up and away from O); "
        "theta = angle of OA from +x, counter-clockwise.\n\n"
        "Consistency: r cos(theta) = 300 - 77.94 = 222.06 mm, r sin(theta) = 45 mm, theta = 11.46 deg, "
        "r = 226.57 mm, gamma = beta + theta = 41.46 deg; v_A = 90*60 = 5400 mm/s, "
        "a_A = 90*60^2 = 324e3 mm/s^2 toward C; v_A cos(gamma) = 4047 = r theta_dot (theta_dot = +17.86), "
        "v_A sin(gamma) = 3575 = r_dot (+), a_r = a cos(gamma), a_theta = -a sin(gamma) (theta_ddot < 0): the "
        "signs and magnitudes of all printed results follow with this sense of rotation.\n\n"
        "Model: crank body (pivot at C, driven beta = 30 deg + 60 t), slotted link body (revolute at O), "
        "pin A a particle held on the crank by a spherical joint and on the slot line by a translational "
        "joint (its coordinate is r - r0). The crank pivot is a cylindrical joint so that the 3D "
        "constraint set is not redundant: the crank's out-of-plane slide is fixed through the pin by the slot."
    ),
    discrepancies=[
        "The table rows are mislabelled: 'r' = 3.58 is r_dot [m/s] (r itself is 0.22657 m) and "
        "'r_dot' = 315 is r_ddot [m/s^2]; the table gives no units.",
        "Table theory theta_dot = 17.88 rad/s is a misprint: the derivation gives 4046.86/226.57 = 17.86; "
        "full precision 17.86243 rad/s. The printed 0.112 % RecurDyn error is an artefact of the misprint "
        "(recomputed: 0.0136 %).",
        "The derivation rounds gamma to 41.46 deg: v cos(gamma) = 4046.86 (full precision 4047.117 mm/s), "
        "r_dot = 3575.32 (3575.031 mm/s), r_ddot = 315082.68 (315118.34 mm/s^2, so RecurDyn's 315.12 m/s^2 "
        "is 0.0005 % off, not 0.038 %), theta_ddot = -1510.48 (-1510.4256 rad/s^2).",
        "a = 90*beta_dot^2 is printed with the unit mm^2/s; it is 324e3 mm/s^2.",
        "The table theory values are truncated to 3 digits (315, -1510, 3.58); the printed RecurDyn errors "
        "are against those truncated values.",
    ],
    notes=["The derivation is exact (constant crank speed; beta_ddot = 0)."],
)


def theory() -> dict[str, float]:
    """r_dot [m/s], r_ddot [m/s^2], theta_dot [rad/s], theta_ddot [rad/s^2] at beta = 30 deg."""
    x = OC - CA * np.cos(BETA0)             # r cos(theta)
    y = CA * np.sin(BETA0)                  # r sin(theta)
    r, theta = np.hypot(x, y), np.arctan2(y, x)
    gamma = BETA0 + theta
    v, a = CA * BETA_DOT, CA * BETA_DOT**2  # speed and (normal) acceleration of A
    theta_dot = v * np.cos(gamma) / r       # v_theta = r theta_dot = v cos(gamma)
    r_dot = v * np.sin(gamma)               # v_r = v sin(gamma)
    r_ddot = r * theta_dot**2 + a * np.cos(gamma)                 # a_r = a cos(gamma)
    theta_ddot = (-a * np.sin(gamma) - 2.0 * r_dot * theta_dot) / r  # a_theta = -a sin(gamma)
    return {"r_dot": r_dot, "r_ddot": r_ddot, "theta_dot": theta_dot, "theta_ddot": theta_ddot}


def build_model():
    """Returns (model, slotted link, slot joint)."""
    model = mb.Model("slotted_link", gravity=(0.0, 0.0, 0.0))
    c = np.array([OC, 0.0, 0.0])
    a0 = c + CA * np.array([-np.cos(BETA0), np.sin(BETA0), 0.0])
    u = a0 / np.linalg.norm(a0)             # slot direction O->A at t=0
    crank = model.add_body("crank", mass=0.5, inertia=(1e-5, 4e-4, 4e-4), position=(c + a0) / 2)
    link = model.add_body("slotted_link", mass=1.0, inertia=(1e-4, 8e-3, 8e-3), position=0.15 * u)
    pin = model.add_particle("pin_A", mass=0.01, position=a0)
    pivot_c = model.add_cylindrical("pivot_C", model.ground, crank, point=c, axis=(0, 0, -1))
    model.add_revolute("pivot_O", model.ground, link, point=(0, 0, 0), axis=(0, 0, 1))
    model.add_spherical("pin_on_crank", crank, pin, point=a0)
    slot = model.add_translational("slot", link, pin, point=a0, axis=u)
    # axis -z: the joint angle is beta - beta0 (clockwise in the ground x-y plane)
    model.add_motion("beta", pivot_c, displacement="60*t", dof="rotation")
    return model, link, slot


def run() -> CaseOutcome:
    model, link, slot = build_model()
    res = mb.kinematics(model, 0.05, 2.5e-4)
    now = res.at(0.0)                       # beta = 30 deg
    measured = {
        "r_dot": float(now.joint_velocity(slot)[0]),
        "r_ddot": float(now.joint_acceleration(slot)[0]),
        "theta_dot": float(now.angular_velocity(link)[0, 2]),
        "theta_ddot": float(now.angular_acceleration(link)[0, 2]),
    }
    th = theory()
    quantities = [Quantity(n, u, theory=th[n], manual_theory=mt, manual_commercial=mc,
                           mbdsim=measured[n], note=note)
                  for n, (u, mt, mc, note) in MANUAL.items()]
    plots = [
        Plot("Relative velocity and acceleration of the pin in the slot", res.time,
             {"r_dot [m/s]": res.joint_velocity(slot), "r_ddot/100 [m/s^2]": res.joint_acceleration(slot) / 100},
             "t [s]", "r_dot, r_ddot/100", mark=(0.0, measured["r_dot"]), mark_label="beta = 30 deg"),
        Plot("Angular velocity and acceleration of the slotted link", res.time,
             {"theta_dot [rad/s]": res.angular_velocity(link)[:, 2],
              "theta_ddot/100 [rad/s^2]": res.angular_acceleration(link)[:, 2] / 100},
             "t [s]", "theta_dot, theta_ddot/100", mark=(0.0, measured["theta_dot"]), mark_label="beta = 30 deg"),
    ]
    return CaseOutcome(info=CASE, quantities=quantities, model=model, result=res, plots=plots)

"""Case 13: slider-crank, angular velocity and angular acceleration of the connecting rod.

Meriam & Kraige 7th ed., p.347, Problem 5/57.  Planar kinematics in the ground x-y plane,
z out of the plane.  Units: SI (m, s, rad); compared quantities in rad/s and rad/s^2.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.cases._slider_crank import build_slider_crank
from mbdsim.validation.cases._common import one_revolution
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
OMEGA0 = 3.0                  # crank speed [rad/s], constant, clockwise
L = 0.2                       # connecting rod AB [m]
R = 0.1                       # crank OB [m]
THETA = np.radians(60.0)      # angle AOB at the instant considered

MANUAL = {"omega_AB": (0.832, 0.832), "alpha_AB": (-3.99, -3.99)}   # (theory, RecurDyn)

CASE = CaseInfo(
    number=13,
    slug="slider_crank_rod",
    title="Slider-crank: angular velocity and acceleration of the connecting rod",
    reference="Meriam & Kraige, Dynamics 7th ed., p.347, Problem 5/57",
    analysis="kinematics",
    statement=(
        "The crank OB (r = 0.1 m) of a slider-crank turns at the constant rate omega_0 = 3 rad/s; "
        "the connecting rod AB (l = 0.2 m) drives the slider A along the line through O. For "
        "theta = angle AOB = 60 deg find the angular velocity and the angular acceleration of AB "
        "from the absolute-motion relation l sin beta = r sin theta."
    ),
    reconstruction=(
        "* l sin beta = r sin theta: B is at height r sin theta above the slider line through O, "
        "beta is the rod's angle to that line at A.\n"
        "* Ground frame as in case 11: O at the origin, slider line = x axis, A left of O, "
        "B = r(-cos theta, sin theta), A = (-(r cos theta + l cos beta), 0); the crank turns "
        "clockwise (theta increasing) so that the rod angle beta (from +x) is its z rotation: "
        "omega_AB = +beta_dot and alpha_AB = +beta_ddot, the signs the manual prints for RecurDyn's "
        "Z components (+0.832, -3.99).\n"
        "* Check: (r/l) sin 60 = 0.43301, sqrt(1 - 0.1875) = 0.90139; omega_AB = 0.5*3*0.5/0.90139 "
        "= 0.83205 (0.832); alpha_AB = 0.5*9*0.86603*(0.25 - 1)/0.8125^1.5 = -3.99089 (-3.99).\n"
        "* Model: crank, rod and slider bodies (nominal masses), revolutes at O (axis -z, driven "
        "3 t), B and A, translational slider along x. Read one crank revolution after the start "
        "(driven coordinate = 2 pi), i.e. again at theta = 60 deg."
    ),
    discrepancies=[],
    notes=["Exact rigid-body kinematics with the prescribed constant crank speed; no approximation. "
           "No slip found in this case: both printed values are the correctly rounded formulas."],
)


def theory() -> dict:
    """The manual's closed forms for beta_dot and beta_ddot (theta_ddot = 0), full precision."""
    k = R / L
    s = k * np.sin(THETA)
    omega = k * OMEGA0 * np.cos(THETA) / np.sqrt(1 - s**2)
    alpha = k * OMEGA0**2 * np.sin(THETA) * (k**2 - 1) / (1 - s**2) ** 1.5
    return {"omega_AB": float(omega), "alpha_AB": float(alpha)}


def build_model(theta0: float = THETA):
    """Slider-crank at crank angle theta0 [rad], crank driven clockwise at OMEGA0."""
    return build_slider_crank("case13_slider_crank", R, L, theta0, "3*t", masses=(0.5, 1.0, 0.5),
                              slider="slider", axial_inertia=1e-5)


def run() -> CaseOutcome:
    model = build_model()
    rod, crank_joint = model.bodies["rod"], model.joints["rev_O"]
    res, t60 = one_revolution(model, crank_joint, OMEGA0)
    at = res.at(t60)
    w = float(at.angular_velocity(rod)[0, 2])
    a = float(at.angular_acceleration(rod)[0, 2])
    th = theory()
    q = [
        Quantity("omega_AB", "rad/s", th["omega_AB"], *MANUAL["omega_AB"], w,
                 note="z component at theta = 60 deg"),
        Quantity("alpha_AB", "rad/s^2", th["alpha_AB"], *MANUAL["alpha_AB"], a,
                 note="z component at theta = 60 deg"),
    ]
    plots = [
        Plot("Angular velocity of the connecting rod", res.time, res.angular_velocity(rod)[:, 2],
             "time [s]", "omega_AB [rad/s]", mark=(t60, w), mark_label="theta = 60 deg"),
        Plot("Angular acceleration of the connecting rod", res.time,
             res.angular_acceleration(rod)[:, 2], "time [s]", "alpha_AB [rad/s^2]",
             mark=(t60, a), mark_label="theta = 60 deg"),
    ]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)

"""Case 28: bar falling from the vertical against a spring, minimum angular velocity and speed at horizontal.

Meriam & Kraige 7th ed., p.511, P6/229.  Planar dynamics in the ground x-y plane, z out of the
plane, gravity (0, -9.81, 0).  Units: SI (m, kg, s, rad); table units rad/s and deg.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
G = 9.81
MASS = 30.0           # uniform slender bar [kg]
L = 2.4               # bar length [m]
K = 3000.0            # spring stiffness [N/m]
OMEGA0 = 4.0          # angular velocity in the vertical position, spring undeformed [rad/s]
A = 1.2               # spring anchor C from O, and attachment on the bar from O [m]

# printed in the manual's comparison table: (theory, RecurDyn)
MANUAL = {"omega_min": (0.909, 0.901), "theta": (73.79, 73.99), "omega_90": (1.589, 1.599)}

CASE = CaseInfo(
    number=28,
    slug="bar_spring_min_speed",
    title="Bar falling from the vertical against a spring: minimum angular velocity",
    reference="Meriam & Kraige, Dynamics 7th ed., p.511, P6/229",
    analysis="dynamics (work-energy)",
    statement=(
        "The uniform 30-kg bar (2.4 m) is pivoted at its lower end O and passes the vertical "
        "position with angular velocity 4 rad/s, at which position the spring (k = 3 kN/m), "
        "connecting the bar's midpoint to a fixed point 1.2 m from O on the horizontal through "
        "O, is undeformed. Find the minimum angular velocity of the bar, the angle theta from "
        "the vertical where it occurs, and the angular velocity when the bar is horizontal "
        "(theta = 90 deg, its centre of mass at the height of O)."
    ),
    reconstruction=(
        "* Ground frame: O at the origin, the bar vertical at t = 0 with G = (0, 1.2) and the "
        "spring attached at G (1.2 m from O); the anchor C = (-1.2, 0); the bar falls clockwise "
        "(towards +x) by theta, so the angle COG is 90 deg + theta: l^2 = 2*1.2^2(1 + sin theta), "
        "l0 = 1.2 sqrt 2, as printed. The height of G is 1.2 cos theta (drop 1.2(1 - cos theta)).\n"
        "* Consistency: I_O = 30*2.4^2/3 = 57.6, (1/2)57.6*4^2 = 460.8, 30*9.81*1.2 = 353.16, "
        "813.96 = 460.8 + 353.16, (1/2)3000(1.2 sqrt2)^2 = 4320, 28.8 = 57.6/2; divided by 28.8: "
        "150, 300, 7826.04/28.8 = 271.7375 (printed 271.74), 353.16/28.8 = 12.2625 (12.263).\n"
        "* The data 'l2 = 0.2 m' enters no equation of the derivation; it is not used.\n"
        "* Model: bar 30 kg, I_G = m L^2/12; revolute O with axis -z (coordinate = clockwise "
        "angle theta from the vertical); spring-damper ground C - bar at G, k = 3000 N/m, free "
        "length 1.2 sqrt 2, no damping; initial angular velocity (0, 0, -4) rad/s and the "
        "matching velocity of G (4.8, 0, 0) m/s. omega_min = minimum of the clockwise angular "
        "velocity (res.minimum), theta = joint angle there, omega at the crossing of theta = 90 deg."
    ),
    discrepancies=[
        "omega_min: the derivation's constant 271.74 is rounded from 271.7375; omega_min^2 is a "
        "small difference of large terms, so the rounding moves omega_min from 0.91016 rad/s (full "
        "precision) to 0.9088 (printed 0.909). RecurDyn's 0.901 is 1.006 % off, not 0.88 %.",
        "theta at omega_min: the root of d(omega^2)/dtheta = -150 cos + 150 cos/sqrt(1+sin) + "
        "12.2625 sin = 0 is 1.292368 rad = 74.0472 deg, not 1.2879 rad = 73.79 deg. RecurDyn's "
        "73.99 deg is 0.077 % from it (printed 0.271 %).",
        "omega at theta = 90 deg: 1.589518 rad/s (printed 1.589); RecurDyn's 1.599 is 0.597 % off "
        "(printed 0.629 %).",
        "I_O = 57.6 is printed with unit 'm'; it is kg m^2.",
        "Table row label omega_AB,h=0: the angular velocity of the bar at theta = 90 deg "
        "(h = 0: G at the height of O).",
    ],
    notes=[
        "Exact energy balance (massless linear spring, frictionless pin): no approximation, no "
        "variant. RecurDyn's omega_min and omega_90 are both about 1 % and 0.6 % off, more than "
        "its other results, which suggests a different model (a bar inertia that is not "
        "m L^2/3, for instance); the manual does not say.",
    ],
)


def _omega2(theta: float) -> float:
    """omega^2 [rad^2/s^2] from the work-energy equation at angle theta [rad] from the vertical."""
    I_O = MASS * L**2 / 3
    delta = A * np.sqrt(2) * (np.sqrt(1 + np.sin(theta)) - 1)
    return (0.5 * I_O * OMEGA0**2 + MASS * G * A * (1 - np.cos(theta)) - 0.5 * K * delta**2) / (0.5 * I_O)


def theory() -> dict:
    """omega_min [rad/s], theta at omega_min [deg], omega at theta = 90 deg [rad/s]."""
    I_O = MASS * L**2 / 3
    c_s = 0.5 * K * 2 * A**2 / (0.5 * I_O)                     # 150
    c_g = MASS * G * A / (0.5 * I_O)                          # 12.2625
    d_omega2 = lambda t: -c_s * np.cos(t) + c_s * np.cos(t) / np.sqrt(1 + np.sin(t)) + c_g * np.sin(t)
    th = brentq(d_omega2, 0.5, 1.5, xtol=1e-15)
    return {"omega_min": float(np.sqrt(_omega2(th))), "theta": float(np.degrees(th)),
            "omega_90": float(np.sqrt(_omega2(np.pi / 2)))}


def build_model():
    """Bar vertical, spring undeformed, turning clockwise at OMEGA0."""
    import mbdsim as mb

    model = mb.Model("case28_bar_spring", gravity=(0.0, -G, 0.0))
    I_G = MASS * L**2 / 12
    rz90 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # body x along +y
    bar = model.add_body("bar", mass=MASS, inertia=(1e-3, I_G, I_G), position=(0.0, L / 2, 0.0),
                         orientation=rz90, velocity=(OMEGA0 * L / 2, 0.0, 0.0),
                         angular_velocity=(0.0, 0.0, -OMEGA0))
    model.add_revolute("rev_O", model.ground, bar, point=(0.0, 0.0, 0.0), axis=(0.0, 0.0, -1.0))
    model.add_spring_damper("spring", (model.ground, (-A, 0.0, 0.0)), (bar, (0.0, A, 0.0)),
                            stiffness=K, damping=0.0, free_length=A * np.sqrt(2))
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    bar, rev = model.bodies["bar"], model.joints["rev_O"]
    res = mb.simulate(model, 0.9, output_step=0.002, method="dop853", rtol=1e-10, atol=1e-12)
    w_cw = lambda r: -r.angular_velocity(bar)[:, 2]
    t_min, w_min = res.minimum(w_cw)
    th_min = float(np.degrees(res.at(t_min).joint_coordinate(rev)[0]))
    t90 = res.crossings(lambda r: r.joint_coordinate(rev), np.pi / 2, direction=1)[0]
    w90 = float(w_cw(res.at(t90))[0])
    th = theory()
    q = [
        Quantity("omega_min", "rad/s", th["omega_min"], *MANUAL["omega_min"], float(w_min),
                 note="minimum clockwise angular velocity between the vertical and the horizontal"),
        Quantity("theta", "deg", th["theta"], *MANUAL["theta"], th_min,
                 note="joint angle from the vertical at omega_min"),
        Quantity("omega_AB,h=0", "rad/s", th["omega_90"], *MANUAL["omega_90"], w90,
                 note="angular velocity at theta = 90 deg (G at the height of O)"),
    ]
    deg = np.degrees(res.joint_coordinate(rev))
    plots = [
        Plot("Angular velocity of the bar (clockwise)", deg, w_cw(res), "theta [deg]", "omega [rad/s]",
             mark=(th_min, float(w_min)), mark_label="minimum"),
        Plot("Angular velocity of the bar (clockwise)", deg, w_cw(res), "theta [deg]", "omega [rad/s]",
             mark=(90.0, w90), mark_label="theta = 90 deg"),
    ]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)

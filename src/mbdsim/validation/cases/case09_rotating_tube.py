"""Case 9: particle sliding out of a tube that rotates at constant rate in a vertical plane (M&K 7th ed., P3.350).

Planar, ground x-y plane (y up), gravity (0, -9.81, 0); the tube pivots about the z axis at O (origin),
horizontal along +x at t = 0 and turning clockwise (theta measured below the horizontal).
Dynamics; SI units, table units s and deg.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

import mbdsim as mb
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

G = 9.81            # [m/s^2] (4 omega0^2 / g = 0.10194 in the derivation)
LENGTH = 1.0        # [m] tube length: the particle leaves the tube at r = 1 m
OMEGA0 = 0.5        # [rad/s] constant angular velocity of the tube

MANUAL = {  # name -> (unit, manual theory, manual RecurDyn)
    "t": ("s", 1.07, 1.068),
    "theta": ("deg", 30.653, 30.681),
}

CASE = CaseInfo(
    number=9,
    slug="rotating_tube",
    title="Particle leaving a tube rotating at constant speed in a vertical plane",
    reference="Meriam & Kraige, Dynamics 7th ed., p.263, P3.350",
    analysis="dynamics (particle, polar coordinates, Newton's second law)",
    statement=(
        "A smooth tube of length 1 m rotates in the vertical plane about a horizontal axis through its end O "
        "at the constant rate omega0 = 0.5 rad/s. A particle is at rest at O (r = 0, r_dot = 0) when the "
        "tube is horizontal (theta = 0) and turning downward. Find the time t and the angle theta when the "
        "particle leaves the tube (r = 1 m)."
    ),
    reconstruction=(
        "O at the origin, the tube along +x at t = 0 turning clockwise, theta = omega0 t below the "
        "horizontal (revolute about -z, driven theta = 0.5 t); the particle (1 kg; the mass does not enter) "
        "on a frictionless translational joint along the tube, starting at O at rest. Gravity along the "
        "tube is g sin(theta) outward, so r_ddot - r omega0^2 = g sin(omega0 t).\n\n"
        "Consistency: r = g/(4 omega0^2) (e^theta - e^-theta - 2 sin theta); with r = 1 m, "
        "4 omega0^2/g = 4*0.25/9.81 = 0.10194; the root is theta = 0.5347 rad, t = 0.5347/0.5 = 1.07 s."
    ),
    discrepancies=[
        "The table's theta = 30.653 deg is 0.535 rad converted after rounding; the root 0.5347203 rad is "
        "30.63722 deg. The full-precision time is 1.069441 s (table: 1.07).",
        "The printed RecurDyn error for theta, 0.009 %, is ten times too small: |30.681 - 30.653|/30.653 = "
        "0.091 %; against the exact 30.63722 deg it is 0.143 %. For t, against 1.069441 s: 0.135 % "
        "(printed 0.187 % against the rounded 1.07).",
        "RecurDyn's two results contradict each other: theta = omega0 t, but 1.068 s gives 30.596 deg, "
        "not 30.681 deg.",
        "Type of analysis is given as 'work-energy equation'; the derivation uses Newton's second law in "
        "polar coordinates.",
    ],
    notes=["The derivation is exact for a smooth tube turning at exactly constant speed (the tube is driven)."],
)


def theory() -> dict[str, float]:
    """t [s] and theta [deg] at r = 1 m, root of (g / 4 omega0^2)(e^th - e^-th - 2 sin th) = r."""
    f = lambda th: np.exp(th) - np.exp(-th) - 2.0 * np.sin(th) - 4.0 * OMEGA0**2 * LENGTH / G  # noqa: E731
    theta = brentq(f, 0.1, 2.0, xtol=1e-15, rtol=1e-15)
    return {"t": theta / OMEGA0, "theta": float(np.degrees(theta))}


def build_model():
    """Returns (model, pivot joint, slide joint)."""
    model = mb.Model("rotating_tube", gravity=(0.0, -G, 0.0))
    tube = model.add_body("tube", mass=1.0, inertia=(1e-3, 0.1, 0.1), position=(LENGTH / 2, 0.0, 0.0))
    ball = model.add_particle("particle", mass=1.0, position=(0.0, 0.0, 0.0))
    pivot = model.add_revolute("pivot_O", model.ground, tube, point=(0, 0, 0), axis=(0, 0, -1))
    slide = model.add_translational("tube_slide", tube, ball, point=(0, 0, 0), axis=(1, 0, 0))
    model.add_motion("omega0", pivot, displacement="0.5*t")   # theta = omega0 t, clockwise
    return model, pivot, slide


def run() -> CaseOutcome:
    model, pivot, slide = build_model()
    res = mb.simulate(model, 1.5, output_step=0.005, method="dop853", rtol=1e-10, atol=1e-12)
    r = lambda rr: rr.joint_coordinate(slide)   # noqa: E731
    t_exit = float(res.crossings(r, LENGTH, direction=1)[0])     # "time when the slider displacement is 1 m"
    theta = float(np.degrees(res.at(t_exit).joint_coordinate(pivot)[0]))
    th = theory()
    measured = {"t": t_exit, "theta": theta}
    quantities = [Quantity(n, u, theory=th[n], manual_theory=mt, manual_commercial=mc, mbdsim=measured[n])
                  for n, (u, mt, mc) in MANUAL.items()]
    plots = [
        Plot("Displacement of the particle in the tube", res.time, r(res), "t [s]", "r [m]",
             mark=(t_exit, LENGTH), mark_label=f"r = 1 m at t = {t_exit:.6f} s"),
        Plot("Rotation angle of the tube against the particle's displacement", r(res),
             np.degrees(res.joint_coordinate(pivot)), "r [m]", "theta [deg]",
             mark=(LENGTH, theta), mark_label=f"theta = {theta:.5f} deg"),
    ]
    return CaseOutcome(info=CASE, quantities=quantities, model=model, result=res, plots=plots)

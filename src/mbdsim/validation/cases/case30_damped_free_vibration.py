"""Case 30: free vibration of a viscously damped spring-mass system, first negative peak.

Meriam & Kraige 7th ed., p.598, P8/36.  One-DOF dynamics: a block on a translational joint along
the ground x axis, spring-damper along x; gravity (0, -9.81, 0) is carried by the joint.
Units: SI (m, kg, s, N); table units m and s.
"""
from __future__ import annotations

import numpy as np

from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

# ----------------------------------------------------------------------------- given data
MASS = 3.0        # [kg]
K = 108.0         # [N/m]
C = 18.0          # [N s/m]
X0 = 0.3          # initial displacement, released from rest [m]
L0 = 1.0          # nominal free length of the spring-damper [m] (does not enter)

# the comparison table of the manual is empty; these are printed in the derivation
MANUAL_DERIVATION = {"x1": -0.0489, "t1": 0.605}

CASE = CaseInfo(
    number=30,
    slug="damped_free_vibration",
    title="Damped free vibration: displacement after half a damped period",
    reference="Meriam & Kraige, Dynamics 7th ed., p.598, P8/36",
    analysis="dynamics",
    statement=(
        "A 3-kg mass on a spring (k = 108 N/m) with a viscous damper (c = 18 N s/m) is displaced "
        "x0 = 0.3 m from equilibrium and released from rest. Find the displacement x1 after "
        "half a damped period, the first extreme on the opposite side."
    ),
    reconstruction=(
        "* Ground frame: the block slides along x on a translational joint; the spring-damper "
        "runs from the ground anchor (0, 0, 0) to the block's centre of mass, free length 1 m "
        "(nominal), so the deformation x = spring length - 1 m, and the block starts at x = 0.3 m "
        "at rest. A horizontal arrangement (or a vertical one measured from equilibrium) gives "
        "the same equation m x'' + c x' + k x = 0.\n"
        "* Consistency: omega_n = sqrt(108/3) = 6 rad/s, zeta = 18/(2 sqrt(324)) = 0.5, omega_d = "
        "5.19615 rad/s, A2 = zeta omega_n/omega_d x0 = 0.57735 x0; the damped period is "
        "tau_d = 2 pi/omega_d = 1.20920 s and x(tau_d/2) = -x0 exp(-pi zeta/sqrt(1 - zeta^2)) = "
        "-0.163034 x0 = -0.0489101 m.\n"
        "* x' is proportional to -sin(omega_d t) exp(-3t), so tau_d/2 is exactly the time of the "
        "first minimum of x: the spring deformation's minimum (res.minimum) gives both x1 and "
        "its time, the reading RecurDyn's DEFL_TSDA plot offers."
    ),
    discrepancies=[
        "The comparison table has no rows: no theory or RecurDyn value is printed. The values "
        "compared here are the derivation's x1 = -0.0489 m and t = 0.605 s.",
        "'omega_d = 5.196/(2 pi) Hz = 0.827 Hz' is the damped frequency f_d, not omega_d; "
        "'T = 1/omega_d = 1.209 s' should read tau_d = 1/f_d = 2 pi/omega_d = 1.2092 s.",
    ],
    notes=[
        "Linear viscous damping exactly as in the derivation; no approximation, no variant.",
    ],
)


def theory() -> dict:
    """x1 = x(tau_d/2) [m] and tau_d/2 [s] from the closed-form damped response."""
    w_n = np.sqrt(K / MASS)
    zeta = C / (2 * np.sqrt(MASS * K))
    w_d = w_n * np.sqrt(1 - zeta**2)
    A1, A2 = X0, zeta * w_n / w_d * X0
    t1 = np.pi / w_d                                          # half the damped period
    x1 = (A1 * np.cos(w_d * t1) + A2 * np.sin(w_d * t1)) * np.exp(-zeta * w_n * t1)
    return {"x1": float(x1), "t1": float(t1)}


def build_model():
    """Block at x = x0 at rest, spring-damper to the ground along x."""
    import mbdsim as mb

    model = mb.Model("case30_damped_oscillator", gravity=(0.0, -9.81, 0.0))
    pos = np.array([L0 + X0, 0.0, 0.0])
    block = model.add_body("block", mass=MASS, inertia=(0.01, 0.01, 0.01), position=pos)
    model.add_translational("slide", model.ground, block, point=pos, axis=(1.0, 0.0, 0.0))
    model.add_spring_damper("spring1", (model.ground, (0.0, 0.0, 0.0)), (block, pos),
                            stiffness=K, damping=C, free_length=L0)
    return model


def run() -> CaseOutcome:
    import mbdsim as mb

    model = build_model()
    spring = model.forces["spring1"]
    res = mb.simulate(model, 1.0, output_step=0.002, method="dop853", rtol=1e-10, atol=1e-12)
    defl = lambda r: r.spring_length(spring) - L0
    t1, x1 = res.minimum(defl)
    th = theory()
    q = [
        Quantity("x1", "m", th["x1"], MANUAL_DERIVATION["x1"], None, float(x1),
                 note="minimum of the spring deformation (first negative peak); manual table "
                      "empty, manual value from the derivation"),
        Quantity("t at x1", "s", th["t1"], MANUAL_DERIVATION["t1"], None, float(t1),
                 note="time of that minimum = half the damped period; manual value from the derivation"),
    ]
    plots = [Plot("Deformation of Spring1 (DEFL_TSDA)", res.time, defl(res), "time [s]", "x [m]",
                  mark=(float(t1), float(x1)), mark_label="x1 at tau_d/2")]
    return CaseOutcome(info=CASE, quantities=q, model=model, result=res, plots=plots)

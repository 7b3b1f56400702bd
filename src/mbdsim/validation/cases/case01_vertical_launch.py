"""Case 1: ball launched vertically (Meriam & Kraige 7th ed., P2.13).

A particle moves on the ground y axis (up) under gravity (0, -g, 0); SI units, ground frame.
The manual's derivation uses g = 9.807 m/s^2, so the model does too.
"""
from __future__ import annotations

import numpy as np

import mbdsim as mb
from mbdsim.validation.framework import CaseInfo, CaseOutcome, Plot, Quantity

G = 9.807          # [m/s^2] the derivation's value (9.807 * t = 25 -> t = 2.549 s)
V0 = 25.0          # [m/s] launch speed, upward
CLIFF = 15.0       # [m] height of the cliff top B above the launch point A

# name -> (unit, manual theory, manual RecurDyn), as printed in the comparison table
MANUAL = {
    "h": ("m", 16.865, 16.866),
    "t": ("s", 4.404, 4.404),
    "v_B": ("m/s", 18.188, 18.189),
}

CASE = CaseInfo(
    number=1,
    slug="vertical_launch",
    title="Ball thrown vertically upward past a 15 m cliff",
    reference="Meriam & Kraige, Dynamics 7th ed., p.31, P2.13",
    analysis="dynamics (particle, rectilinear motion)",
    statement=(
        "A ball is thrown vertically upward with an initial speed of 25 m/s from the base A of a "
        "15 m cliff. Determine the distance *h* by which the ball clears the top of the cliff, the "
        "time *t* after release for the ball to land at B on the top of the cliff, and its speed "
        "*v_B* there. Air resistance and the small horizontal motion are neglected."
    ),
    reconstruction=(
        "No figure is needed beyond the given data: launch point A at the origin, the cliff top B at "
        "y = 15 m, ball = particle of 1 kg (the mass does not enter), initial velocity (0, 25, 0) m/s, "
        "gravity (0, -9.807, 0) m/s^2.\n\n"
        "Consistency: 25/9.807 = 2.549 s to the top; 25^2/(2*9.807) = 31.865 m maximum height; "
        "h = 31.865 - 15 = 16.865 m; v_B = sqrt(2*9.807*16.865) = 18.188 m/s; fall time "
        "18.188/9.807 = 1.855 s; total 2.549 + 1.855 = 4.404 s: every printed number follows."
    ),
    discrepancies=[
        "Error column recomputed against the full-precision theory: t = 4.403756 s, so RecurDyn's "
        "4.404 s is 0.0055 % off (printed 0 %); v_B = 18.187633 m/s, so RecurDyn's 18.189 m/s is "
        "0.0075 % off (printed 0.005 %); h = 16.864994 m, RecurDyn 16.866 m is 0.0060 % off.",
        "Section 5 prints V_B = 18.188 without a unit (m/s); the table labels it v_s.",
    ],
    notes=[
        "The derivation uses g = 9.807 m/s^2 (not 9.81); the model uses the same value. "
        "RecurDyn's h = 16.866 m matches standard gravity 9.80665 m/s^2 (16.8656 m) better.",
    ],
)


def theory() -> dict[str, float]:
    """h [m], t [s] (launch to landing at B on the way down), v_B [m/s], from the formulas."""
    t_top = V0 / G                          # V = V0 - g t = 0
    s_max = V0 * t_top - 0.5 * G * t_top**2  # S = V0 t - g t^2 / 2
    h = s_max - CLIFF
    v_b = np.sqrt(2.0 * G * h)              # V_B^2 - 0 = 2 g h
    t_fall = v_b / G
    return {"h": h, "t": t_top + t_fall, "v_B": v_b}


def build_model() -> tuple[mb.Model, object]:
    """The ball as a particle at the origin moving up the ground y axis."""
    model = mb.Model("vertical_launch", gravity=(0.0, -G, 0.0))
    ball = model.add_particle("ball", mass=1.0, position=(0.0, 0.0, 0.0), velocity=(0.0, V0, 0.0))
    return model, ball


def run() -> CaseOutcome:
    model, ball = build_model()
    res = mb.simulate(model, 5.0, output_step=0.01, method="dop853", rtol=1e-10, atol=1e-12)
    height = lambda r: r.position(ball)[:, 1]  # noqa: E731

    _, y_max = res.maximum(height)
    # "time when the ball reaches a height of 15 m" (on the way down)
    t_b = res.crossings(height, CLIFF, direction=-1)[0]
    # "velocity of the ball when the time is 4.404" -> at the measured landing time
    v_b = float(np.linalg.norm(res.at(t_b).velocity(ball)[0]))

    th = theory()
    measured = {"h": y_max - CLIFF, "t": t_b, "v_B": v_b}
    quantities = [Quantity(name, unit, theory=th[name], manual_theory=mt, manual_commercial=mc,
                           mbdsim=float(measured[name]))
                  for name, (unit, mt, mc) in MANUAL.items()]
    plots = [
        Plot("Height of the ball", res.time, height(res), "t [s]", "y [m]",
             mark=(float(t_b), CLIFF), mark_label=f"y = 15 m at t = {t_b:.5f} s"),
        Plot("Vertical velocity of the ball", res.time, res.velocity(ball)[:, 1], "t [s]", "v_y [m/s]",
             mark=(float(t_b), -v_b), mark_label=f"v = {-v_b:.5f} m/s at B"),
    ]
    return CaseOutcome(info=CASE, quantities=quantities, model=model, result=res, plots=plots)

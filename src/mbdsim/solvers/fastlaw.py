"""The contact law at one point of shape contact (issue 30; solvers.fastcontact's narrow phase finds the points).

`_apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, p, n, delta)` turns a contact point p [m] (ground) of depth
delta > 0 [m] and unit normal n (ground, from the pair's shape_i towards shape_j) into the force on shape_j's
frame at p and its opposite on shape_i's (F (nf, 6): force [N] in ground axes, torque [N m] about the CM in
body axes), and records the point into rec while it has room (REC_FIELDS; nrec[0] counts the rows).

Law (gap rate gd = n . v_rel [m/s]): IMPACT Fn = max(0, k delta^e - STEP(delta, 0, 0, d, c_max) gd), or with a
coefficient of restitution eps (POISSON) Fn = k delta^e (1 - (1 - eps^2) STEP(gd, 0, 0, RESTITUTION_VELOCITY,
1)): the unloading branch returns eps^2 of the work of the loading one, so a mass leaves with eps times its
approach speed.  Friction -mu(s) Fn t / s (t: tangential slip velocity, s = |t|): mode 0 (mu,
friction_velocity vs) mu(s) = mu s / sqrt(s^2 + vs^2); mode 1 (Adams) mu = STEP(s, -vs, -mu_s, vs, mu_s)
below the stiction velocity vs, STEP(s, vs, mu_s, vt, mu_d) up to the transition velocity vt, mu_d above.
The pair's parameters are the rows of sc[11] (PAR_FIELDS).
"""
from __future__ import annotations

import numpy as np

from .. import _jitcache  # noqa: F401  (numba's cache directory, before any kernel is defined)
from .._jit import kernel
from ..system.exprloads_kernel import _cross, _force as _point_force

RESTITUTION_VELOCITY = 1e-4   # [m/s] width of the POISSON law's switch from loading to unloading
NREC = 15
REC_FIELDS = ("pair", "x", "y", "z", "nx", "ny", "nz", "penetration", "normal_force", "friction_x",
              "friction_y", "friction_z", "slip_velocity", "gap_rate", "element")
PAR_FIELDS = ("stiffness", "exponent", "damping", "penetration", "restitution", "friction_mode", "mu_static",
              "mu_dynamic", "stiction_velocity", "transition_velocity", "element")


@kernel(_nrt=False)
def _step(x, x0, h0, x1, h1):
    """Adams STEP: cubic from h0 at x0 to h1 at x1, constant outside."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    u = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * u * u * (3.0 - 2.0 * u)


@kernel(_nrt=False)
def friction_coefficient(s, mode, mu_s, mu_d, vs, vt):
    """mu(s) of the slip speed s [m/s] >= 0 (module docstring)."""
    if mode == 0:
        return mu_s * s / np.sqrt(s * s + vs * vs)
    if s <= vs:
        return _step(s, -vs, -mu_s, vs, mu_s)
    if s <= vt:
        return _step(s, vs, mu_s, vt, mu_d)
    return mu_d


@kernel(_nrt=False)
def normal_force(delta, gd, k, ex, cmax, dpen, eps):
    """Normal force [N] >= 0 at depth delta > 0 [m] and gap rate gd [m/s] (module docstring)."""
    if eps < 0.0:
        u = min(delta / dpen, 1.0)
        return max(k * delta ** ex - cmax * u * u * (3.0 - 2.0 * u) * gd, 0.0)
    return k * delta ** ex * (1.0 - (1.0 - eps * eps) * _step(gd, 0.0, 0.0, RESTITUTION_VELOCITY, 1.0))


@kernel(_nrt=False)
def relative_velocity(r, rd, w, fi, fj, p0, p1, p2):
    """Velocity [m/s] (ground) of frame fj's material point at the ground point p relative to frame fi's (r
    [m], rd [m/s], w [rad/s]: the frames' origins, their velocities and angular velocities, ground axes)."""
    x0, x1, x2 = _cross(w[fj, 0], w[fj, 1], w[fj, 2], p0 - r[fj, 0], p1 - r[fj, 1], p2 - r[fj, 2])
    y0, y1, y2 = _cross(w[fi, 0], w[fi, 1], w[fi, 2], p0 - r[fi, 0], p1 - r[fi, 1], p2 - r[fi, 2])
    return rd[fj, 0] + x0 - rd[fi, 0] - y0, rd[fj, 1] + x1 - rd[fi, 1] - y1, rd[fj, 2] + x2 - rd[fi, 2] - y2


@kernel(_nrt=False)
def _apply(sc, pair, r, A, rd, w, rigid, F, rec, nrec, p0, p1, p2, n0, n1, n2, delta):
    """The contact law at the point p [m] (normal n from shape_i towards shape_j, depth delta [m]): the force
    on shape_j's frame at p and its opposite on shape_i's."""
    pr, pp, sh_f = sc[10], sc[11], sc[0]
    fi, fj = sh_f[pr[pair, 0]], sh_f[pr[pair, 1]]
    v0, v1, v2 = relative_velocity(r, rd, w, fi, fj, p0, p1, p2)
    gd = n0 * v0 + n1 * v1 + n2 * v2
    Fn = normal_force(delta, gd, pp[pair, 0], pp[pair, 1], pp[pair, 2], pp[pair, 3], pp[pair, 4])
    t0, t1, t2 = v0 - gd * n0, v1 - gd * n1, v2 - gd * n2
    s = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    c = 0.0
    if pp[pair, 6] > 0.0 or pp[pair, 7] > 0.0:
        mode = int(pp[pair, 5])
        if mode == 0:
            c = pp[pair, 6] * Fn / np.sqrt(s * s + pp[pair, 8] * pp[pair, 8])
        elif s > 0.0:
            c = friction_coefficient(s, mode, pp[pair, 6], pp[pair, 7], pp[pair, 8], pp[pair, 9]) * Fn / s
    G0, G1, G2 = Fn * n0 - c * t0, Fn * n1 - c * t1, Fn * n2 - c * t2
    _point_force(F, A, fj, p0 - r[fj, 0], p1 - r[fj, 1], p2 - r[fj, 2], G0, G1, G2, rigid)
    _point_force(F, A, fi, p0 - r[fi, 0], p1 - r[fi, 1], p2 - r[fi, 2], -G0, -G1, -G2, rigid)
    k = nrec[0]
    if k < rec.shape[0]:
        vals = (float(pair), p0, p1, p2, n0, n1, n2, delta, Fn, -c * t0, -c * t1, -c * t2, s, gd, pp[pair, 10])
        for j in range(NREC):
            rec[k, j] = vals[j]
        nrec[0] = k + 1

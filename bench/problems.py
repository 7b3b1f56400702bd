"""Benchmark problems: geometry, references and error measures (engine independent).

Every problem is posed in SI units with gravity -y.  An engine run returns a standard trajectory:
``{"t": (N,), "cm": (N, nb, 3)}`` (world CM positions of the moving bodies at the output times) and,
for the chain, ``"energy": (N,)`` (total mechanical energy, same datum for every engine).
The error of a run is a single dimensionless number, see ``Problem.error``.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipk

G = 9.81


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_x_to(d):
    """Rotation matrix (body -> world) taking body x onto unit vector d (minimal rotation)."""
    d = np.asarray(d, float) / np.linalg.norm(d)
    x = np.array([1.0, 0.0, 0.0])
    v, c = np.cross(x, d), float(x @ d)
    if np.linalg.norm(v) < 1e-14:
        return np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def rod_inertia(m, L, w=0.02):
    """Principal inertia about the CM of a rod along body x: (axial, transverse, transverse).
    Transverse is the thin-rod value m L^2 / 12 exactly (so theta'' = -(3 g / 2 L) cos theta holds);
    the axial value m w^2 / 6 (square section w x w) keeps the mass matrix positive definite."""
    return np.array([m * w * w / 6, m * L * L / 12, m * L * L / 12])


class Rod:
    """A uniform rod: joint at `origin` (world), axis along unit vector `d`, length L, mass m."""

    def __init__(self, origin, d, L, m):
        self.origin, self.L, self.m = np.asarray(origin, float), float(L), float(m)
        self.d = np.asarray(d, float) / np.linalg.norm(d)
        self.R = rot_x_to(self.d)
        self.cm = self.origin + 0.5 * L * self.d
        self.tip = self.origin + L * self.d
        self.J = rod_inertia(m, L)


# --------------------------------------------------------------------------- problems
class Problem:
    key = ""
    title = ""
    t_end = 1.0
    out_dt = 0.01
    scale = 1.0            # characteristic length [m] for relative position errors
    measure = "max_t max_b |r_cm - r_cm_ref| / L_char"

    def times(self):
        n = int(round(self.t_end / self.out_dt))
        return np.linspace(0.0, self.t_end, n + 1)

    def reference(self):
        raise NotImplementedError

    def error(self, traj):
        ref = self.ref
        if traj is None or len(traj["t"]) != len(ref["t"]) or not np.all(np.isfinite(traj["cm"])):
            return np.inf
        return float(np.max(np.linalg.norm(traj["cm"] - ref["cm"], axis=-1)) / self.scale)

    @property
    def ref(self):
        if not hasattr(self, "_ref"):
            self._ref = self.reference()
        return self._ref


class RodPendulum(Problem):
    key = "pendulum"
    title = "uniform rod pendulum, released horizontally, 10 s"
    t_end, out_dt = 10.0, 0.05
    L, m = 1.0, 1.0

    def __init__(self):
        self.rods = [Rod((0, 0, 0), (1, 0, 0), self.L, self.m)]
        self.scale = self.L
        self.w0 = np.sqrt(1.5 * G / self.L)     # theta'' = -(3 g / 2 L) cos(theta), theta from +x

    def theta(self, rtol=1e-13, atol=1e-15):
        f = lambda t, y: [y[1], -self.w0 ** 2 * np.cos(y[0])]  # noqa: E731
        s = solve_ivp(f, (0, self.t_end), [0.0, 0.0], method="DOP853", rtol=rtol, atol=atol,
                      t_eval=self.times(), dense_output=True)
        return s

    def reference(self):
        s = self.theta()
        th = s.y[0]
        cm = 0.5 * self.L * np.stack([np.cos(th), np.sin(th), 0 * th], -1)[:, None, :]
        # check: the period from the complete elliptic integral, amplitude pi/2 about the downward vertical
        T_exact = 4.0 * ellipk(np.sin(np.pi / 4) ** 2) / self.w0
        turn = lambda t, y: y[1]  # noqa: E731
        turn.direction = 1.0             # theta' rises through 0 at theta = -pi (other horizontal), t = T/2
        s2 = solve_ivp(lambda t, y: [y[1], -self.w0 ** 2 * np.cos(y[0])], (0, 2 * T_exact), [0.0, 0.0],
                       method="DOP853", rtol=1e-13, atol=1e-15, events=turn)
        t_turn = s2.t_events[0]
        T_num = 2.0 * t_turn[0]
        return {"t": self.times(), "cm": cm, "check": {
            "period_elliptic_s": T_exact, "period_reference_s": T_num,
            "period_rel_diff": abs(T_num - T_exact) / T_exact}}


class DoublePendulum(Problem):
    key = "double_pendulum"
    title = "planar double pendulum (two uniform rods), 5 s"
    t_end, out_dt = 5.0, 0.02
    L1, m1, L2, m2 = 1.0, 1.0, 0.7, 0.6
    phi0 = (0.0, np.pi / 4)        # absolute angles from +x at t=0 (link 1 horizontal, link 2 45 deg up)

    def __init__(self):
        p1, p2 = self.phi0
        r1 = Rod((0, 0, 0), (np.cos(p1), np.sin(p1), 0), self.L1, self.m1)
        r2 = Rod(r1.tip, (np.cos(p2), np.sin(p2), 0), self.L2, self.m2)
        self.rods = [r1, r2]
        self.scale = self.L1 + self.L2

    def lagrange_rhs(self, t, y):
        """Minimal-coordinate equations M(phi) phi'' + c = Q for absolute angles phi1, phi2 (from +x)."""
        p1, p2, w1, w2 = y
        L1, L2, m1, m2 = self.L1, self.L2, self.m1, self.m2
        I1, I2 = self.rods[0].J[2], self.rods[1].J[2]          # about z, through the CM
        k = m2 * L1 * L2 / 2
        s, c = np.sin(p1 - p2), np.cos(p1 - p2)
        M = np.array([[m1 * L1 ** 2 / 4 + I1 + m2 * L1 ** 2, k * c], [k * c, m2 * L2 ** 2 / 4 + I2]])
        rhs = np.array([-(m1 * L1 / 2 + m2 * L1) * G * np.cos(p1) - k * s * w2 ** 2,
                        -m2 * L2 / 2 * G * np.cos(p2) + k * s * w1 ** 2])
        a1, a2 = np.linalg.solve(M, rhs)
        return [w1, w2, a1, a2]

    def cm_from_angles(self, p1, p2):
        L1, L2 = self.L1, self.L2
        z = 0 * p1
        c1 = np.stack([L1 / 2 * np.cos(p1), L1 / 2 * np.sin(p1), z], -1)
        c2 = np.stack([L1 * np.cos(p1) + L2 / 2 * np.cos(p2), L1 * np.sin(p1) + L2 / 2 * np.sin(p2), z], -1)
        return np.stack([c1, c2], 1)

    def reference(self):
        s = solve_ivp(self.lagrange_rhs, (0, self.t_end), [*self.phi0, 0.0, 0.0], method="DOP853",
                      rtol=1e-12, atol=1e-14, t_eval=self.times())
        return {"t": self.times(), "cm": self.cm_from_angles(s.y[0], s.y[1])}


class SliderCrank(Problem):
    key = "slider_crank"
    title = "slider-crank, crank driven theta = pi/6 + 3 t + 2 t^2, kinematics, 2 s"
    t_end, out_dt = 2.0, 0.01
    r, l = 0.1, 0.35
    m1, m2, m3 = 1.5, 2.0, 0.8
    th0 = np.pi / 6
    drive = "3*t + 2*t**2"

    def __init__(self):
        self.scale = self.r + self.l

    def angles(self, t):
        th = self.th0 + 3 * t + 2 * t ** 2
        ph = -np.arcsin(self.r * np.sin(th) / self.l)
        return th, ph

    def drive_fn(self, t):
        """theta(t) - theta(0), its first and second derivative."""
        return 3 * t + 2 * t ** 2, 3 + 4 * t, 4.0

    def closed_form_cm(self, t):
        th, ph = self.angles(t)
        r, l = self.r, self.l
        z = 0 * t
        A = np.stack([r * np.cos(th), r * np.sin(th), z], -1)
        e2 = np.stack([np.cos(ph), np.sin(ph), z], -1)
        B = A + l * e2
        return np.stack([A / 2, A + l / 2 * e2, B], 1)

    def reference(self):
        t = self.times()
        return {"t": t, "cm": self.closed_form_cm(t)}


class SphericalChain(Problem):
    key = "chain"
    title = "10-link spherical chain under gravity, 2 s (3D, from rest)"
    t_end, out_dt = 2.0, 0.02
    n, L, m = 10, 0.2, 0.1
    measure = "max_t |E(t) - E(0)| / max_t KE(t)   (energy drift)"

    def __init__(self):
        rods, o = [], np.zeros(3)
        for k in range(self.n):   # a non-planar initial shape, released from rest
            d = np.array([1.0, 0.35 * np.sin(0.9 * k), 0.5 * np.cos(0.7 * k)])
            rods.append(Rod(o, d, self.L, self.m))
            o = rods[-1].tip
        self.rods = rods
        self.scale = self.n * self.L

    def reference(self):
        return None   # filled by run.py from a tight mbdsim dop853 run (cross-checked with MuJoCo)

    def error(self, traj):
        if traj is None or not np.all(np.isfinite(traj["energy"])):
            return np.inf
        E = traj["energy"]
        return float(np.max(np.abs(E - E[0])) / self.ke_scale)

    def position_error(self, traj):
        if traj is None or self.ref is None or len(traj["t"]) != len(self.ref["t"]):
            return np.inf
        return float(np.max(np.linalg.norm(traj["cm"] - self.ref["cm"], axis=-1)) / self.scale)

    def energy(self, cm, v, w_body, zero_pe=True):
        """E = sum 1/2 m |v|^2 + 1/2 w_B . J w_B - m g . r  (g = -G y), arrays (N, nb, 3)."""
        J = np.array([r.J for r in self.rods])
        ke = 0.5 * self.m * np.sum(v ** 2, axis=(1, 2)) + 0.5 * np.sum(J[None] * w_body ** 2, axis=(1, 2))
        pe = self.m * G * np.sum(cm[:, :, 1], axis=1)
        return ke + pe, ke


class PointPendulum(Problem):
    """Issue 7: point mass 1 kg at 1 m on a massless rod, released horizontally, 10 s. The bob is a body of
    1 kg with a tiny inertia (1e-6 kg m^2, a ~1.6 mm ball) so every engine can take it; the reference
    includes that inertia exactly: theta'' = -m g a cos(theta) / (m a^2 + I)."""

    key = "pendulum_point"
    title = "point-mass pendulum (1 kg at 1 m), released horizontally, 10 s"
    t_end, out_dt = 10.0, 0.01
    a, m, I = 1.0, 1.0, 1e-6

    def __init__(self):
        rod = Rod((0, 0, 0), (1, 0, 0), 2 * self.a, self.m)
        rod.J = np.array([self.I, self.I, self.I])
        self.rods = [rod]
        self.scale = self.a

    def reference(self):
        k = self.m * G * self.a / (self.m * self.a ** 2 + self.I)
        s = solve_ivp(lambda t, y: [y[1], -k * np.cos(y[0])], (0, self.t_end), [0.0, 0.0], method="DOP853",
                      rtol=1e-13, atol=1e-15, t_eval=self.times())
        th = s.y[0]
        return {"t": self.times(), "cm": self.a * np.stack([np.cos(th), np.sin(th), 0 * th], -1)[:, None, :]}


class PlanarChain(Problem):
    """Issue 7: N uniform rods (1 kg, 0.1 m) on revolute joints, first to ground, released horizontally, 1 s.
    Reference: Pinocchio's articulated-body algorithm in joint coordinates (an independent formulation)
    integrated by scipy's DOP853 at rtol 1e-12."""

    t_end, out_dt = 1.0, 0.01
    L, m = 0.1, 1.0

    def __init__(self, n):
        self.n = n
        self.key = f"chain2d_{n}"
        self.title = f"planar chain of {n} rods (1 kg, 0.1 m), released horizontally, 1 s"
        self.rods = [Rod((k * self.L, 0, 0), (1, 0, 0), self.L, self.m) for k in range(n)]
        self.scale = n * self.L

    def reference(self):
        import pinocchio as pin
        model = pin.Model()
        model.gravity.linear = np.array([0.0, -G, 0.0])
        parent = 0
        for k, r in enumerate(self.rods):
            place = pin.SE3(np.eye(3), np.array([0.0 if k == 0 else self.L, 0.0, 0.0]))
            parent = model.addJoint(parent, pin.JointModelRZ(), place, f"j{k}")
            model.appendBodyToJoint(parent, pin.Inertia(r.m, np.array([self.L / 2, 0, 0]), np.diag(r.J)), pin.SE3.Identity())
        data = model.createData()
        n = self.n

        def rhs(t, y):
            return np.concatenate([y[n:], pin.aba(model, data, y[:n], y[n:], np.zeros(n))])

        s = solve_ivp(rhs, (0, self.t_end), np.zeros(2 * n), method="DOP853", rtol=1e-12, atol=1e-12,
                      t_eval=self.times())
        cm = np.empty((len(s.t), n, 3))
        for i in range(len(s.t)):
            pin.forwardKinematics(model, data, s.y[:n, i])
            for k in range(n):
                cm[i, k] = data.oMi[k + 1].act(np.array([self.L / 2, 0, 0]))
        return {"t": self.times(), "cm": cm}


class FreeSliderCrank(Problem):
    """Issue 7: slider-crank under gravity, free (not driven): crank 0.1 m and rod 0.3 m (uniform, 1 kg
    each), slider 1 kg, released from rest with the crank at 60 deg, 2 s. Reference: the one-DOF Lagrange
    equation J(th) th'' + J'(th) th'^2 / 2 + V'(th) = 0 (J' and V' by complex step), scipy DOP853 1e-12."""

    key = "slider_crank_free"
    title = "slider-crank under gravity, free, released at 60 deg, 2 s"
    t_end, out_dt = 2.0, 0.01
    r, l, m = 0.1, 0.3, 1.0
    th0 = np.pi / 3

    def __init__(self):
        self.scale = self.r + self.l

    def positions(self, th):
        """Crank CM, rod CM and slider positions (N, 3, 3) and the rod angle for crank angles th."""
        r, l = self.r, self.l
        s = np.sqrt(l * l - (r * np.sin(th)) ** 2)
        A = np.stack([r * np.cos(th), r * np.sin(th), 0 * th], -1)
        B = np.stack([r * np.cos(th) + s, 0 * th, 0 * th], -1)
        return np.stack([A / 2, (A + B) / 2, B], -2), np.arctan2(-r * np.sin(th), s)

    def _J(self, th):
        r, l, m = self.r, self.l, self.m
        s = np.sqrt(l * l - (r * np.sin(th)) ** 2)
        ds = -r * r * np.sin(th) * np.cos(th) / s
        dx = -r * np.sin(th) + ds
        dphi = (s * (-r * np.cos(th)) + r * np.sin(th) * ds) / (l * l)
        gx, gy = 0.5 * (-r * np.sin(th) + dx), 0.5 * r * np.cos(th)
        return m * r * r / 3 + m * (gx * gx + gy * gy) + m * l * l / 12 * dphi ** 2 + m * dx ** 2

    def reference(self):
        V = lambda th: G * self.m * self.r * np.sin(th)  # noqa: E731   crank CM and rod CM at r sin(th) / 2
        cs = lambda f, th: f(th + 1e-30j).imag / 1e-30  # noqa: E731

        def rhs(t, y):
            return [y[1], -(0.5 * cs(self._J, y[0]) * y[1] ** 2 + cs(V, y[0])) / self._J(y[0])]

        s = solve_ivp(rhs, (0, self.t_end), [self.th0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                      t_eval=self.times())
        return {"t": self.times(), "cm": self.positions(s.y[0])[0]}


class HeavyTop(Problem):
    """Issue 8: heavy symmetric top on a ball joint at the origin (1 kg, CM 0.1 m from the pivot, moments
    0.002 kg m^2 transverse about the CM and 0.004 axial), tilted 30 deg from the vertical and released
    spinning at 100 rad/s about its axis with no precession, so it nutates; 2 s (gravity -y here: the
    vertical is +y). Reference: Euler's equations about the pivot in body axes with the quaternion
    kinematics (an independent formulation), scipy DOP853 at rtol 1e-13."""

    key = "heavy_top"
    title = "heavy top: 30 deg tilt, 100 rad/s spin, released without precession, 2 s"
    t_end, out_dt = 2.0, 0.01
    m, arm, Jt, J3, tilt, spin = 1.0, 0.1, 0.002, 0.004, np.radians(30.0), 100.0

    def __init__(self):
        self.scale = self.arm
        # body axes: x, z transverse, y the symmetry axis; R0 tilts body y by 30 deg about ground z
        c, s_ = np.cos(self.tilt), np.sin(self.tilt)
        self.R0 = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
        self.J_cm = np.array([self.Jt, self.J3, self.Jt])

    def cm0(self):
        return self.R0 @ np.array([0.0, self.arm, 0.0])

    def w0(self):
        return self.R0 @ np.array([0.0, self.spin, 0.0])

    def reference(self):
        Jp = self.J_cm + self.m * self.arm ** 2 * np.array([1.0, 0.0, 1.0])   # about the pivot
        rc = np.array([0.0, self.arm, 0.0])
        g = np.array([0.0, -G, 0.0])

        def R_of(qv):
            w, x, y, z = qv / np.linalg.norm(qv)
            return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                             [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                             [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])

        def rhs(t, y):
            qv, wb = y[:4], y[4:]
            R = R_of(qv)
            tau = np.cross(rc, R.T @ (self.m * g))
            wd = (tau - np.cross(wb, Jp * wb)) / Jp
            w, x, yy, z = qv
            p, q_, r = wb
            qd = 0.5 * np.array([-x * p - yy * q_ - z * r, w * p + yy * r - z * q_, w * q_ + z * p - x * r,
                                 w * r + x * q_ - yy * p])
            return np.concatenate([qd, wd])

        a = self.tilt / 2
        y0 = np.concatenate([[np.cos(a), 0.0, 0.0, np.sin(a)], [0.0, self.spin, 0.0]])
        s = solve_ivp(rhs, (0, self.t_end), y0, method="DOP853", rtol=1e-13, atol=1e-15, t_eval=self.times())
        cm = np.array([R_of(s.y[:4, i]) @ rc for i in range(s.y.shape[1])])[:, None, :]
        return {"t": self.times(), "cm": cm}


ISSUE7 = (PointPendulum(), FreeSliderCrank(), *(PlanarChain(n) for n in (2, 8, 32, 128)))
PROBLEMS = {p.key: p for p in (RodPendulum(), DoublePendulum(), SliderCrank(), SphericalChain(), *ISSUE7,
                                HeavyTop())}

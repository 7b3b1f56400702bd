"""Adams function library: formulas, endpoints, continuity, derivatives against finite differences."""
import numpy as np
import pytest

from mbdsim import functions as F


def fd(f, x, h=1e-6):
    return (f(x + h) - f(x - h)) / (2 * h)


# ----------------------------------------------------------------------------- STEP family
@pytest.mark.parametrize("step", [F.step, F.step5, F.havsin])
def test_step_endpoints_and_plateaus(step):
    x0, h0, x1, h1 = 0.5, -1.0, 2.0, 3.0
    assert step(x0, x0, h0, x1, h1) == h0
    assert step(x1, x0, h0, x1, h1) == h1
    assert step(-10.0, x0, h0, x1, h1) == h0
    assert step(10.0, x0, h0, x1, h1) == h1
    assert step(1.25, x0, h0, x1, h1) == pytest.approx((h0 + h1) / 2, abs=1e-15)   # symmetric about the middle
    x = np.linspace(-1, 3, 401)
    y = step(x, x0, h0, x1, h1)
    assert isinstance(y, np.ndarray) and y.shape == x.shape
    assert np.all(np.diff(y) >= 0)                     # monotone from h0 to h1
    assert isinstance(step(1.0, x0, h0, x1, h1), float)


def test_step_closed_forms():
    x0, h0, x1, h1 = 1.0, 2.0, 3.0, 6.0
    x = np.linspace(1.1, 2.9, 7)
    s = (x - x0) / (x1 - x0)
    np.testing.assert_allclose(F.STEP(x, x0, h0, x1, h1), h0 + (h1 - h0) * s**2 * (3 - 2 * s), rtol=1e-15)
    np.testing.assert_allclose(F.STEP5(x, x0, h0, x1, h1), h0 + (h1 - h0) * (10 * s**3 - 15 * s**4 + 6 * s**5), rtol=1e-15)
    np.testing.assert_allclose(F.HAVSIN(x, x0, h0, x1, h1), h0 + (h1 - h0) * (1 - np.cos(np.pi * s)) / 2, rtol=1e-15)
    # derivative values: STEP' at the middle is 1.5 (h1 - h0)/(x1 - x0), zero at both ends
    assert F.STEP_d(2.0, x0, h0, x1, h1) == pytest.approx(1.5 * 4 / 2)
    assert F.STEP5_d(2.0, x0, h0, x1, h1) == pytest.approx(1.875 * 4 / 2)
    assert F.HAVSIN_d(2.0, x0, h0, x1, h1) == pytest.approx(np.pi / 2 * 4 / 2)
    for d in (F.STEP_d, F.STEP5_d, F.HAVSIN_d):
        assert d(x0, x0, h0, x1, h1) == 0.0 and d(x1, x0, h0, x1, h1) == 0.0


@pytest.mark.parametrize("step,orders", [(F.step, 4), (F.step5, 6), (F.havsin, 4)])
def test_step_derivatives_against_finite_differences(step, orders):
    args = (0.2, 1.0, 1.7, -0.5)
    x = np.linspace(0.25, 1.65, 9)
    for n in range(1, orders):
        exact = step(x, *args, order=n)
        approx = fd(lambda y: step(y, *args, order=n - 1), x)
        np.testing.assert_allclose(exact, approx, rtol=1e-6, atol=1e-6 * np.max(np.abs(approx)))
    if step is F.step:
        assert np.all(step(x, *args, order=4) == 0)
    if step is F.step5:
        assert np.all(step(x, *args, order=6) == 0)


def test_step_continuity():
    x0, h0, x1, h1, eps = 0.0, 1.0, 1.0, 2.0, 1e-7
    for step, smooth in ((F.step, 1), (F.step5, 2), (F.havsin, 1)):
        for n in range(smooth + 1):                   # C1 (STEP, HAVSIN) and C2 (STEP5) at both ends
            for xe in (x0, x1):
                lo, hi = step(xe - eps, x0, h0, x1, h1, order=n), step(xe + eps, x0, h0, x1, h1, order=n)
                assert abs(lo - hi) < 1e-5
    # STEP's second derivative jumps at x0 (it is only C1): 6 (h1 - h0)/(x1 - x0)^2
    assert F.step(1e-12, x0, h0, x1, h1, order=2) == pytest.approx(6.0)


def test_step_broadcast_and_errors():
    y = F.step(np.array([0.0, 0.5, 1.0]), 0.0, np.array([0.0, 1.0, 2.0]), 1.0, 1.0)
    np.testing.assert_allclose(y, [0.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="x0 < x1"):
        F.step(0.5, 1.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="x0 < x1"):
        F.havsin(0.5, 2.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="order"):
        F.step(0.5, 0.0, 0.0, 1.0, 1.0, order=-1)


# ----------------------------------------------------------------------------- POLY, SHF
def test_poly_and_derivatives():
    a = [1.5, -2.0, 0.25, 3.0]
    x = np.linspace(-2, 2, 11)
    coeffs = np.array(a[::-1])
    np.testing.assert_allclose(F.POLY(x, 0.5, *a), np.polyval(coeffs, x - 0.5), rtol=1e-14)
    for n in range(1, 5):
        np.testing.assert_allclose(F.poly(x, 0.5, *a, order=n), np.polyval(np.polyder(coeffs, n), x - 0.5),
                                   rtol=1e-14, atol=1e-14)
    assert F.POLY_d(1.0, 0.0, 1.0, 2.0, 3.0) == 8.0
    with pytest.raises(ValueError):
        F.poly(1.0, 0.0)


def test_shf():
    x0, a, w, phi, b = 0.3, 2.0, 5.0, 0.7, -1.0
    x = np.linspace(0, 2, 13)
    np.testing.assert_allclose(F.SHF(x, x0, a, w, phi, b), a * np.sin(w * (x - x0) - phi) + b, rtol=1e-14)
    np.testing.assert_allclose(F.SHF_d(x, x0, a, w, phi, b), a * w * np.cos(w * (x - x0) - phi), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(F.shf(x, x0, a, w, phi, b, order=2), -a * w**2 * np.sin(w * (x - x0) - phi),
                               rtol=1e-12, atol=1e-12)


# ----------------------------------------------------------------------------- IMPACT, BISTOP
IMP = dict(x1=1.0, k=1e5, e=1.5, cmax=50.0, d=0.01)


def test_impact_zero_outside_contact():
    x = np.linspace(1.0, 3.0, 50)
    for v in (-10.0, 0.0, 10.0):
        assert np.all(F.IMPACT(x, v, **IMP) == 0.0)
    assert F.impact(1.0, -5.0, **IMP) == 0.0
    assert isinstance(F.impact(0.99, 0.0, **IMP), float)


def test_impact_never_negative_and_formula():
    rng = np.random.default_rng(1)
    x = rng.uniform(0.95, 1.05, 2000)
    v = rng.uniform(-50, 50, 2000)                     # fast separation would make k p^e - c v negative
    f = F.IMPACT(x, v, **IMP)
    assert np.all(f >= 0.0)
    assert np.any(f == 0.0) and np.any(f > 0.0)
    p = np.maximum(1.0 - x, 0.0)
    c = np.where(p >= 0.01, 50.0, F.step(x, 0.99, 50.0, 1.0, 0.0))
    raw = 1e5 * p**1.5 - c * v
    np.testing.assert_allclose(f, np.where((x < 1.0) & (raw > 0), raw, 0.0), rtol=1e-14)
    # full damping beyond penetration d, none at first contact
    assert F.impact(0.98, -1.0, **IMP) == pytest.approx(1e5 * 0.02**1.5 + 50.0)
    assert F.impact(1.0 - 1e-12, -1.0, **IMP) < 1e-6   # continuous at contact onset


def test_impact_partials_against_finite_differences():
    x, v = np.array([0.995, 0.985, 0.97]), np.array([-0.3, 0.2, -1.0])
    f, dfdx, dfdv = F.impact_partials(x, v, **IMP)
    np.testing.assert_allclose(dfdx, fd(lambda y: F.impact(y, v, **IMP), x, 1e-8), rtol=1e-6)
    np.testing.assert_allclose(dfdv, fd(lambda y: F.impact(x, y, **IMP), v, 1e-6), rtol=1e-6)
    np.testing.assert_allclose(F.IMPACT_d(x, v, **IMP), dfdx)
    assert F.impact_partials(1.5, 0.0, **IMP)[1:] == (0.0, 0.0)


def test_impact_parameter_checks():
    with pytest.raises(ValueError):
        F.impact(0.5, 0.0, 1.0, -1.0, 1.5, 1.0, 0.1)
    with pytest.raises(ValueError):
        F.impact(0.5, 0.0, 1.0, 1.0, 1.5, 1.0, 0.0)


BI = dict(x1=-0.5, x2=0.5, k=2e4, e=2.0, cmax=10.0, d=0.02)


def test_bistop_regions_and_symmetry():
    assert np.all(F.BISTOP(np.linspace(-0.5, 0.5, 21), 3.0, **BI) == 0.0)
    assert F.bistop(-0.6, 0.0, **BI) == pytest.approx(2e4 * 0.01)
    assert F.bistop(0.6, 0.0, **BI) == pytest.approx(-2e4 * 0.01)
    # upper wall: min(-k (x - x2)^e - STEP(x, x2, 0, x2 + d, cmax) xdot, 0)
    x, v = 0.51, 0.7
    assert F.bistop(x, v, **BI) == pytest.approx(-2e4 * 0.01**2 - F.step(x, 0.5, 0.0, 0.52, 10.0) * v)
    rng = np.random.default_rng(2)
    x, v = rng.uniform(-0.7, 0.7, 500), rng.uniform(-20, 20, 500)
    f = F.bistop(x, v, **BI)
    np.testing.assert_allclose(f, -F.bistop(-x, -v, **BI), atol=1e-12)   # mirror image (gap centred on 0)
    assert np.all(f[x < -0.5] >= 0) and np.all(f[x > 0.5] <= 0)
    with pytest.raises(ValueError, match="x1 < x2"):
        F.bistop(0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 1.0, 0.1)


def test_bistop_partials_against_finite_differences():
    x, v = np.array([-0.51, -0.6, 0.53, 0.61]), np.array([-0.1, 0.3, 0.2, -0.4])
    f, dfdx, dfdv = F.bistop_partials(x, v, **BI)
    np.testing.assert_allclose(dfdx, fd(lambda y: F.bistop(y, v, **BI), x, 1e-8), rtol=1e-6)
    np.testing.assert_allclose(dfdv, fd(lambda y: F.bistop(x, y, **BI), v, 1e-6), rtol=1e-6)
    np.testing.assert_allclose(F.BISTOP_d(x, v, **BI), dfdx)


# ----------------------------------------------------------------------------- tables
def test_akima_interpolates_and_differentiates():
    xs = np.linspace(0.0, 4.0, 9)
    ys = np.sin(xs)
    ak = F.Akima(xs, ys)
    np.testing.assert_allclose(ak(xs), ys, atol=1e-15)
    x = np.linspace(0.1, 3.9, 16)                                      # no knot: ak'' jumps at knots
    np.testing.assert_allclose(ak(x, 1), fd(ak, x), rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(ak.derivative(2)(x), fd(lambda y: ak(y, 1), x), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(ak(x), np.sin(x), atol=1e-2)           # a fair interpolant of the data
    lin = F.Akima(xs, 2.0 * xs - 1.0)                                  # Akima reproduces straight lines
    np.testing.assert_allclose(lin(x), 2.0 * x - 1.0, atol=1e-14)
    np.testing.assert_allclose(F.akispl(x, xs, 2.0 * xs - 1.0, order=1), 2.0, atol=1e-13)
    assert F.AKISPL(2.0, xs, ys) == pytest.approx(np.sin(2.0), abs=1e-15)
    assert ak.domain == (0.0, 4.0)
    with pytest.raises(ValueError):
        F.akispl(1.0, xs, ys, order=3)


def test_cubic_spline_table():
    xs = np.array([0.0, 0.4, 1.0, 1.5, 2.2, 3.0])
    cs = F.CubicSplineTable(xs, xs**3 - xs)                            # not-a-knot reproduces cubics
    x = np.linspace(-0.5, 3.5, 23)
    np.testing.assert_allclose(cs(x), x**3 - x, atol=1e-12)
    np.testing.assert_allclose(cs(x, 1), 3 * x**2 - 1, atol=1e-11)
    np.testing.assert_allclose(cs(x, 2), 6 * x, atol=1e-10)
    with pytest.raises(ValueError, match="increasing"):
        F.CubicSplineTable([0.0, 1.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(ValueError):
        F.Akima([0.0], [1.0])


def test_library_registry():
    assert set(F.LIBRARY) == {"STEP", "STEP5", "HAVSIN", "POLY", "SHF", "IMPACT", "BISTOP"}
    for name, entry in F.LIBRARY.items():
        if name in ("IMPACT", "BISTOP"):   # order 0: the force, order 1: its partial d/dx at fixed xdot
            args = (0.99, -0.3, 1.0, 1e4, 1.5, 10.0, 0.02) if name == "IMPACT" else (0.99, -0.3, 1.0, 2.0, 1e4, 1.5, 10.0, 0.02)
            assert entry.fn(*args) == getattr(F, name)(*args)
            assert entry.fn(*args, order=1) == getattr(F, f"{name}_d")(*args)
            with pytest.raises(ValueError):
                entry.fn(*args, order=2)
            continue
        assert entry.fn is getattr(F, name)

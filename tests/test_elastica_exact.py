"""Exact discrete elasticae: eqs. (3.9), (3.18), Prop. 4.1, continuum limit, the sign of phi."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import trapezoid
from scipy.special import ellipj

from curvesmith.elastica import (
    case_of,
    curvature,
    exact_curvature,
    invariants,
    sample,
    segment_length,
    tangent_angles,
)
from curvesmith.errors import CurveError
from curvesmith.internals import elastica_params as _as_params
from curvesmith.internals import elastica_positions_and_jacobian as _positions_and_jacobian

PARAMS = [
    (0.3, -0.2, 0.07, 0.0, 0.11, 0.4, 0.3),
    (0.3, -0.2, 0.07, 0.7, 0.11, 0.4, 0.8),
    (1.0, 2.0, 0.5, -2.0, -0.06, 1.3, 0.999),
    (0.0, 0.0, 0.07, 0.5, 0.11, 0.4, 1.0),
    (0.0, 0.0, 0.07, 0.5, 0.11, 0.4, 1.0005),
    (5.0, -1.0, 0.2, 2.5, 0.05, -0.7, 1.3),
    (0.0, 0.0, 1.0, -1.0, 0.02, 0.1, 5.0),
    (0.0, 0.0, 0.01, 0.1, 0.01, 0.3, 27.4),
]


def naive_curvature(pts):
    """kappa_n = (2/h) tan(K_n/2) with K_n from atan2 tangent angles, eqs. (3.1), (3.4)."""
    e = np.diff(pts, axis=0)
    h = np.hypot(*e.T).mean()
    theta = np.unwrap(np.arctan2(e[:, 1], e[:, 0]))
    return 2.0 / h * np.tan(np.diff(theta) / 2.0)


@pytest.mark.parametrize("p", PARAMS)
def test_equal_segments_and_closed_form_curvature(p):
    pts = sample(p, 60)
    assert np.allclose(np.hypot(*np.diff(pts, axis=0).T), p[2], rtol=1e-13, atol=0)
    assert np.allclose(pts[0], p[:2])
    kap = curvature(pts)
    np.testing.assert_allclose(kap, naive_curvature(pts), rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(kap, exact_curvature(p, 60)[1:-1], rtol=1e-9, atol=1e-10)


@pytest.mark.parametrize("p", PARAMS)
def test_recurrence_3_9_with_constant_alpha(p):
    """kappa_{n+1} + kappa_{n-1} = alpha kappa_n / (1 + h^2 kappa_n^2 / 4), one alpha for all n."""
    h = p[2]
    kap = curvature(sample(p, 80))
    inv = invariants(p)
    lhs = kap[2:] + kap[:-2]
    rhs = inv.alpha * kap[1:-1] / (1.0 + h * h * kap[1:-1] ** 2 / 4.0)
    scale = np.abs(kap).max()
    assert np.max(np.abs(lhs - rhs)) < 1e-11 * scale
    # and alpha is what eq. (3.9) solved per vertex gives
    alpha_n = lhs * (1.0 + h * h * kap[1:-1] ** 2 / 4.0) / kap[1:-1]
    big = np.abs(kap[1:-1]) > 0.1 * scale
    np.testing.assert_allclose(alpha_n[big], inv.alpha, rtol=1e-10)


@pytest.mark.parametrize("p", PARAMS)
def test_conserved_quantity_3_18(p):
    h = p[2]
    kap = curvature(sample(p, 80))
    inv = invariants(p)
    a, b = kap[1:], kap[:-1]
    C = a * a + b * b - inv.alpha * a * b + h * h / 4.0 * a * a * b * b
    scale = np.abs(kap).max() ** 2
    assert np.max(np.abs(C - inv.C)) < 1e-12 * scale
    assert np.ptp(C) < 1e-12 * scale


@pytest.mark.parametrize("p", PARAMS)
def test_prop_4_1_curvature_affine_in_projection(p):
    """kappa_n = (mu / Lambda) u_n + A, u_n = <(sin phi, -cos phi), gamma_n>: eqs. (4.13)-(4.16)."""
    pts = sample(p, 70)
    phi = p[3]
    u = pts[1:-1] @ np.array([np.sin(phi), -np.cos(phi)])
    kap = curvature(pts)
    inv = invariants(p)
    A = kap - inv.mu / inv.Lambda * u
    assert np.ptp(A) < 1e-10 * max(1.0, np.abs(kap).max())


def test_printed_4_4_rotation_sign_violates_prop_4_1():
    """Eq. (4.4) as printed (tangent angle Theta_n - 2 phi) breaks Prop. 4.1; '+ phi' keeps it."""
    p = (0.0, 0.0, 0.07, 0.9, 0.11, 0.4, 0.6)
    phi = p[3]
    unrotated = sample((*p[:3], 0.0, *p[4:]), 70)
    printed = unrotated @ np.array([[np.cos(-phi), np.sin(-phi)], [-np.sin(-phi), np.cos(-phi)]])
    ours = sample(p, 70)
    axis = np.array([np.sin(phi), -np.cos(phi)])
    for pts, ok in ((ours, True), (printed, False)):
        u = pts[1:-1] @ axis
        kap = curvature(pts)
        coef = np.polyfit(u, kap, 1)
        resid = np.max(np.abs(np.polyval(coef, u) - kap))
        assert (resid < 1e-10) == ok


def test_continuum_limit_2_22_and_2_20():
    """h -> 0 with z = sqrt(mu) h: kappa_n -> 2 k sqrt(mu) cn(sqrt(mu) s; k), error O(h^2)."""
    mu, k, q = 1.7, 0.6, 0.3
    errors = {}
    for case_k, smooth in (
        (k, lambda s: 2 * k * np.sqrt(mu) * smooth_cn(np.sqrt(mu) * s + q, k * k)),
        # case (i) of modulus k: kappa = (2/k) sqrt(mu) dn((sqrt(mu) s + q)/k; k), eq. (2.20)
        (1 / k, lambda s: 2 / k * np.sqrt(mu) * smooth_dn((np.sqrt(mu) * s + q) / k, k * k)),
    ):
        errs = []
        for h in (0.02, 0.01, 0.005):
            n = round(4.0 / h)
            kap = exact_curvature((0, 0, h, 0, np.sqrt(mu) * h, q, case_k), n + 1)
            s = h * np.arange(n + 1)
            errs.append(np.max(np.abs(kap - smooth(s))))
        errors[case_k] = errs
        rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
        assert np.all(rates > 1.9), (case_k, errs)
        assert errs[-1] < 1e-3


def smooth_cn(x, m):
    return ellipj(x, m)[1]


def smooth_dn(x, m):
    return ellipj(x, m)[2]


def test_positions_converge_to_smooth_elastica_2_23():
    """h -> 0: the polygon approaches the smooth elastica sin(theta/2) = k sn(sqrt(mu) s; k)."""
    mu, k, L = 1.0, 0.7, 3.0

    def smooth_end(npts=4001):
        s = np.linspace(0, L, npts)
        sn = ellipj(s, k * k)[0]
        theta = 2 * np.arcsin(k * sn)
        return np.array([trapezoid(np.cos(theta), s), trapezoid(np.sin(theta), s)])

    ref = smooth_end()
    errs = []
    for h in (0.03, 0.015):
        n = round(L / h)
        pts = sample((0, 0, h, 0, np.sqrt(mu) * h, 0.0, k), n + 1)
        errs.append(np.hypot(*(pts[-1] - ref)))
    assert errs[1] < errs[0] / 3 and errs[1] < 1e-3


def test_continuation_in_k_is_continuous_through_1():
    base = (0.0, 0.0, 0.1, 0.2, 0.08, 0.3)
    pts = [sample((*base, k), 50) for k in (1 - 1e-9, 1.0, 1 + 1e-9)]
    assert np.max(np.abs(pts[0] - pts[1])) < 1e-7
    assert np.max(np.abs(pts[2] - pts[1])) < 1e-7


def test_case_i_equals_reciprocal_continued_modulus():
    p = (0.0, 0.0, 0.1, 0.2, 0.08, 0.3, 0.4)
    np.testing.assert_allclose(sample(p, 40, case="i"), sample((*p[:6], 2.5), 40), atol=1e-13)
    assert case_of(0.4) == "ii" and case_of(2.5) == "i" and case_of(1.0) == "separatrix"
    assert invariants((*p[:6], 2.5)).case == "i"


def test_case_i_no_inflection_case_ii_inflections():
    kap_i = curvature(sample((0, 0, 0.05, 0, 0.05, 0.0, 1.5), 300))
    kap_ii = curvature(sample((0, 0, 0.05, 0, 0.05, 0.0, 0.5), 300))
    assert np.all(kap_i > 0)
    assert np.any(kap_ii > 0) and np.any(kap_ii < 0)


def richardson_fd(p, i, n, d=1e-6):
    def diff(step):
        pp, pm = np.array(p, float), np.array(p, float)
        pp[i] += step
        pm[i] -= step
        return (sample(pp, n) - sample(pm, n)) / (2 * step)

    return (4 * diff(d) - diff(2 * d)) / 3


@pytest.mark.parametrize("p", PARAMS)
def test_jacobian_4_10_4_11_against_finite_differences(p):
    n = 50
    _, jac = _positions_and_jacobian(_as_params(p), n)
    for i in range(7):
        d = 1e-6 * max(1.0, abs(p[i])) if i != 6 else 1e-7 * max(1.0, p[6])
        ref = richardson_fd(p, i, n, d)
        err = np.max(np.abs(jac[:, :, i] - ref)) / max(1.0, np.max(np.abs(ref)))
        assert err < 5e-7, (i, err)


@given(
    k=st.floats(0.05, 20.0),
    z=st.floats(-0.2, 0.2).filter(lambda v: abs(v) > 1e-3),
    q=st.floats(-5, 5),
    phi=st.floats(-4, 4),
)
def test_property_invariants_hold(k, z, q, phi):
    z = z / max(1.0, k)  # keep the turning per vertex below about 0.4 rad
    p = (0.0, 0.0, 0.1, phi, z, q, k)
    pts = sample(p, 40)
    kap = curvature(pts)
    inv = invariants(p)
    scale = max(np.abs(kap).max(), 1e-300)
    C = kap[1:] ** 2 + kap[:-1] ** 2 - inv.alpha * kap[1:] * kap[:-1]
    C += 0.01 / 4 * kap[1:] ** 2 * kap[:-1] ** 2
    assert np.ptp(C) <= 1e-11 * scale**2 + 1e-300


def test_segment_length_and_curvature_errors():
    assert segment_length([[0, 0], [1, 0], [1, 1]]) == 1.0
    with pytest.raises(CurveError, match=r"equal length .*\(spread 0.75\)"):
        curvature([[0, 0], [1, 0], [1, 2], [2, 2]])
    with pytest.raises(CurveError, match="fold back"):
        curvature([[0, 0], [1, 0], [0, 0.0000000000001]], rtol=1.0)
    with pytest.raises(CurveError, match="at least 3"):
        curvature([[0, 0], [1, 0]])
    with pytest.raises(CurveError, match="k must be > 0"):
        sample((0, 0, 1, 0, 0.1, 0, -1.0), 5)
    with pytest.raises(CurveError, match="h must be > 0"):
        sample((0, 0, 0, 0, 0.1, 0, 1.0), 5)
    with pytest.raises(CurveError, match="7 numbers"):
        sample((0, 0, 1), 5)
    with pytest.raises(CurveError, match="finite"):
        sample((0, 0, 1, np.nan, 0.1, 0, 1.0), 5)
    with pytest.raises(CurveError, match="n_points"):
        sample((0, 0, 1, 0, 0.1, 0, 1.0), 1)
    with pytest.raises(CurveError, match=r"case \(i\) needs"):
        sample((0, 0, 1, 0, 0.1, 0, 2.0), 5, case="i")


def test_tangent_angles_turn_by_the_curvature_angles():
    p = (0.0, 0.0, 0.1, 0.3, 0.08, 0.2, 1.4)  # case (i): keeps turning, beyond 2 pi
    pts = sample(p, 200)
    theta = tangent_angles(pts)
    turn = np.diff(theta)
    np.testing.assert_allclose(2 / p[2] * np.tan(turn / 2), curvature(pts), rtol=1e-10)
    assert theta[-1] - theta[0] > 2 * np.pi
    np.testing.assert_allclose(theta[0], np.arctan2(*(pts[1] - pts[0])[::-1]))


@pytest.mark.parametrize("p", PARAMS)
def test_projection_step_4_18_and_corollary_4_2(p):
    """(u_{n+1} - u_n)/h = cos Psi_n (printed (4.17)/(4.18) have -sin(Psi_n - phi), which is
    off unless phi = 0), and sin Psi_n = (mu/2Lambda) u_{n+1} u_n + A (u_{n+1} + u_n)/2 + B
    with one constant B (eq. 4.21)."""
    pts = sample(p, 60)
    phi, h = p[3], p[2]
    u = pts @ np.array([np.sin(phi), -np.cos(phi)])
    psi = np.pi / 2 + tangent_angles(pts) - phi
    np.testing.assert_allclose((u[1:] - u[:-1]) / h, np.cos(psi), atol=1e-12)
    if phi != 0.0:
        assert np.max(np.abs((u[1:] - u[:-1]) / h + np.sin(psi - phi))) > 0.1
    inv = invariants(p)
    slope = inv.mu / inv.Lambda
    kap = curvature(pts)
    A = np.mean(kap - slope * u[1:-1])
    B = np.sin(psi) - slope / 2 * u[1:] * u[:-1] - A * (u[1:] + u[:-1]) / 2
    assert np.ptp(B) < 1e-10 * max(1.0, np.abs(u).max() ** 2 * slope)


def test_separatrix_curve_with_far_arguments():
    """k = 1 exactly: one loop, then straight on (tanh saturates); no overflow at s = 2000."""
    pts = sample((0.0, 0.0, 1.0, 0.0, 10.0, 0.0, 1.0), 200)
    np.testing.assert_allclose(np.hypot(*np.diff(pts, axis=0).T), 1.0, rtol=1e-13)
    np.testing.assert_allclose(np.diff(pts[5:], axis=0), [[-1.0, 0.0]] * 194, atol=1e-12)


def _closing_modulus(vertices_per_period):
    """k at which a case (ii) elastica closes after one period (the figure eight of Fig. 4)."""
    from scipy.optimize import brentq
    from scipy.special import ellipk

    def drift(k):
        z = 4 * ellipk(k * k) / vertices_per_period
        pts = sample((0.0, 0.0, 1.0, 0.0, z, 0.0, k), vertices_per_period + 1)
        return pts[-1, 0] - pts[0, 0]

    return brentq(drift, 0.85, 0.999, xtol=1e-14)


def test_figure_4_figure_eight_moduli():
    """Fig. 4 (right): the smooth figure eight has k = 0.9089... (2E(k) = K(k)), the discrete
    one k = 0.919...; 15 vertices per period give 0.9189, and k -> 0.9089 like 1/M^2."""
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipk

    smooth = brentq(lambda k: 2 * ellipe(k * k) - ellipk(k * k), 0.5, 0.99, xtol=1e-15)
    assert f"{smooth:.4f}" == "0.9089"
    assert f"{_closing_modulus(15):.3f}" == "0.919"
    e200 = _closing_modulus(200) - smooth
    e2000 = _closing_modulus(2000) - smooth
    assert 0 < e2000 < e200 < 1e-4
    assert 80 < e200 / e2000 < 120  # second order in the step

"""Jacobi coordinates: against a readable numpy version, round trip, and the
kinetic-energy identity that makes them canonical."""

import numpy as np

from orbits._kernels import coordinates as C


def jacobi_reference(x, m):
    """x'_i = x_i - (centre of mass of bodies 0..i-1); x'_0 = centre of mass of all."""
    out = np.empty_like(x)
    for i in range(1, len(m)):
        out[i] = x[i] - (m[:i] @ x[:i]) / m[:i].sum()
    out[0] = (m @ x) / m.sum()
    return out


def system(rng, n=7, massless=2):
    gm = np.r_[1.0, rng.uniform(1e-6, 1e-2, n - 1 - massless), np.zeros(massless)]
    return rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), gm


def test_against_reference(rng):
    x, v, gm = system(rng)
    eta = np.empty(len(gm))
    C.interior_gm(gm, eta)
    np.testing.assert_array_equal(eta, np.cumsum(gm))
    xj, vj = np.empty_like(x), np.empty_like(v)
    C.to_jacobi(x, v, gm, eta, xj, vj)
    # different but equivalent summation orders: a few ulps of |x| ~ 1
    np.testing.assert_allclose(xj, jacobi_reference(x, gm), rtol=0, atol=1e-14)
    np.testing.assert_allclose(vj, jacobi_reference(v, gm), rtol=0, atol=1e-14)


def test_round_trip(rng):
    x, v, gm = system(rng)
    eta = np.cumsum(gm)
    xj, vj, x2, v2 = (np.empty_like(x) for _ in range(4))
    C.to_jacobi(x, v, gm, eta, xj, vj)
    C.from_jacobi(xj, vj, gm, eta, x2, v2)
    np.testing.assert_allclose(x2, x, rtol=0, atol=4e-16 * len(x))
    np.testing.assert_allclose(v2, v, rtol=0, atol=4e-16 * len(x))


def test_kinetic_energy_splits_into_jacobi_terms(rng):
    # sum m v^2 = M V^2 + sum_i m'_i v'_i^2 with m'_i = m_i eta_{i-1} / eta_i
    # (Wisdom & Holman 1991, eq. 13): the transformation is canonical with
    # those reduced masses; rounding of the sums ~1e-15
    x, v, gm = system(rng, massless=0)
    eta = np.cumsum(gm)
    xj, vj = np.empty_like(x), np.empty_like(v)
    C.to_jacobi(x, v, gm, eta, xj, vj)
    T = np.sum(gm * np.sum(v * v, axis=1))
    mred = gm[1:] * eta[:-1] / eta[1:]
    Tj = eta[-1] * vj[0] @ vj[0] + np.sum(mred * np.sum(vj[1:] ** 2, axis=1))
    assert abs(T - Tj) < 1e-14 * T


# -- democratic heliocentric -------------------------------------------------------

def heliocentric_reference(x, v, m):
    """Q_i = x_i - x_0, V_i = v_i - V_cm; row 0 the centre of mass and its velocity."""
    xh = x - x[0]
    vb = v - (m @ v) / m.sum()
    xh[0] = (m @ x) / m.sum()
    vb[0] = (m @ v) / m.sum()
    return xh, vb


def test_democratic_heliocentric_against_reference(rng):
    x, v, gm = system(rng)
    xh, vb = np.empty_like(x), np.empty_like(v)
    C.to_democratic_heliocentric(x, v, gm, xh, vb)
    xr, vr = heliocentric_reference(x, v, gm)
    # the same sums in another order: a few ulps of |x| ~ 1
    np.testing.assert_allclose(xh, xr, rtol=0, atol=1e-14)
    np.testing.assert_allclose(vb, vr, rtol=0, atol=1e-14)


def test_democratic_heliocentric_round_trip(rng):
    x, v, gm = system(rng)
    xh, vb, x2, v2 = (np.empty_like(x) for _ in range(4))
    C.to_democratic_heliocentric(x, v, gm, xh, vb)
    C.from_democratic_heliocentric(xh, vb, gm, x2, v2)
    # each component passes a difference and a mass-weighted sum of N terms of
    # size ~1, each rounded once: ~N ulps (measured 2e-16)
    np.testing.assert_allclose(x2, x, rtol=0, atol=4e-16 * len(x))
    np.testing.assert_allclose(v2, v, rtol=0, atol=4e-16 * len(x))


def test_kinetic_energy_splits_into_democratic_heliocentric_terms(rng):
    # sum m v^2 = M V^2 + sum_i m_i V_i^2 + |sum_i m_i V_i|^2 / m_0, i >= 1
    # (Duncan, Levison & Lee 1998, eq. 3): the Kepler parts' kinetic terms and
    # the jump; rounding of the sums ~1e-15
    x, v, gm = system(rng, massless=0)
    xh, vb = np.empty_like(x), np.empty_like(v)
    C.to_democratic_heliocentric(x, v, gm, xh, vb)
    T = np.sum(gm * np.sum(v * v, axis=1))
    p = gm[1:] @ vb[1:]
    Th = gm.sum() * vb[0] @ vb[0] + np.sum(gm[1:] * np.sum(vb[1:] ** 2, axis=1)) \
        + p @ p / gm[0]
    assert abs(T - Th) < 1e-14 * T

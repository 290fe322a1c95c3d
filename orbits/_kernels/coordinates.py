"""Inertial <-> Jacobi coordinates on plain float64 arrays.

Jacobi coordinates (Plummer 1918; Wisdom & Holman 1991, sect. 3) measure each
body from the centre of mass of the bodies before it::

    x'_0 = X_{N-1}                       (centre of mass of all)
    x'_i = x_i - X_{i-1},    i >= 1,     X_i = (sum_{j<=i} m_j x_j) / eta_i,
    eta_i = sum_{j<=i} m_j

and the same for velocities (and for accelerations: the transformation is
linear and the same matrix maps all three).  Only mass ratios enter, so the
kernels take ``gm = G m`` as the stepping loops do.  Massless bodies are
allowed after a massive first body: their Jacobi coordinate is relative to
the centre of mass of the bodies before them, and they move nothing.
"""

from ._jit import njit

__all__ = ["interior_gm", "to_jacobi", "from_jacobi", "to_jacobi_one", "from_jacobi_one"]


@njit
def interior_gm(gm, out):
    """``out[i] = G eta_i = sum_{j <= i} gm[j]``, the interior masses (times G)."""
    s = 0.0
    for i in range(gm.shape[0]):
        s += gm[i]
        out[i] = s


@njit(inline="always")
def to_jacobi_one(a, gm, eta, out):
    """Jacobi components ``out`` of the vectors ``a`` (positions, velocities or
    accelerations), shape (N, 3); ``eta`` from :func:`interior_gm`."""
    n = a.shape[0]
    # running centre of mass of bodies 0..i-1
    sx = a[0, 0]
    sy = a[0, 1]
    sz = a[0, 2]
    for i in range(1, n):
        out[i, 0] = a[i, 0] - sx
        out[i, 1] = a[i, 1] - sy
        out[i, 2] = a[i, 2] - sz
        w = gm[i] / eta[i]
        sx += w * out[i, 0]
        sy += w * out[i, 1]
        sz += w * out[i, 2]
    out[0, 0] = sx
    out[0, 1] = sy
    out[0, 2] = sz


@njit(inline="always")
def from_jacobi_one(aj, gm, eta, out):
    """Inverse of :func:`to_jacobi_one`."""
    n = aj.shape[0]
    sx = aj[0, 0]
    sy = aj[0, 1]
    sz = aj[0, 2]
    for i in range(n - 1, 0, -1):
        # X_{i-1} = X_i - (m_i / eta_i) x'_i,  x_i = x'_i + X_{i-1}
        w = gm[i] / eta[i]
        sx -= w * aj[i, 0]
        sy -= w * aj[i, 1]
        sz -= w * aj[i, 2]
        out[i, 0] = aj[i, 0] + sx
        out[i, 1] = aj[i, 1] + sy
        out[i, 2] = aj[i, 2] + sz
    out[0, 0] = sx
    out[0, 1] = sy
    out[0, 2] = sz


@njit
def to_jacobi(x, v, gm, eta, xj, vj):
    """Jacobi positions ``xj`` and velocities ``vj`` from inertial ``x``, ``v``.

    Parameters
    ----------
    x, v : ndarray, shape (N, 3)
        Inertial positions and velocities.
    gm : ndarray, shape (N,)
        G times the masses; ``gm[0] > 0``.
    eta : ndarray, shape (N,)
        :func:`interior_gm` of ``gm``.
    xj, vj : ndarray, shape (N, 3)
        Written.

    References
    ----------
    Wisdom, J. & Holman, M. 1991, AJ 102, 1528, sect. 3.
    """
    to_jacobi_one(x, gm, eta, xj)
    to_jacobi_one(v, gm, eta, vj)


@njit
def from_jacobi(xj, vj, gm, eta, x, v):
    """Inertial ``x``, ``v`` from Jacobi ``xj``, ``vj``; arguments as :func:`to_jacobi`."""
    from_jacobi_one(xj, gm, eta, x)
    from_jacobi_one(vj, gm, eta, v)

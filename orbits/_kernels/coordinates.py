"""Inertial <-> Jacobi and democratic heliocentric coordinates on plain float64 arrays.

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

Democratic heliocentric coordinates (Duncan, Levison & Lee 1998, sect. 2;
"canonical heliocentric" in Wisdom 2006) take positions relative to the
central body and velocities relative to the centre of mass::

    Q_0 = X,  V_0 = V                    (centre of mass of all, and its velocity)
    Q_i = x_i - x_0,  V_i = v_i - V,     i >= 1

The momenta conjugate to ``Q_i`` are ``m_i V_i``, so the transformation is
canonical with the masses unchanged.  Inverting it needs the masses once
more: ``x_0 = X - sum_i m_i Q_i / M`` and ``v_0 = V - sum_i m_i V_i / m_0``
(the barycentric momenta sum to zero).
"""

from ._jit import njit

__all__ = ["interior_gm", "to_jacobi", "from_jacobi", "to_jacobi_one", "from_jacobi_one",
           "to_democratic_heliocentric", "from_democratic_heliocentric", "jacobi_step",
           "row_difference", "row", "set_row", "weighted_sum", "centre_of_mass"]


@njit
def interior_gm(gm, out):
    """``out[i] = G eta_i = sum_{j <= i} gm[j]``, the interior masses (times G)."""
    s = 0.0
    for i in range(gm.shape[0]):
        s += gm[i]
        out[i] = s


@njit(inline="always")
def row(a, i):
    """Row ``i`` of ``a`` as ``(x, y, z)``."""
    return a[i, 0], a[i, 1], a[i, 2]


@njit(inline="always")
def set_row(a, i, x, y, z):
    """Row ``i`` of ``a`` set to ``(x, y, z)``."""
    a[i, 0] = x
    a[i, 1] = y
    a[i, 2] = z


@njit(inline="always")
def row_difference(a, i, j):
    """``a[i] - a[j]`` of the rows of ``a`` (shape (N, 3)), as three numbers: a
    separation, or a relative velocity."""
    return a[i, 0] - a[j, 0], a[i, 1] - a[j, 1], a[i, 2] - a[j, 2]


@njit(inline="always")
def weighted_sum(a, gm, first, end):
    """``sum_i gm[i] a[i]`` over the rows ``first <= i < end`` of ``a`` (shape
    (N, 3)), summed in order: a momentum, or a centre of mass times the mass."""
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for i in range(first, end):
        sx += gm[i] * a[i, 0]
        sy += gm[i] * a[i, 1]
        sz += gm[i] * a[i, 2]
    return sx, sy, sz


@njit(inline="always")
def centre_of_mass(x, v, gm, n):
    """The total ``gm`` of the first ``n`` bodies, their centre of mass and its
    velocity: ``(M, X, Y, Z, VX, VY, VZ)``."""
    mtot = 0.0
    for i in range(n):
        mtot += gm[i]
    cx, cy, cz = weighted_sum(x, gm, 0, n)
    cvx, cvy, cvz = weighted_sum(v, gm, 0, n)
    return mtot, cx / mtot, cy / mtot, cz / mtot, cvx / mtot, cvy / mtot, cvz / mtot


@njit(inline="always")
def jacobi_step(a, r, gm, eta, i, sx, sy, sz):
    """One row of a Jacobi transform: row ``r`` of ``a`` (body ``i``'s) less
    the running centre ``(sx, sy, sz)`` of the rows before it, and that
    centre moved by ``w = m_i / eta_i`` times the difference: ``(dx, dy,
    dz, w, sx, sy, sz)``."""
    dx = a[r, 0] - sx
    dy = a[r, 1] - sy
    dz = a[r, 2] - sz
    w = gm[i] / eta[i]
    return dx, dy, dz, w, sx + w * dx, sy + w * dy, sz + w * dz


@njit(inline="always")
def to_jacobi_one(a, gm, eta, out):
    """Jacobi components ``out`` of the vectors ``a`` (positions, velocities or
    accelerations), shape (N, 3); ``eta`` from :func:`interior_gm`."""
    n = a.shape[0]
    # running centre of mass of bodies 0..i-1
    sx, sy, sz = row(a, 0)
    for i in range(1, n):
        out[i, 0] = a[i, 0] - sx
        out[i, 1] = a[i, 1] - sy
        out[i, 2] = a[i, 2] - sz
        w = gm[i] / eta[i]
        sx += w * out[i, 0]
        sy += w * out[i, 1]
        sz += w * out[i, 2]
    set_row(out, 0, sx, sy, sz)


@njit(inline="always")
def from_jacobi_one(aj, gm, eta, out):
    """Inverse of :func:`to_jacobi_one`."""
    n = aj.shape[0]
    sx, sy, sz = row(aj, 0)
    for i in range(n - 1, 0, -1):
        # X_{i-1} = X_i - (m_i / eta_i) x'_i,  x_i = x'_i + X_{i-1}
        w = gm[i] / eta[i]
        sx -= w * aj[i, 0]
        sy -= w * aj[i, 1]
        sz -= w * aj[i, 2]
        out[i, 0] = aj[i, 0] + sx
        out[i, 1] = aj[i, 1] + sy
        out[i, 2] = aj[i, 2] + sz
    set_row(out, 0, sx, sy, sz)


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


@njit
def to_democratic_heliocentric(x, v, gm, xh, vb):
    """Democratic heliocentric positions ``xh`` and barycentric velocities ``vb``
    from inertial ``x``, ``v``.

    Parameters
    ----------
    x, v : ndarray, shape (N, 3)
        Inertial positions and velocities; body 0 is the central body.
    gm : ndarray, shape (N,)
        G times the masses; ``gm[0] > 0``, zeros allowed for the others.
    xh, vb : ndarray, shape (N, 3)
        Written: row 0 the centre of mass and its velocity, row ``i >= 1``
        ``x_i - x_0`` and ``v_i - V``.

    References
    ----------
    Duncan, M. J., Levison, H. F. & Lee, M. H. 1998, AJ 116, 2067, sect. 2.
    """
    n = x.shape[0]
    _, cx, cy, cz, cvx, cvy, cvz = centre_of_mass(x, v, gm, n)
    for i in range(1, n):
        xh[i, 0] = x[i, 0] - x[0, 0]
        xh[i, 1] = x[i, 1] - x[0, 1]
        xh[i, 2] = x[i, 2] - x[0, 2]
        vb[i, 0] = v[i, 0] - cvx
        vb[i, 1] = v[i, 1] - cvy
        vb[i, 2] = v[i, 2] - cvz
    set_row(xh, 0, cx, cy, cz)
    set_row(vb, 0, cvx, cvy, cvz)


@njit
def from_democratic_heliocentric(xh, vb, gm, x, v):
    """Inertial ``x``, ``v`` from democratic heliocentric ``xh``, ``vb``;
    arguments as :func:`to_democratic_heliocentric`."""
    n = xh.shape[0]
    mtot = 0.0
    for i in range(1, n):
        mtot += gm[i]
    mtot += gm[0]
    sx, sy, sz = weighted_sum(xh, gm, 1, n)
    x0 = xh[0, 0] - sx / mtot
    y0 = xh[0, 1] - sy / mtot
    z0 = xh[0, 2] - sz / mtot
    for i in range(1, n):
        x[i, 0] = xh[i, 0] + x0
        x[i, 1] = xh[i, 1] + y0
        x[i, 2] = xh[i, 2] + z0
    set_row(x, 0, x0, y0, z0)
    px, py, pz = weighted_sum(vb, gm, 1, n)
    for i in range(1, n):
        v[i, 0] = vb[i, 0] + vb[0, 0]
        v[i, 1] = vb[i, 1] + vb[0, 1]
        v[i, 2] = vb[i, 2] + vb[0, 2]
    v[0, 0] = vb[0, 0] - px / gm[0]
    v[0, 1] = vb[0, 1] - py / gm[0]
    v[0, 2] = vb[0, 2] - pz / gm[0]

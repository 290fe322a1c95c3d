"""Pairwise Newtonian gravity on plain float64 arrays.

Bodies are ordered so that the ``n_active`` massive ones come first; the
others are test particles, which feel the massive bodies but cost no pair work
among themselves.  ``gm[i] = G * m[i]`` is precomputed by the caller.
Softening replaces ``r**2`` by ``r**2 + eps2``.

Two kernels compute the same accelerations:

* :func:`accelerate_pairwise` visits each pair once (j < i) and uses Newton's
  third law; it is the fastest for small N and is deterministic.
* :func:`accelerate_pairwise_parallel` gives each thread whole rows i and
  sums over all j, writing only ``acc[i]``, so threads never write the same
  element.  It costs twice the arithmetic but spreads over cores, and works on
  separate x, y, z arrays whose inner loops vectorise.
"""

import math

import numpy as np
import numba

from ._jit import njit, njit_parallel

__all__ = ["accelerate_pairwise", "accelerate_pairwise_parallel", "accelerate_reference"]


@njit
def accelerate_pairwise(x, gm, n_active, eps2, acc):
    """Accelerations by the serial j < i pair loop.

    Parameters
    ----------
    x : ndarray, shape (N, 3)
        Positions.
    gm : ndarray, shape (N,)
        G times the masses; zero for test particles.
    n_active : int
        Number of massive bodies, which come first.
    eps2 : float
        Softening length squared (0 for none).
    acc : ndarray, shape (N, 3)
        Output.

    Notes
    -----
    ``a_i = - sum_j G m_j (x_i - x_j) / (|x_i - x_j|^2 + eps2)^(3/2)``.
    """
    n = x.shape[0]
    for i in range(n):
        acc[i, 0] = 0.0
        acc[i, 1] = 0.0
        acc[i, 2] = 0.0
    for i in range(1, n_active):
        xi = x[i, 0]
        yi = x[i, 1]
        zi = x[i, 2]
        gmi = gm[i]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for j in range(i):
            dx = xi - x[j, 0]
            dy = yi - x[j, 1]
            dz = zi - x[j, 2]
            r2 = dx * dx + dy * dy + dz * dz + eps2
            inv_r3 = 1.0 / (r2 * math.sqrt(r2))
            sj = gm[j] * inv_r3
            si = gmi * inv_r3
            axi -= sj * dx
            ayi -= sj * dy
            azi -= sj * dz
            acc[j, 0] += si * dx
            acc[j, 1] += si * dy
            acc[j, 2] += si * dz
        acc[i, 0] += axi
        acc[i, 1] += ayi
        acc[i, 2] += azi
    for i in range(n_active, n):
        xi = x[i, 0]
        yi = x[i, 1]
        zi = x[i, 2]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for j in range(n_active):
            dx = xi - x[j, 0]
            dy = yi - x[j, 1]
            dz = zi - x[j, 2]
            r2 = dx * dx + dy * dy + dz * dz + eps2
            sj = gm[j] / (r2 * math.sqrt(r2))
            axi -= sj * dx
            ayi -= sj * dy
            azi -= sj * dz
        acc[i, 0] = axi
        acc[i, 1] = ayi
        acc[i, 2] = azi
    return 0


@njit(fastmath={"reassoc", "contract"})
def _row_sum(xi, yi, zi, xs, ys, zs, gms, lo, hi, eps2):
    # Re-association lets LLVM vectorise these sums; the result differs from
    # the serial kernel only by round-off (tested to 1e-13 relative).
    ax = 0.0
    ay = 0.0
    az = 0.0
    for j in range(lo, hi):
        dx = xs[j] - xi
        dy = ys[j] - yi
        dz = zs[j] - zi
        r2 = dx * dx + dy * dy + dz * dz + eps2
        s = gms[j] / (r2 * math.sqrt(r2))
        ax += s * dx
        ay += s * dy
        az += s * dz
    return ax, ay, az


@njit_parallel
def accelerate_pairwise_parallel(x, gm, n_active, eps2, acc):
    """Accelerations with threads over rows; same arguments as :func:`accelerate_pairwise`."""
    n = x.shape[0]
    xs = np.empty(n_active)
    ys = np.empty(n_active)
    zs = np.empty(n_active)
    gms = np.empty(n_active)
    for j in range(n_active):
        xs[j] = x[j, 0]
        ys[j] = x[j, 1]
        zs[j] = x[j, 2]
        gms[j] = gm[j]
    for i in numba.prange(n):
        xi = x[i, 0]
        yi = x[i, 1]
        zi = x[i, 2]
        # the self term is skipped by splitting the row at i, not by a branch
        hi = i if i < n_active else n_active
        ax, ay, az = _row_sum(xi, yi, zi, xs, ys, zs, gms, 0, hi, eps2)
        if i + 1 < n_active:
            bx, by, bz = _row_sum(xi, yi, zi, xs, ys, zs, gms, i + 1, n_active, eps2)
            ax += bx
            ay += by
            az += bz
        acc[i, 0] = ax
        acc[i, 1] = ay
        acc[i, 2] = az
    return 0


def accelerate_reference(x, gm, eps2=0.0):
    """Plain numpy version for tests: O(N^2) memory, no tricks."""
    d = x[:, None, :] - x[None, :, :]
    r2 = np.sum(d * d, axis=-1) + eps2
    np.fill_diagonal(r2, np.inf)
    return -np.sum(gm[None, :, None] * d / r2[..., None] ** 1.5, axis=1)

"""Force terms beyond Newtonian point-mass gravity, on plain float64 arrays.

Each term is three kernels over the bodies in the internal order (massive
bodies first), with its parameters in one tuple ``args``:

* ``accel(x, v, t, args, acc)`` *adds* the term's accelerations to ``acc``;
* ``energy(x, v, args)`` returns its contribution to the conserved energy
  (a potential, or the first post-Newtonian correction to the Hamiltonian),
  so that the energy monitor measures integration error, not physics;
* ``jacobian(x, v, t, args, jx, jv)`` *adds* ``da/dx`` and ``da/dv`` (shape
  (3N, 3N), rows and columns ``3 i + d``) to ``jx`` and ``jv``.

Any combination of terms is one :class:`TermTable` (a row of codes and
parameters a term), read by one kernel of each kind (:data:`TABLE`), so a loop
compiled for gravity with terms serves every combination of them, none
included.  The loops call those kernels through C callables whose addresses
the table holds (:func:`table_pointer`), handing over the data of the state
and of the table's arrays: a loop's compilation leaves the kernels out, and
they compile once for every loop, when a first table has terms.

``gm`` is ``G`` times the masses and ``m`` the masses, both in the internal
order; ``inv_c2`` is ``1 / c^2`` in the simulation's units.

References
----------
Anderson, J. D., Esposito, P. B., Martin, W., Thornton, C. L. & Muhleman,
D. O. 1975, ApJ 200, 221 (the single-source 1PN correction).  Nobili, A. &
Roxburgh, I. W. 1986, IAU Symp. 114, 105 (the GR potential).  Newhall, X X,
Standish, E. M. & Williams, J. G. 1983, A&A 125, 150 (the Einstein-Infeld-
Hoffmann equations of the JPL ephemerides).  Damour, T. & Deruelle, N. 1985
and Will, C. M. 2014, Living Rev. Relativ. 17, 4 (the conserved 1PN energy).
Murray, C. D. & Dermott, S. F. 1999, *Solar System Dynamics*, sect. 4.9 (the
zonal harmonics).  Papaloizou, J. C. B. & Larwood, J. D. 2000, MNRAS 315, 823
(migration and damping forces).  Hut, P. 1981, A&A 99, 126 and Eggleton, P. P.,
Kiseleva, L. G. & Hut, P. 1998, ApJ 499, 853 (the constant-time-lag tide).
Burns, J. A., Lamy, P. L. & Soter, S. 1979, Icarus 40, 1 (radiation pressure and
Poynting-Robertson drag).
"""

import math

from typing import Callable, NamedTuple

import numpy as np

from numba import carray
from numba.core import types as nbtypes

from ._jit import address_caller, contiguous_data, njit, pointer, slots, specialize, value
from .coordinates import row_difference
from .invariants import _add
from .jacobians import central_differences

# the name the energy template below is written against, bound by specialize
body_energy, = slots("body_energy")

__all__ = ["TermKernel", "TermTable", "TermRows", "TermRow", "UserTerms", "user_terms",
           "no_user_terms", "user_flag", "user_accel", "user_energy", "TABLE", "table", "row",
           "table_rows", "table_pointer", "with_jacobian",
           "table_accel", "table_energy", "table_jacobian", "gr_accel", "gr_energy", "gr_jacobian",
           "gr_potential_accel", "gr_potential_energy", "gr_potential_jacobian",
           "gr_full_accel", "gr_full_energy", "zonal_accel", "zonal_energy", "zonal_jacobian",
           "migration_accel", "migration_jacobian", "tides_accel", "tides_jacobian",
           "radiation_accel", "radiation_jacobian", "dissipative_energy",
           "rows_accel", "row_difference_jacobian"]


class TermKernel(NamedTuple):
    """The compiled kernels of one term and how loops that call them are compiled."""

    accel: Callable
    energy: Callable
    jacobian: Callable
    key: str          # names the loops compiled for it
    cache: bool = True  # False for a user's function, which numba cannot cache
    # reads_velocities(args) -> bool: whether the terms of these arguments read
    # the velocities (data, so that one loop serves terms that do and do not)
    reads_velocities: Callable = None


@njit(inline="always")
def _pull(acc, i, src, w, ax, ay, az):
    # body i's acceleration and the source's reaction, -w times it (w = m_i / m_src)
    acc[i, 0] += ax
    acc[i, 1] += ay
    acc[i, 2] += az
    acc[src, 0] -= w * ax
    acc[src, 1] -= w * ay
    acc[src, 2] -= w * az


@njit(inline="always")
def _apart(a, i, j, r):
    # r = a_i - a_j (rows of a), and returns |r|^2
    for d in range(3):
        r[d] = a[i, d] - a[j, d]
    return r[0] * r[0] + r[1] * r[1] + r[2] * r[2]


@njit(inline="always")
def _add_block(jac, i, j, wi, wj, d):
    # the 3x3 block d = d a_rel / dr (or du) of a_rel(r, u), r = x_i - x_j,
    # u = v_i - v_j, into jac: body i takes wi a_rel, body j -wj a_rel
    for a in range(3):
        for c in range(3):
            jac[3 * i + a, 3 * i + c] += wi * d[a, c]
            jac[3 * i + a, 3 * j + c] -= wi * d[a, c]
            if wj != 0.0:
                jac[3 * j + a, 3 * i + c] -= wj * d[a, c]
                jac[3 * j + a, 3 * j + c] += wj * d[a, c]


@njit(inline="always")
def _add_pair_block(jx, jv, i, j, wi, wj, dx, dv):
    # both blocks of a_rel(r, u): dx = d a_rel / dr into jx, dv = d a_rel / du into jv
    _add_block(jx, i, j, wi, wj, dx)
    _add_block(jv, i, j, wi, wj, dv)


def _energy_about_source(x, v, args):
    # A term's energy about its source body args[0]: body_energy(x, v, i,
    # args), each massive body's share (the masses are args' last item),
    # summed with compensation.  A template (specialize binds body_energy).
    src = args[0]
    m = args[-1]
    s = 0.0
    c = 0.0
    for i in range(x.shape[0]):
        if i == src or m[i] == 0.0:
            continue
        s, c = _add(s, c, body_energy(x, v, i, args))
    return s + c


# -- GR from one dominant body (Anderson et al. 1975) ------------------------------------

@njit(inline="always")  # called every substep: a call costs ~15 % of it
def gr_accel(x, v, t, args, acc):
    """The 1PN correction of each body about ``src`` (harmonic gauge)::

        a_i = mu / (c^2 r^3) [ (4 mu_i / r - v^2) r + 4 (r . v) v ]

    with ``r``, ``v`` relative to the source, ``mu = G m_src`` and
    ``mu_i = G (m_src + m_i)``; the source takes the reaction
    ``-(m_i / m_src) a_i`` so momentum is conserved.  The relative
    acceleration ``(1 + m_i / m_src) a_i`` is then Schwarzschild's test-body
    correction about ``mu_i``, whose periapsis advances by
    ``6 pi mu_i / (c^2 a (1 - e^2))`` a period; a test particle (``mu_i = mu``)
    feels exactly that correction.
    ``args = (src, gm, inv_c2)``; O(N), test particles included.
    """
    src, gm, inv_c2 = args
    mu = gm[src]
    k = mu * inv_c2
    inv_mu = 1.0 / mu
    # one division a body, and the source's reaction summed in registers (a
    # store to acc[src] every body would chain the iterations through memory)
    x0, x1, x2 = x[src, 0], x[src, 1], x[src, 2]
    v0, v1, v2 = v[src, 0], v[src, 1], v[src, 2]
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for i in range(x.shape[0]):
        if i == src:
            continue
        rx = x[i, 0] - x0
        ry = x[i, 1] - x1
        rz = x[i, 2] - x2
        ux = v[i, 0] - v0
        uy = v[i, 1] - v1
        uz = v[i, 2] - v2
        r2 = rx * rx + ry * ry + rz * rz
        inv_r = 1.0 / math.sqrt(r2)
        u2 = ux * ux + uy * uy + uz * uz
        rv = rx * ux + ry * uy + rz * uz
        f = k * inv_r * inv_r * inv_r
        a = f * (4.0 * (mu + gm[i]) * inv_r - u2)
        b = 4.0 * f * rv
        ax = a * rx + b * ux
        ay = a * ry + b * uy
        az = a * rz + b * uz
        acc[i, 0] += ax
        acc[i, 1] += ay
        acc[i, 2] += az
        w = gm[i] * inv_mu
        sx += w * ax
        sy += w * ay
        sz += w * az
    acc[src, 0] -= sx
    acc[src, 1] -= sy
    acc[src, 2] -= sz


@njit(inline="always")
def _gr_energy_of(x, v, i, args):
    # body i's share of gr_energy
    src, gm, inv_c2, m = args
    mu = gm[src]
    rx, ry, rz = row_difference(x, i, src)
    u2 = ((v[i, 0] - v[src, 0]) ** 2 + (v[i, 1] - v[src, 1]) ** 2
          + (v[i, 2] - v[src, 2]) ** 2)
    r = math.sqrt(rx * rx + ry * ry + rz * rz)
    mu_i = mu + gm[i]
    return (m[i] * (mu / mu_i) * inv_c2
            * (0.375 * u2 * u2 + 1.5 * mu_i * u2 / r + 0.5 * mu_i * mu_i / (r * r)))


gr_energy = specialize(_energy_about_source, "gr", body_energy=_gr_energy_of)
gr_energy.__doc__ = """The 1PN energy of each body's orbit about the source, from the
    Lagrangian whose equations :func:`gr_accel` are: Schwarzschild's test-body
    energy about ``mu_i = G (m_src + m_i)`` in the relative coordinates, times
    the reduced mass ``m_i m_src / (m_src + m_i) = m_i mu / mu_i``::

        m_i (mu / mu_i) (3/8 v^4 + 3/2 mu_i v^2 / r + 1/2 mu_i^2 / r^2) / c^2

    (``args`` as :func:`gr_accel`, plus the masses).  The Newtonian energy's
    rate of change under the term is ``sum_i m_i v_i . a_i`` (relative
    velocities), minus this energy's along the Keplerian motion about
    ``mu_i``: for two bodies the sum is conserved to O(1/c^4); with more,
    the others' pull on a body's relative orbit leaves terms of order their
    mass ratio to the source times the 1PN energy.
    """


@njit
def gr_jacobian(x, v, t, args, jx, jv):
    """``da/dx`` and ``da/dv`` of :func:`gr_accel`, reaction included."""
    src, gm, inv_c2 = args[0], args[1], args[2]
    mu = gm[src]
    k = mu * inv_c2
    n = x.shape[0]
    r = np.empty(3)
    u = np.empty(3)
    dx = np.empty((3, 3))
    dv = np.empty((3, 3))
    for i in range(n):
        if i == src:
            continue
        r2 = _apart(x, i, src, r)
        _apart(v, i, src, u)
        rr = math.sqrt(r2)
        u2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
        rv = r[0] * u[0] + r[1] * u[1] + r[2] * u[2]
        # a = k [A(r, u) r + B(r, u) u] with A = (4 mu_i / r - u^2) / r^3, B = 4 rv / r^3
        mu_i = mu + gm[i]
        A = (4.0 * mu_i / rr - u2) / (r2 * rr)
        B = 4.0 * rv / (r2 * rr)
        # dA/dr_b = dA_dr r_b, dB/dr_b = dB_dr r_b + 4 u_b / r^3
        dA_dr = -4.0 * mu_i / (r2 * r2 * r2) - 3.0 * A / r2
        dB_dr = -3.0 * B / r2
        for a in range(3):
            for b in range(3):
                # d/dr_b of A r_a + B u_a
                gx = (dA_dr * r[b]) * r[a] + (dB_dr * r[b]) * u[a] + 4.0 * u[b] / (r2 * rr) * u[a]
                if a == b:
                    gx += A
                # d/du_b: A depends on u through -u^2, B through rv
                gv = (-2.0 * u[b] / (r2 * rr)) * r[a] + (4.0 * r[b] / (r2 * rr)) * u[a]
                if a == b:
                    gv += B
                dx[a, b] = k * gx
                dv[a, b] = k * gv
        _add_pair_block(jx, jv, i, src, 1.0, gm[i] / mu, dx, dv)


# -- the GR potential (Nobili & Roxburgh 1986) ------------------------------------------

@njit(inline="always")  # called every substep: a call costs ~15 % of it
def gr_potential_accel(x, v, t, args, acc):
    """``a = -6 mu^2 r / (c^2 r^4)`` about the source, from the potential
    ``-3 mu^2 / (c^2 r^2)`` per unit mass; the source takes the reaction.
    ``args = (src, gm, inv_c2)``."""
    src, gm, inv_c2 = args[0], args[1], args[2]
    mu = gm[src]
    k = 6.0 * mu * mu * inv_c2
    for i in range(x.shape[0]):
        if i == src:
            continue
        rx, ry, rz = row_difference(x, i, src)
        r2 = rx * rx + ry * ry + rz * rz
        f = -k / (r2 * r2)
        _pull(acc, i, src, gm[i] / mu, f * rx, f * ry, f * rz)


@njit(inline="always")
def _gr_potential_energy_of(x, v, i, args):
    # body i's share of gr_potential_energy
    src, gm, inv_c2, m = args
    mu = gm[src]
    r2 = ((x[i, 0] - x[src, 0]) ** 2 + (x[i, 1] - x[src, 1]) ** 2
          + (x[i, 2] - x[src, 2]) ** 2)
    return -3.0 * mu * mu * inv_c2 * m[i] / r2


gr_potential_energy = specialize(_energy_about_source, "gr_potential",
                                 body_energy=_gr_potential_energy_of)
gr_potential_energy.__doc__ = """``sum_i -3 mu^2 m_i / (c^2 r_i^2)``; ``args`` as
:func:`gr_potential_accel` plus the masses."""


@njit
def gr_potential_jacobian(x, v, t, args, jx, jv):
    """``da/dx`` of :func:`gr_potential_accel`: ``-k (I / r^4 - 4 r r^T / r^6)``."""
    src, gm, inv_c2 = args[0], args[1], args[2]
    mu = gm[src]
    k = 6.0 * mu * mu * inv_c2
    r, dx = np.empty(3), np.empty((3, 3))
    for i in range(x.shape[0]):
        if i == src:
            continue
        r2 = _apart(x, i, src, r)
        inv4 = 1.0 / (r2 * r2)
        for a in range(3):
            for b in range(3):
                g = 4.0 * k * r[a] * r[b] * inv4 / r2
                if a == b:
                    g -= k * inv4
                dx[a, b] = g
        _add_block(jx, i, src, 1.0, gm[i] / mu, dx)


# -- Einstein-Infeld-Hoffmann among all massive bodies ----------------------------------

@njit
def _newtonian_and_potential(x, gm, n_active, an, pot):
    # the Newtonian accelerations of every body and the potentials
    # sum_k mu_k / r_ik, from the massive bodies only
    n = x.shape[0]
    for i in range(n):
        an[i, 0] = 0.0
        an[i, 1] = 0.0
        an[i, 2] = 0.0
        pot[i] = 0.0
    for i in range(n):
        for j in range(min(i, n_active)):
            dx, dy, dz = row_difference(x, j, i)
            r2 = dx * dx + dy * dy + dz * dz
            r = math.sqrt(r2)
            inv3 = 1.0 / (r2 * r)
            an[i, 0] += gm[j] * dx * inv3
            an[i, 1] += gm[j] * dy * inv3
            an[i, 2] += gm[j] * dz * inv3
            pot[i] += gm[j] / r
            if i < n_active:
                an[j, 0] -= gm[i] * dx * inv3
                an[j, 1] -= gm[i] * dy * inv3
                an[j, 2] -= gm[i] * dz * inv3
                pot[j] += gm[i] / r


@njit
def gr_full_accel(x, v, t, args, acc):
    """The 1PN part of the EIH accelerations (Newhall et al. 1983, eq. 1, less
    the Newtonian term), with the Newtonian accelerations in the 1PN terms.
    Massive bodies are the sources; test particles feel them.
    ``args = (gm, n_active, inv_c2, an, pot)`` with scratch ``an`` (N, 3) and
    ``pot`` (N,)."""
    gm, n_active, inv_c2, an, pot = args[0], args[1], args[2], args[3], args[4]
    n = x.shape[0]
    _newtonian_and_potential(x, gm, n_active, an, pot)
    for i in range(n):
        vi2 = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
        ax = 0.0
        ay = 0.0
        az = 0.0
        for j in range(n_active):
            if j == i:
                continue
            dx, dy, dz = row_difference(x, j, i)
            r2 = dx * dx + dy * dy + dz * dz
            r = math.sqrt(r2)
            mu = gm[j]
            inv3 = mu / (r2 * r)
            vj2 = v[j, 0] * v[j, 0] + v[j, 1] * v[j, 1] + v[j, 2] * v[j, 2]
            vij = v[i, 0] * v[j, 0] + v[i, 1] * v[j, 1] + v[i, 2] * v[j, 2]
            # (x_i - x_j) . v_j / r_ij
            nv = -(dx * v[j, 0] + dy * v[j, 1] + dz * v[j, 2]) / r
            ra = dx * an[j, 0] + dy * an[j, 1] + dz * an[j, 2]
            br = inv_c2 * (-4.0 * pot[i] - pot[j] + vi2 + 2.0 * vj2 - 4.0 * vij
                           - 1.5 * nv * nv + 0.5 * ra)
            ax += inv3 * dx * br
            ay += inv3 * dy * br
            az += inv3 * dz * br
            # (x_i - x_j) . (4 v_i - 3 v_j) (v_i - v_j)
            p = -(dx * (4.0 * v[i, 0] - 3.0 * v[j, 0]) + dy * (4.0 * v[i, 1] - 3.0 * v[j, 1])
                  + dz * (4.0 * v[i, 2] - 3.0 * v[j, 2]))
            q = inv_c2 * inv3 * p
            ax += q * (v[i, 0] - v[j, 0])
            ay += q * (v[i, 1] - v[j, 1])
            az += q * (v[i, 2] - v[j, 2])
            s = 3.5 * inv_c2 * mu / r
            ax += s * an[j, 0]
            ay += s * an[j, 1]
            az += s * an[j, 2]
        acc[i, 0] += ax
        acc[i, 1] += ay
        acc[i, 2] += az


@njit
def gr_full_energy(x, v, args):
    """The 1PN correction to the energy of the EIH Lagrangian::

        (1/c^2) [ sum_a 3/8 m_a v_a^4
                  + 1/2 sum_a sum_{b != a} (G m_a m_b / r_ab)
                        (3 v_a^2 - 7/2 v_a.v_b - 1/2 (n_ab.v_a)(n_ab.v_b))
                  + 1/2 sum_a sum_{b != a} sum_{c != a} G^2 m_a m_b m_c / (r_ab r_ac) ]

    ``args`` as :func:`gr_full_accel`, plus the masses.
    """
    gm, n_active, inv_c2, an, pot, m = args
    n = x.shape[0]
    _newtonian_and_potential(x, gm, n_active, an, pot)
    s = 0.0
    c = 0.0
    for a in range(n_active):
        va2 = v[a, 0] * v[a, 0] + v[a, 1] * v[a, 1] + v[a, 2] * v[a, 2]
        s, c = _add(s, c, 0.375 * m[a] * va2 * va2 + 0.5 * m[a] * pot[a] * pot[a])
        for b in range(n_active):
            if b == a:
                continue
            dx, dy, dz = row_difference(x, a, b)
            r = math.sqrt(dx * dx + dy * dy + dz * dz)
            na = (dx * v[a, 0] + dy * v[a, 1] + dz * v[a, 2]) / r
            nb = (dx * v[b, 0] + dy * v[b, 1] + dz * v[b, 2]) / r
            vab = v[a, 0] * v[b, 0] + v[a, 1] * v[b, 1] + v[a, 2] * v[b, 2]
            s, c = _add(s, c, 0.5 * m[a] * gm[b] / r * (3.0 * va2 - 3.5 * vab - 0.5 * na * nb))
    return (s + c) * inv_c2


# -- zonal harmonics of one oblate body ----------------------------------------------------

@njit(inline="always")  # called every substep: a call costs ~15 % of it
def zonal_accel(x, v, t, args, acc):
    """The J2 and J4 accelerations of the oblate body ``b`` on every other body
    (Murray & Dermott 1999, eq. 4.134 ff.), with ``u = (r . pole) / r``::

        a_2 = 3 k2 / (2 r^5) [ (5 u^2 - 1) r - 2 u r pole ]
        a_4 = k4 / (8 r^7) [ (315 u^4 - 210 u^2 + 15) r - (140 u^3 - 60 u) r pole ]

    where ``k2 = G m_b J2 R^2`` and ``k4 = G m_b J4 R^4``; the oblate body takes
    the reaction.  ``args = (b, gm, k2, k4, pole)``.
    """
    b, gm, k2, k4, pole = args[0], args[1], args[2], args[3], args[4]
    px = pole[0]
    py = pole[1]
    pz = pole[2]
    for i in range(x.shape[0]):
        if i == b:
            continue
        rx, ry, rz = row_difference(x, i, b)
        r2 = rx * rx + ry * ry + rz * rz
        r = math.sqrt(r2)
        u = (rx * px + ry * py + rz * pz) / r
        u2 = u * u
        inv5 = 1.0 / (r2 * r2 * r)
        fr = 1.5 * k2 * inv5 * (5.0 * u2 - 1.0)
        fp = -3.0 * k2 * inv5 * u * r
        if k4 != 0.0:
            inv7 = inv5 / r2
            fr += 0.125 * k4 * inv7 * ((315.0 * u2 - 210.0) * u2 + 15.0)
            fp -= 0.125 * k4 * inv7 * (140.0 * u2 - 60.0) * u * r
        _pull(acc, i, b, gm[i] / gm[b], fr * rx + fp * px, fr * ry + fp * py,
              fr * rz + fp * pz)


@njit(inline="always")
def _zonal_energy_of(x, v, i, args):
    # body i's share of zonal_energy
    b, gm, k2, k4, pole, m = args
    rx, ry, rz = row_difference(x, i, b)
    r = math.sqrt(rx * rx + ry * ry + rz * rz)
    u = (rx * pole[0] + ry * pole[1] + rz * pole[2]) / r
    u2 = u * u
    p2 = 0.5 * (3.0 * u2 - 1.0)
    p4 = 0.125 * ((35.0 * u2 - 30.0) * u2 + 3.0)
    return m[i] * (k2 * p2 / (r * r * r) + k4 * p4 / (r ** 5))


zonal_energy = specialize(_energy_about_source, "zonal", body_energy=_zonal_energy_of)
zonal_energy.__doc__ = """``sum_i m_i Phi(r_i)`` with ``Phi = k2 P2(u) / r^3 + k4 P4(u) / r^5``
(the monopole is gravity's); ``args`` as :func:`zonal_accel` plus the masses."""


@njit
def zonal_jacobian(x, v, t, args, jx, jv):
    """``da/dx`` of :func:`zonal_accel`: minus the Hessian of the potential.

    Writing ``Phi = g(s, q)`` with ``s = r^2`` and ``q = r . pole``, ::

        H = 2 g_s I + 4 g_ss r r^T + 2 g_sq (r pole^T + pole r^T) + g_qq pole pole^T

    with the partial derivatives of ``k2 (3 q^2 s^-5/2 - s^-3/2) / 2`` and
    ``k4 (35 q^4 s^-9/2 - 30 q^2 s^-7/2 + 3 s^-5/2) / 8``.
    """
    b, gm, k2, k4, pole = args[0], args[1], args[2], args[3], args[4]
    r, h = np.empty(3), np.empty((3, 3))
    for i in range(x.shape[0]):
        if i == b:
            continue
        s = _apart(x, i, b, r)
        q = r[0] * pole[0] + r[1] * pole[1] + r[2] * pole[2]
        q2 = q * q
        s52 = s ** -2.5
        s72 = s52 / s
        s92 = s72 / s
        c2 = 0.5 * k2
        g_s = c2 * (-7.5 * q2 * s72 + 1.5 * s52)
        g_ss = c2 * (26.25 * q2 * s92 - 3.75 * s72)
        g_sq = c2 * (-15.0 * q * s72)
        g_qq = c2 * (6.0 * s52)
        if k4 != 0.0:
            c4 = 0.125 * k4
            s112 = s92 / s
            s132 = s112 / s
            g_s += c4 * (-157.5 * q2 * q2 * s112 + 105.0 * q2 * s92 - 7.5 * s72)
            g_ss += c4 * (866.25 * q2 * q2 * s132 - 472.5 * q2 * s112 + 26.25 * s92)
            g_sq += c4 * (-630.0 * q2 * q * s112 + 210.0 * q * s92)
            g_qq += c4 * (420.0 * q2 * s92 - 60.0 * s72)
        for a in range(3):
            for c in range(3):
                h[a, c] = (4.0 * g_ss * r[a] * r[c] + 2.0 * g_sq * (r[a] * pole[c]
                                                                  + pole[a] * r[c])
                           + g_qq * pole[a] * pole[c])
            h[a, a] += 2.0 * g_s
        # d a / dr = -H: the weights' signs turned instead of H's
        _add_block(jx, i, b, -1.0, -(gm[i] / gm[b]), h)


# -- dissipative terms: no energy of their own ------------------------------------------

@njit
def dissipative_energy(x, v, args):
    """0.0: a dissipative term adds nothing to the conserved energy (the work it
    does is accounted for elsewhere)."""
    return 0.0


# -- migration and damping on prescribed time scales (Papaloizou & Larwood 2000) --------

@njit(inline="always")  # called every substep: a call costs ~15 % of it
def migration_accel(x, v, t, args, acc):
    """Migration and eccentricity / inclination damping of body ``b`` about ``p``::

        a_rel = -u / (2 tau_a) - 2 (r . u) r / (r^2 tau_e) - 2 u_z z / tau_inc

    with ``r``, ``u`` the position and velocity of ``b`` relative to ``p`` and
    ``z`` the frame's z axis; ``b`` takes ``wb a_rel`` and ``p`` takes
    ``-wp a_rel`` with ``wb = m_p / (m_p + m_b)``, ``wp = m_b / (m_p + m_b)``, so
    the relative acceleration is ``a_rel`` and momentum is conserved.
    ``args = (b, p, wb, wp, 1 / tau_a, 1 / tau_e, 1 / tau_inc)``, an inverse
    time scale 0 for a time scale left out.
    """
    b, p, wb, wp, ia, ie, ii = args
    rx, ry, rz = row_difference(x, b, p)
    ux, uy, uz = row_difference(v, b, p)
    fu = -0.5 * ia
    fr = -2.0 * ie * (rx * ux + ry * uy + rz * uz) / (rx * rx + ry * ry + rz * rz)
    ax = fu * ux + fr * rx
    ay = fu * uy + fr * ry
    az = fu * uz + fr * rz - 2.0 * ii * uz
    acc[b, 0] += wb * ax
    acc[b, 1] += wb * ay
    acc[b, 2] += wb * az
    acc[p, 0] -= wp * ax
    acc[p, 1] -= wp * ay
    acc[p, 2] -= wp * az


@njit
def migration_jacobian(x, v, t, args, jx, jv):
    """``da/dx`` and ``da/dv`` of :func:`migration_accel`::

        d a_rel / d r = -(2 / tau_e) [ (r u^T + (r . u) I) / r^2 - 2 (r . u) r r^T / r^4 ]
        d a_rel / d u = -I / (2 tau_a) - 2 r r^T / (r^2 tau_e) - 2 z z^T / tau_inc
    """
    b, p, wb, wp, ia, ie, ii = args
    r = np.empty(3)
    u = np.empty(3)
    dx = np.zeros((3, 3))
    dv = np.zeros((3, 3))
    r2 = _apart(x, b, p, r)
    _apart(v, b, p, u)
    ru = r[0] * u[0] + r[1] * u[1] + r[2] * u[2]
    for a in range(3):
        for c in range(3):
            dx[a, c] = -2.0 * ie * (r[a] * u[c] / r2 - 2.0 * ru * r[a] * r[c] / (r2 * r2))
            dv[a, c] = -2.0 * ie * r[a] * r[c] / r2
        dx[a, a] -= 2.0 * ie * ru / r2
        dv[a, a] -= 0.5 * ia
    dv[2, 2] -= 2.0 * ii
    _add_pair_block(jx, jv, b, p, wb, wp, dx, dv)


# -- the constant-time-lag tide (Hut 1981; Eggleton, Kiseleva & Hut 1998) ---------------

@njit(inline="always")  # called every substep: a call costs ~15 % of it
def tides_accel(x, v, t, args, acc):
    """The tide raised on body ``b`` (radius ``R``, Love number ``k2``, time lag
    ``tau``, spin ``Omega``) by every other massive body ``j``, as the force on
    ``j``::

        F_j = -3 k2 G m_j^2 R^5 / r^8 [ r + tau (2 (r . u) r / r^2 + u + r x Omega) ]

    with ``r``, ``u`` the position and velocity of ``j`` relative to ``b``; ``b``
    takes ``-F_j``.  ``args = (b, gm, 3 k2 R^5, tau, Omega)``.
    """
    b, gm, k, tau, om = args
    for j in range(x.shape[0]):
        if j == b or gm[j] == 0.0:
            continue
        rx, ry, rz = row_difference(x, j, b)
        ux, uy, uz = row_difference(v, j, b)
        r2 = rx * rx + ry * ry + rz * rz
        r8 = r2 * r2 * r2 * r2
        q = 2.0 * tau * (rx * ux + ry * uy + rz * uz) / r2
        gx = rx * (1.0 + q) + tau * (ux + ry * om[2] - rz * om[1])
        gy = ry * (1.0 + q) + tau * (uy + rz * om[0] - rx * om[2])
        gz = rz * (1.0 + q) + tau * (uz + rx * om[1] - ry * om[0])
        f = -k * gm[j] / r8
        w = gm[j] / gm[b]
        acc[j, 0] += f * gx
        acc[j, 1] += f * gy
        acc[j, 2] += f * gz
        acc[b, 0] -= w * f * gx
        acc[b, 1] -= w * f * gy
        acc[b, 2] -= w * f * gz


@njit
def tides_jacobian(x, v, t, args, jx, jv):
    """``da/dx`` and ``da/dv`` of :func:`tides_accel`.  With ``s = r^2``,
    ``w = r . u``, ``q = 2 tau w / s``, ``g' = (1 + q) r + tau (u + r x Omega)``
    and ``g = s^-4 g'`` (so that ``F_j = -3 k2 G m_j^2 R^5 g``)::

        dg/dr = s^-4 [ (1 + q) I + 2 tau r (u^T / s - 2 w r^T / s^2) - tau [Omega]x ]
                - 8 s^-5 g' r^T
        dg/du = tau s^-4 (I + 2 r r^T / s)

    where ``[Omega]x v = Omega x v``.
    """
    b, gm, k, tau, om = args
    r = np.empty(3)
    u = np.empty(3)
    gp = np.empty(3)
    dx = np.empty((3, 3))
    dv = np.empty((3, 3))
    for j in range(x.shape[0]):
        if j == b or gm[j] == 0.0:
            continue
        s = _apart(x, j, b, r)
        _apart(v, j, b, u)
        w = r[0] * u[0] + r[1] * u[1] + r[2] * u[2]
        q = 2.0 * tau * w / s
        gp[0] = r[0] * (1.0 + q) + tau * (u[0] + r[1] * om[2] - r[2] * om[1])
        gp[1] = r[1] * (1.0 + q) + tau * (u[1] + r[2] * om[0] - r[0] * om[2])
        gp[2] = r[2] * (1.0 + q) + tau * (u[2] + r[0] * om[1] - r[1] * om[0])
        s4 = 1.0 / (s * s * s * s)
        f = -k * gm[j]
        for a in range(3):
            for c in range(3):
                # d/dr_c of s^-4 g'_a: -8 s^-5 g'_a r_c + s^-4 dg'_a/dr_c, where
                # dg'_a/dr_c = (1 + q) delta_ac + 2 tau r_a (u_c / s - 2 w r_c / s^2)
                #              - tau [Omega]x_ac
                d = 2.0 * tau * r[a] * (u[c] / s - 2.0 * w * r[c] / (s * s))
                if a == c:
                    d += 1.0 + q
                dx[a, c] = f * (s4 * d - 8.0 * s4 / s * gp[a] * r[c])
                dv[a, c] = f * tau * s4 * 2.0 * r[a] * r[c] / s
            dv[a, a] += f * tau * s4
        # r x Omega = -Omega x r: its derivative is -[Omega]x
        dx[0, 1] += f * s4 * tau * om[2]
        dx[0, 2] -= f * s4 * tau * om[1]
        dx[1, 0] -= f * s4 * tau * om[2]
        dx[1, 2] += f * s4 * tau * om[0]
        dx[2, 0] += f * s4 * tau * om[1]
        dx[2, 1] -= f * s4 * tau * om[0]
        _add_pair_block(jx, jv, j, b, 1.0, gm[j] / gm[b], dx, dv)


# -- radiation pressure and Poynting-Robertson drag (Burns, Lamy & Soter 1979) ----------

@njit(inline="always")  # called every substep: a call costs ~15 % of it
def radiation_accel(x, v, t, args, acc):
    """Radiation from the source ``s`` on each body ``i`` with ``beta_i != 0``::

        a_i = beta_i G m_s / r^2 [ (1 - rdot / c) r_hat - u / c ]

    with ``r``, ``u`` relative to the source and ``rdot = r_hat . u``.  The source
    takes no reaction (it radiates isotropically).
    ``args = (s, G m_s, beta, 1 / c)``, ``beta`` of shape (N,).
    """
    s, mu, beta, ic = args
    for i in range(x.shape[0]):
        if beta[i] == 0.0:
            continue
        rx, ry, rz = row_difference(x, i, s)
        ux, uy, uz = row_difference(v, i, s)
        r2 = rx * rx + ry * ry + rz * rz
        r = math.sqrt(r2)
        k = beta[i] * mu / r2
        fr = k * (1.0 - (rx * ux + ry * uy + rz * uz) * ic / r) / r
        fu = -k * ic
        acc[i, 0] += fr * rx + fu * ux
        acc[i, 1] += fr * ry + fu * uy
        acc[i, 2] += fr * rz + fu * uz


@njit
def radiation_jacobian(x, v, t, args, jx, jv):
    """``da/dx`` and ``da/dv`` of :func:`radiation_accel`, writing
    ``a = k [r / r^3 - (r . u) r / (c r^4) - u / (c r^2)]`` with ``k = beta G m_s``::

        da/dr = k [ I / r^3 - 3 r r^T / r^5
                    - ((r . u) I + r u^T) / (c r^4) + 4 (r . u) r r^T / (c r^6)
                    + 2 u r^T / (c r^4) ]
        da/du = -k [ r r^T / (c r^4) + I / (c r^2) ]
    """
    s, mu, beta, ic = args
    r = np.empty(3)
    u = np.empty(3)
    dx = np.empty((3, 3))
    dv = np.empty((3, 3))
    for i in range(x.shape[0]):
        if beta[i] == 0.0:
            continue
        r2 = _apart(x, i, s, r)
        _apart(v, i, s, u)
        rr = math.sqrt(r2)
        w = r[0] * u[0] + r[1] * u[1] + r[2] * u[2]
        k = beta[i] * mu
        i3 = 1.0 / (r2 * rr)
        i4 = 1.0 / (r2 * r2)
        for a in range(3):
            for c in range(3):
                dx[a, c] = k * (-3.0 * r[a] * r[c] * i3 / r2 - ic * r[a] * u[c] * i4
                                + 4.0 * ic * w * r[a] * r[c] * i4 / r2
                                + 2.0 * ic * u[a] * r[c] * i4)
                dv[a, c] = -k * ic * r[a] * r[c] * i4
            dx[a, a] += k * (i3 - ic * w * i4)
            dv[a, a] -= k * ic / r2
        _add_pair_block(jx, jv, i, s, 1.0, 0.0, dx, dv)


# -- central differences of one term, for terms without an analytic Jacobian -----------

#: relative step of :func:`row_difference_jacobian` (about the cube root of the
#: machine epsilon, which balances truncation and rounding in a central difference)
FD_STEP = 6.0e-6


@njit
def _scale(a):
    s = 0.0
    for i in range(a.shape[0]):
        for d in range(3):
            s = max(s, abs(a[i, d]))
    return s if s > 0.0 else 1.0


# -- several terms as one table ------------------------------------------------------------
#
# Any combination of terms is data of one type, a :class:`TermTable`, read by
# one set of kernels (:data:`TABLE`): the loops compiled for gravity with terms
# are compiled once for every combination.  A user's functions enter the table
# through function pointers of declared signatures (:data:`USER_ACCEL`,
# :data:`USER_ENERGY`), so they too leave the loop's type unchanged.

#: the term codes of a table row
GR, GR_POTENTIAL, GR_FULL, ZONAL, MIGRATION, TIDES, RADIATION, USER = range(1, 9)
#: the integers and reals of a table row
INTS = 2
REALS = 5

_A2 = nbtypes.float64[:, :]
_I1 = nbtypes.int64[::1]
_F1 = nbtypes.float64[::1]
_F2 = nbtypes.float64[:, ::1]
#: the signature of a table's user accelerations: ``(x, v, t, pos, xu, vu, mu,
#: flag, acc)`` adds the user's terms to ``acc`` (see :class:`UserTerms`)
USER_ACCEL = nbtypes.void(_A2, _A2, nbtypes.float64, _I1, _F2, _F2, _F1, _I1, _A2)
#: the signature of a table's user potential: ``(x, pos, xu, mu) -> energy``
USER_ENERGY = nbtypes.float64(_A2, _I1, _F2, _F1)


class UserTerms(NamedTuple):
    """A table's user terms, in two arrays (views of the table's buffers).

    ``ints`` holds the addresses of the C callables of :data:`USER_ACCEL`
    and :data:`USER_ENERGY` (0: none), called through
    :func:`~orbits._kernels._jit.address_caller` so that a table's type is
    the same with and without user terms, then whether they read the
    velocities (1) or not (0), the flag, and ``pos``: ``pos[k]`` the internal
    row of the body set's row ``k`` (the user's functions see the bodies in
    the body set's order).  ``reals`` is scratch ``xu``, ``vu`` (each (n,
    3), in that order) and the masses ``mu`` in it.  A function that returns
    the wrong shape fills ``acc`` with NaN and sets the flag to 1: the loop
    then stops as for a non-finite state, and the caller names the cause
    (:func:`user_flag`)."""

    ints: np.ndarray    # int64: accelerations' address, energy's, velocities, flag, pos
    reals: np.ndarray   # float64 (7 n,): xu, vu, mu


#: the fixed entries of :attr:`UserTerms.ints`
_ACCEL, _ENERGY, _READS, _FLAG, _POS = range(5)


def user_terms(accel, energy, pos, mu, velocity_dependent):
    """The :class:`UserTerms` of C callables at the addresses ``accel`` and
    ``energy`` over bodies in the order ``pos`` with masses ``mu``."""
    n = len(pos)
    ints = np.concatenate([[accel, energy, int(bool(velocity_dependent)), 0],
                           np.asarray(pos, dtype=np.int64)]).astype(np.int64)
    reals = np.zeros(7 * n)
    reals[6 * n:] = mu
    return UserTerms(ints, reals)


def no_user_terms():
    """The :class:`UserTerms` of a table without user terms."""
    return user_terms(0, 0, np.zeros(0, dtype=np.int64), np.zeros(0), False)


def user_flag(u):
    """The flag of the user terms ``u``: 1 after a function returned the wrong shape."""
    return int(u.ints[_FLAG])


#: the header of a table's integer buffer: its rows, bodies and the user
#: terms' bodies, the addresses of its kernels' C callables (accelerations,
#: energy, Jacobians; 0: none), and whether a term reads the velocities
_ROWS, _BODIES, _USERS, _ACCEL_AT, _ENERGY_AT, _JACOBIAN_AT, _READS_V = range(7)
_HEAD = 7


class TermRows(NamedTuple):
    """A table's rows as the kernels read them: row ``k`` is term
    ``codes[k]`` with its integers, reals and per-body values (:func:`row`);
    every array a view of the table's buffers (:class:`TermTable`), all
    one-dimensional but the scratch ``an``, so that the views cost a few
    nanoseconds (numba's reshape costs some twenty a call)."""

    codes: np.ndarray     # int64 (n,)
    ints: np.ndarray      # int64 (n INTS,): row k's at [k INTS, (k + 1) INTS)
    reals: np.ndarray     # float64 (n REALS,): row k's at [k REALS, (k + 1) REALS)
    per_body: np.ndarray  # float64 (n N,): row k's at [k N, (k + 1) N)
    gm: np.ndarray        # G m, internal order
    m: np.ndarray         # masses, internal order
    an: np.ndarray        # scratch (N, 3)
    pot: np.ndarray       # scratch (N,)
    user: UserTerms


class TermTable(NamedTuple):
    """Force terms as data, in two buffers and a scratch array: ``ibuf``
    (int64: a header, then the rows' codes and integers and the user terms'
    integers), ``rbuf`` (float64: the rows' reals and per-body values, ``G
    m``, the masses, scratch and the user terms' reals) and ``an`` (N, 3).
    The loops hand them to the table's C callables (:func:`table_pointer`),
    whose addresses the header holds, and the kernels read them as
    :class:`TermRows` (:attr:`rows`).  A table travels to another process
    without the addresses and takes that process's on arrival."""

    ibuf: np.ndarray
    rbuf: np.ndarray
    an: np.ndarray

    @property
    def rows(self):
        """The :class:`TermRows` of the table (views of its buffers)."""
        return _views.py_func(self.ibuf, self.rbuf, self.an)

    @property
    def user(self):
        """The :class:`UserTerms` of the table."""
        return self.rows.user

    def __deepcopy__(self, memo):
        # the same process: the addresses stay good
        return TermTable(self.ibuf.copy(), self.rbuf.copy(), self.an.copy())

    def __reduce__(self):
        # another process has other addresses: the buffers travel with the
        # kernels' addresses cleared, and the table takes that process's on
        # arrival; a user's functions' addresses cannot
        user = self.user
        if user.ints[_ACCEL] != 0 or user.ints[_ENERGY] != 0:
            raise TypeError(
                "a simulation with UserForce terms holds the addresses of their compiled "
                "code in this process and cannot be pickled; send what makes it (its "
                "bodies, integrator and forces, as orbits.Ensemble does), or run it with "
                "output= to a file and restore it with Simulation.from_file(path, "
                "functions=...)")
        ibuf = self.ibuf.copy()
        jacobian = bool(ibuf[_JACOBIAN_AT])
        ibuf[_ACCEL_AT:_JACOBIAN_AT + 1] = 0
        return (_arrived, (ibuf, self.rbuf, self.an, jacobian))


@njit(inline="always")
def _buffer_sizes(nrows, n, nu):
    # the lengths of a table's two buffers
    return (_HEAD + nrows * (1 + INTS) + _POS + nu,
            nrows * (REALS + n) + 3 * n + 7 * nu)


@njit(inline="always")
def _views(ibuf, rbuf, an):
    # the TermRows of a table's buffers (in the C callables, and as Python
    # for TermTable.rows)
    nrows = ibuf[_ROWS]
    n = ibuf[_BODIES]
    nu = ibuf[_USERS]
    i = _HEAD
    codes = ibuf[i:i + nrows]
    i += nrows
    ints = ibuf[i:i + nrows * INTS]
    i += nrows * INTS
    uints = ibuf[i:i + _POS + nu]
    r = nrows * REALS
    reals = rbuf[:r]
    per_body = rbuf[r:r + nrows * n]
    r += nrows * n
    gm = rbuf[r:r + n]
    m = rbuf[r + n:r + 2 * n]
    pot = rbuf[r + 2 * n:r + 3 * n]
    r += 3 * n
    ureals = rbuf[r:r + 7 * nu]
    return TermRows(codes, ints, reals, per_body, gm, m, an, pot, UserTerms(uints, ureals))


def _arrived(ibuf, rbuf, an, jacobian):
    # a table unpickled: this process's addresses of its kernels
    tab = TermTable(ibuf, rbuf, an)
    _address(tab, jacobian)
    return tab


class TermRow(NamedTuple):
    """One term's row of a :class:`TermTable`, as a term's ``bind`` gives it."""

    code: int
    ints: tuple = ()
    reals: tuple = ()
    per_body: object = None


def table(rows, gm, m, user=None, jacobian=False):
    """The :class:`TermTable` of ``rows`` (:class:`TermRow`) over bodies with
    ``G m`` ``gm`` and masses ``m`` (internal order); ``user`` the
    :class:`UserTerms` of the rows coded :data:`USER`, or None without such
    rows.  Every table holds arrays and numbers alone (a user function by
    its address), which numba types on a call from Python in a few
    microseconds, and all are of one type: one loop serves every table, an
    empty one included.  A table with rows holds the addresses of the C
    callables of its accelerations and energy (compiled on first use,
    :func:`table_pointer`), and with ``jacobian`` its Jacobians'
    (:func:`with_jacobian`)."""
    n = len(m)
    rows = list(rows)
    user = no_user_terms() if user is None else user
    nrows, nu = len(rows), len(user.ints) - _POS
    isize, rsize = _buffer_sizes.py_func(nrows, n, nu)
    ibuf = np.zeros(isize, dtype=np.int64)
    rbuf = np.zeros(rsize)
    ibuf[_ROWS], ibuf[_BODIES], ibuf[_USERS] = nrows, n, nu
    tab = TermTable(ibuf, rbuf, np.zeros((n, 3)))
    t = tab.rows
    for k, r in enumerate(rows):
        t.codes[k] = r.code
        t.ints[k * INTS:k * INTS + len(r.ints)] = r.ints
        t.reals[k * REALS:k * REALS + len(r.reals)] = r.reals
        if r.per_body is not None:
            t.per_body[k * n:(k + 1) * n] = r.per_body
    t.gm[:] = gm
    t.m[:] = m
    t.user.ints[:] = user.ints
    t.user.reals[:] = user.reals
    ibuf[_READS_V] = any(r.code in (GR, GR_FULL, MIGRATION, TIDES, RADIATION) for r in rows) or (
        any(r.code == USER for r in rows) and bool(user.ints[_READS]))
    _address(tab, jacobian)
    return tab


_call_accel = address_caller(USER_ACCEL)
_call_energy = address_caller(USER_ENERGY)


@njit
def user_accel(u, x, v, t, acc):
    """Adds the accelerations of the user terms ``u`` (a :class:`UserTerms`)
    to ``acc``; none where there are none (address 0)."""
    address = u.ints[_ACCEL]
    if address != 0:
        n = u.ints.shape[0] - _POS
        r = u.reals
        _call_accel(address, (x, v, t, u.ints[_POS:], r[:3 * n].reshape((n, 3)),
                              r[3 * n:6 * n].reshape((n, 3)), r[6 * n:],
                              u.ints[_FLAG:_FLAG + 1], acc))


@njit
def user_energy(u, x):
    """The potential of the user terms ``u`` (0 where they have none)."""
    address = u.ints[_ENERGY]
    if address != 0:
        n = u.ints.shape[0] - _POS
        return _call_energy(address, (x, u.ints[_POS:], u.reals[:3 * n].reshape((n, 3)),
                                      u.reals[6 * n:]))
    return 0.0


@njit
def _user_velocity_dependent(u):
    return u.ints[_READS] != 0


@njit(inline="always")
def row(tab, k):
    """Row ``k`` of the :class:`TermRows` ``tab``: its integers, its reals
    and its per-body values (views)."""
    n = tab.m.shape[0]
    return (tab.ints[k * INTS:(k + 1) * INTS], tab.reals[k * REALS:(k + 1) * REALS],
            tab.per_body[k * n:(k + 1) * n])


@njit(inline="always")
def table_rows(tab):
    """The number of rows (terms) of the table ``tab``."""
    return tab.ibuf[_ROWS]


@njit(inline="always")
def table_reads_velocities(tab):
    """Whether a term of the table ``tab`` reads the velocities: GR, GRFull
    and the dissipative terms do, a user's term says (each term class's
    ``velocity_dependent``, which tests/test_forces.py holds this to)."""
    return tab.ibuf[_READS_V] != 0


def _table_accel(xp, vp, t, nx, ip, rp, anp, accp):
    # every row's accelerations: the C callable of table_accel
    tab = _pointed(ip, rp, anp)
    rows_accel(carray(xp, (nx, 3)), carray(vp, (nx, 3)), t, tab, value(0), tab.codes.shape[0],
               carray(accp, (nx, 3)))


@njit(inline="always")
def _pointed(ip, rp, anp):
    # the TermRows of the table whose arrays are at ip, rp and anp: arrays
    # that own nothing, so that their views count no references
    head = carray(ip, (_HEAD,))
    n = head[_BODIES]
    isize, rsize = _buffer_sizes(head[_ROWS], n, head[_USERS])
    return _views(carray(ip, (isize,)), carray(rp, (rsize,)), carray(anp, (n, 3)))


@njit
def rows_accel(x, v, t, tab, first, end, acc):
    """Adds the accelerations of the rows ``first`` to ``end - 1`` of ``tab`` to ``acc``."""
    gm = tab.gm
    for k in range(first, end):
        c = tab.codes[k]
        ints, reals, per_body = row(tab, k)
        if c == GR:
            gr_accel(x, v, t, (ints[0], gm, reals[0]), acc)
        elif c == GR_POTENTIAL:
            gr_potential_accel(x, v, t, (ints[0], gm, reals[0]), acc)
        elif c == GR_FULL:
            gr_full_accel(x, v, t, (gm, ints[0], reals[0], tab.an, tab.pot), acc)
        elif c == ZONAL:
            zonal_accel(x, v, t, (ints[0], gm, reals[0], reals[1], reals[2:5]), acc)
        elif c == MIGRATION:
            migration_accel(x, v, t, (ints[0], ints[1], reals[0], reals[1], reals[2],
                                      reals[3], reals[4]), acc)
        elif c == TIDES:
            tides_accel(x, v, t, (ints[0], gm, reals[0], reals[1], reals[2:5]), acc)
        elif c == RADIATION:
            radiation_accel(x, v, t, (ints[0], reals[0], per_body, reals[1]), acc)
        elif c == USER:
            user_accel(tab.user, x, v, t, acc)


def _table_energy(xp, vp, nx, ip, rp, anp):
    # the rows' energy: the C callable of table_energy
    x = carray(xp, (nx, 3))
    v = carray(vp, (nx, 3))
    tab = _pointed(ip, rp, anp)
    gm = tab.gm
    m = tab.m
    e = 0.0
    for k in range(tab.codes.shape[0]):
        c = tab.codes[k]
        ints, reals, _ = row(tab, k)
        if c == GR:
            e += gr_energy(x, v, (ints[0], gm, reals[0], m))
        elif c == GR_POTENTIAL:
            e += gr_potential_energy(x, v, (ints[0], gm, reals[0], m))
        elif c == GR_FULL:
            e += gr_full_energy(x, v, (gm, ints[0], reals[0], tab.an, tab.pot, m))
        elif c == ZONAL:
            e += zonal_energy(x, v, (ints[0], gm, reals[0], reals[1], reals[2:5], m))
        elif c == USER:
            e += user_energy(tab.user, x)
    return e


@njit(inline="always")
def _row_accel(x, v, t, row, acc):
    # adds the accelerations of the table's row k alone, row = (tab, k)
    tab, k = row
    rows_accel(x, v, t, tab, k, k + 1, acc)


_row_differences = specialize(central_differences, "term_row", inline=True, force=_row_accel)


@njit
def row_difference_jacobian(x, v, t, tab, k, velocity, jx, jv):
    """Adds the central-difference ``da/dx`` (and with ``velocity`` ``da/dv``)
    of row ``k`` of the :class:`TermRows` ``tab`` to ``jx`` (``jv``), column by column
    (:func:`~.jacobians.central_differences`): the accelerations at ``x +-
    delta e_q`` with ``delta`` :data:`FD_STEP` of the component (at least
    1e-3 of the largest), for terms without an analytic Jacobian (6N or 12N
    evaluations of the row)."""
    _row_differences(x, v, t, (tab, k), jx, jv, velocity, FD_STEP, 1e-3 * _scale(x),
                     1e-3 * _scale(v), True)


def _table_jacobian(xp, vp, t, nx, ip, rp, anp, jxp, jvp):
    # the rows' da/dx and da/dv, analytic where a term has one, central
    # differences for the full 1PN term and the user's terms: the C callable
    # of table_jacobian
    x = carray(xp, (nx, 3))
    v = carray(vp, (nx, 3))
    jx = carray(jxp, (3 * nx, 3 * nx))
    jv = carray(jvp, (3 * nx, 3 * nx))
    tab = _pointed(ip, rp, anp)
    gm = tab.gm
    for k in range(tab.codes.shape[0]):
        c = tab.codes[k]
        ints, reals, per_body = row(tab, k)
        if c == GR:
            gr_jacobian(x, v, t, (ints[0], gm, reals[0]), jx, jv)
        elif c == GR_POTENTIAL:
            gr_potential_jacobian(x, v, t, (ints[0], gm, reals[0]), jx, jv)
        elif c == GR_FULL:
            row_difference_jacobian(x, v, t, tab, k, value(True), jx, jv)
        elif c == ZONAL:
            zonal_jacobian(x, v, t, (ints[0], gm, reals[0], reals[1], reals[2:5]), jx, jv)
        elif c == MIGRATION:
            migration_jacobian(x, v, t, (ints[0], ints[1], reals[0], reals[1], reals[2],
                                         reals[3], reals[4]), jx, jv)
        elif c == TIDES:
            tides_jacobian(x, v, t, (ints[0], gm, reals[0], reals[1], reals[2:5]),
                           jx, jv)
        elif c == RADIATION:
            radiation_jacobian(x, v, t, (ints[0], reals[0], per_body, reals[1]), jx, jv)
        elif c == USER:
            row_difference_jacobian(x, v, t, tab, k,
                                     value(_user_velocity_dependent(tab.user)), jx, jv)


_P = nbtypes.CPointer(nbtypes.float64)
_IP = nbtypes.CPointer(nbtypes.int64)
#: the signatures of the table's C callables, which take the data of the
#: state, of the table's arrays and of the result, and the bodies' number
#: ``nx``: ``accel(x, v, t, nx, ibuf, rbuf, an, acc)``, ``energy(x, v, nx,
#: ibuf, rbuf, an) -> e`` and ``jacobian(x, v, t, nx, ibuf, rbuf, an, jx, jv)``
TABLE_ACCEL = nbtypes.void(_P, _P, nbtypes.float64, nbtypes.int64, _IP, _P, _P, _P)
TABLE_ENERGY = nbtypes.float64(_P, _P, nbtypes.int64, _IP, _P, _P)
TABLE_JACOBIAN = nbtypes.void(_P, _P, nbtypes.float64, nbtypes.int64, _IP, _P, _P, _P, _P)

_KERNELS = {_ACCEL_AT: (_table_accel, TABLE_ACCEL), _ENERGY_AT: (_table_energy, TABLE_ENERGY),
            _JACOBIAN_AT: (_table_jacobian, TABLE_JACOBIAN)}
_POINTERS = {}


def table_pointer(kind):
    """The address of a C callable of a table's rows: ``kind`` ``"accel"``
    (:data:`TABLE_ACCEL`), ``"energy"`` (:data:`TABLE_ENERGY`) or
    ``"jacobian"`` (:data:`TABLE_JACOBIAN`).  Compiled on the first call in
    a process or loaded from numba's cache on disk, and kept for the
    process: one compilation serves every loop and every table."""
    at = {"accel": _ACCEL_AT, "energy": _ENERGY_AT, "jacobian": _JACOBIAN_AT}[kind]
    if at not in _POINTERS:
        _POINTERS[at] = pointer(*_KERNELS[at])
    return _POINTERS[at].cfunc.address


def _address(tab, jacobian):
    # a table's addresses of its kernels: none without rows, which the loops
    # then do not call (so a run without terms compiles none of them), and
    # the Jacobians' only where asked (with_jacobian)
    if tab.ibuf[_ROWS] == 0:
        return
    tab.ibuf[_ACCEL_AT] = table_pointer("accel")
    tab.ibuf[_ENERGY_AT] = table_pointer("energy")
    if jacobian:
        tab.ibuf[_JACOBIAN_AT] = table_pointer("jacobian")


def with_jacobian(tab):
    """The table ``tab`` with its Jacobians' C callable (set in place), what
    loops that read the terms' Jacobians (implicit methods, variational
    equations) take; compiled on first use.  A table without it adds NaN to
    a Jacobian, so that a loop that was not given it stops."""
    if tab.ibuf[_ROWS] > 0:
        tab.ibuf[_JACOBIAN_AT] = table_pointer("jacobian")
    return tab


_call_table_accel = address_caller(TABLE_ACCEL)
_call_table_energy = address_caller(TABLE_ENERGY)
_call_table_jacobian = address_caller(TABLE_JACOBIAN)


@njit(inline="always")
def table_accel(x, v, t, tab, acc):
    """Adds the accelerations of every term of the table ``tab`` to ``acc``."""
    at = tab.ibuf[_ACCEL_AT]
    if at != 0:
        _call_table_accel(at, (contiguous_data(x), contiguous_data(v), t, x.shape[0],
                               contiguous_data(tab.ibuf), contiguous_data(tab.rbuf),
                               contiguous_data(tab.an), contiguous_data(acc)))


@njit(inline="always")
def table_energy(x, v, tab):
    """The terms' contribution to the conserved energy (see the module notes)."""
    at = tab.ibuf[_ENERGY_AT]
    if at != 0:
        return _call_table_energy(at, (contiguous_data(x), contiguous_data(v), x.shape[0],
                                       contiguous_data(tab.ibuf), contiguous_data(tab.rbuf),
                                       contiguous_data(tab.an)))
    return 0.0


@njit(inline="always")
def table_jacobian(x, v, t, tab, jx, jv):
    """Adds the terms' ``da/dx`` and ``da/dv`` to ``jx`` and ``jv``: analytic
    where a term has one, central differences for the full 1PN term and the
    user's terms."""
    at = tab.ibuf[_JACOBIAN_AT]
    if at != 0:
        _call_table_jacobian(at, (contiguous_data(x), contiguous_data(v), t, x.shape[0],
                                  contiguous_data(tab.ibuf), contiguous_data(tab.rbuf),
                                  contiguous_data(tab.an), contiguous_data(jx),
                                  contiguous_data(jv)))
    elif tab.ibuf[_ROWS] > 0:
        jx[0, 0] += math.nan


#: the kernels of every table of terms: one key, so one loop for any combination
TABLE = TermKernel(table_accel, table_energy, table_jacobian, "terms",
                   reads_velocities=table_reads_velocities)

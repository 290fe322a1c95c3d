"""The tangent map of the Wisdom-Holman family: first-order variational equations.

A tangent vector ``delta = (dx, dv)``, with a constant mass variation ``dm``,
follows the derivative of the map itself (Rein & Tamayo 2016 [2]): every
operator of a step (:mod:`orbits._kernels.wisdom_holman`) is a smooth map of
the state and the masses, so the step's tangent is the chain of the
operators' derivatives, applied in the same order.  This is the exact
tangent of the symplectic map, not an integration of the variational
equations of the true flow, so the pair (state, tangent) is itself the map
of the variational system and the chaos indicators built on it see the
map's dynamics (the symplectic tangent map of Mikkola & Innanen 1999 [3];
WHFast's approach, Rein & Tamayo 2015 [1], 2016 [2]).

Rows.  The state arrays ``x``, ``v`` of a run with ``k`` tangent vectors have
``n (1 + k)`` rows: the ``n`` bodies, then tangent vector ``j`` in rows
``[n (1 + j), n (2 + j))`` (``dx`` in ``x``, ``dv`` in ``v``), in the inertial
frame.  The internal state (Jacobi or democratic heliocentric, the
workspace's ``xj``, ``vj``) has the same layout, its tangent rows the
derivative of the internal coordinates, so a checkpoint keeps both.

The operators and their derivatives, for tangent vector ``j`` with ``dgm =
G dm`` (mass variations may be zero):

* coordinates: Jacobi and democratic heliocentric coordinates are linear in
  the state with mass-dependent weights; the tangent applies the same
  linear map to ``delta`` plus its derivative in the masses applied to the
  state (``w_i = m_i / eta_i`` gives ``dw_i = (dm_i - w_i deta_i) / eta_i``;
  the centre of mass ``X = sum m x / M`` gives ``dX = (sum dm x + m dx - X dM) / M``);
* Kepler drift: :func:`~orbits._kernels.kepler_tangent.kepler_drift_tangent`, exact
  derivative in the state and in ``G eta_i`` (Jacobi) or ``G m_0`` (democratic
  heliocentric), whose variation is ``G`` times the cumulative ``dm`` or ``dm_0``;
* interaction kick: the Jacobian of the pair accelerations it contains,
  block ``G m_l (I / r^3 - 3 d d^T / r^5)`` of body ``i`` against ``l``
  (``d = x_i - x_l``) and ``G dm_l d / r^3`` for the masses, transformed as
  the kick transforms its accelerations, with the derivative of the Jacobi
  Kepler term ``G eta_i x'_i / r'^3``;
* jump (democratic heliocentric): linear, ``dQ_i += h (sum_l m_l dV_l + dm_l
  V_l) / m_0 - h dm_0 sum_l m_l V_l / m_0^2``;
* added force terms (position-only, :mod:`.terms`): their Jacobian
  ``da/dx`` (``TermKernel.jacobian``) times the inertial ``dx``, transformed
  as their kick; their dependence on the masses is not known, so mass
  variations with terms are refused (by the integrator);
* correctors: compositions of drifts and perturbation steps, so their
  tangent is the composition of the tangents above.

A mass variation of a test particle (a row at or after ``N_active``, which
the map lets pull nothing) is differentiated as in the map in which every
body is active, which at zero mass has the same values: the tangent feels
its pull (as the variational equations of the other integrators do).

The kernels take the tangent arguments as one tuple ``tp = (dgm, deta, k,
masses, jx, jv, box, chaos)``: ``dgm`` (shape (K, n)) the variations of ``G m``,
``deta`` (shape (K, n)) those of each row's Kepler ``G M``, ``k <= K`` the
number of tangent vectors to carry (all of them in a step; 1 to synchronise
the chaos indicators' vector; 0 for the bodies alone), ``masses`` whether
any ``dm`` is non-zero, ``jx``, ``jv`` (shape (3n, 3n)) scratch for the
terms' Jacobian, ``box`` the chaos accumulators
(:mod:`orbits._kernels.variational`) and ``chaos`` whether they are on.
The bound ``targs`` of the
Wisdom-Holman templates is then ``(the terms' args, tp)``.

Chaos indicators.  With them on (a flag of the arguments), after
every step the loop takes tangent vector 0 at the step's internal point,
before the deferred half drift and the corrector, to inertial coordinates
(a linear map, :func:`jacobi_inertial_tangent`) and hands it to
:func:`~orbits._kernels.variational.chaos_update`.  Synchronising it fully,
as an output does, would cost a Kepler drift of the bodies and of the
vector every step, about doubling the cost of a step with the indicators
(benchmarks/RESULTS.md).  The vector at the
internal point is the fully synchronised one mapped back by the half drift
(and corrector), a near-identity map the same every step, so ``|delta|``
differs by a bounded factor: the Lyapunov exponent and MEGNO's limits (2 on
regular orbits, slope ``lambda / 2`` on chaotic ones) are the same, and the
finite-time ``<Y>`` differs by a transient that decays as ``ln(t) / t``
(on Jupiter and Saturn with a 50-day step, 1.5e-2 after 2000 steps and
2.6e-3 after 20000; tests/kernels/test_wh_tangent.py).  When
``|delta|`` has grown large the internal rows of vector 0 are scaled by an
exact power of two inside the loop
(:func:`~orbits._kernels.variational.renormalise`, its exponent from the
internal rows' norm); the tangent being linear, this is exact, and the
loop never returns ``RENORMALISE``.

References
----------
.. [1] Rein, H. & Tamayo, D. 2015, "WHFAST: a fast and unbiased
   implementation of a symplectic Wisdom-Holman integrator for long-term
   gravitational simulations", MNRAS 452, 376.
.. [2] Rein, H. & Tamayo, D. 2016, "Second-order variational equations for
   N-body simulations", MNRAS 459, 2275.
.. [3] Mikkola, S. & Innanen, K. 1999, "Symplectic tangent map for
   planetary motions", Celest. Mech. Dyn. Astron. 74, 59.
"""

import math

from ._jit import called, njit, slots, specialize, value
from .coordinates import (from_democratic_heliocentric, from_jacobi, jacobi_step, row,
                          row_difference, set_row, to_democratic_heliocentric, to_jacobi)
from .gravity import add_pulls, pull_with_sums, zero_rows
from .kepler import straight_drift
from .kepler_tangent import advance_tangent_by_anomaly, kepler_drift_tangent
from .stepping import epilogue, terms_recorder, work_kernels
from .terms import table_rows
from .variational import (chaos_update, renormalise, tangent_product, varied_recorder,
                          variational_work_kernels)
from .wisdom_holman import (_apply_corrector, _correct_compiled, _heliocentric_term_kick,
                            _jacobi_term_kick, _synchronize, _wh_loop, escape_kernels, escape_pointer,
                            heliocentric_interaction_kick, jump,
                            short_step_anomalies)

# the names the templates below are written against, bound by specialize
(TERMS, conversion, record, inertial_tangent, jacobian, note, synchronize, term_jacobian,
 term_kick, term_tangent) = slots(
    "TERMS", "conversion", "record", "inertial_tangent", "jacobian", "note", "synchronize",
    "term_jacobian", "term_kick", "term_tangent")

__all__ = ["drift_tangent", "interaction_kick_and_tangent",
           "jump_tangent",
           "heliocentric_kick_tangent", "to_jacobi_tangent", "from_jacobi_tangent",
           "to_heliocentric_tangent", "from_heliocentric_tangent", "jacobi_inertial_tangent",
           "heliocentric_inertial_tangent", "wh_tangent_loop", "tangent_loop_escape",
           "tangent_synchronizer"]


# -- coordinates -------------------------------------------------------------------------

@njit(inline="always")
def _to_jacobi_block(a, out, gm, eta, dgm, deta, j, masses):
    # tangent block j of to_jacobi_one: a's rows o.. into out's, with the
    # bodies' Jacobi components (out[:n], already computed) for the weights'
    # mass derivative
    n = gm.shape[0]
    o = n * (1 + j)
    sx, sy, sz = row(a, o)
    for i in range(1, n):
        dx = a[o + i, 0] - sx
        dy = a[o + i, 1] - sy
        dz = a[o + i, 2] - sz
        out[o + i, 0] = dx
        out[o + i, 1] = dy
        out[o + i, 2] = dz
        w = gm[i] / eta[i]
        sx += w * dx
        sy += w * dy
        sz += w * dz
        if masses:
            dw = (dgm[j, i] - w * deta[j, i]) / eta[i]
            sx += dw * out[i, 0]
            sy += dw * out[i, 1]
            sz += dw * out[i, 2]
    set_row(out, o, sx, sy, sz)


@njit(inline="always")
def _from_jacobi_block(aj, out, gm, eta, dgm, deta, j, masses):
    # tangent block j of from_jacobi_one, with the bodies' Jacobi aj[:n]
    n = gm.shape[0]
    o = n * (1 + j)
    sx, sy, sz = row(aj, o)
    for i in range(n - 1, 0, -1):
        w = gm[i] / eta[i]
        sx -= w * aj[o + i, 0]
        sy -= w * aj[o + i, 1]
        sz -= w * aj[o + i, 2]
        if masses:
            dw = (dgm[j, i] - w * deta[j, i]) / eta[i]
            sx -= dw * aj[i, 0]
            sy -= dw * aj[i, 1]
            sz -= dw * aj[i, 2]
        out[o + i, 0] = aj[o + i, 0] + sx
        out[o + i, 1] = aj[o + i, 1] + sy
        out[o + i, 2] = aj[o + i, 2] + sz
    set_row(out, o, sx, sy, sz)


@njit
def to_jacobi_tangent(x, v, gm, eta, xj, vj, tp):
    """:func:`~orbits._kernels.coordinates.to_jacobi` of the bodies (rows
    ``[0, n)``, ``n = gm.shape[0]``) and of the first ``tp[2]`` tangent
    vectors, with the transformation's derivative in the masses."""
    n = gm.shape[0]
    to_jacobi(x[:n], v[:n], gm, eta, xj[:n], vj[:n])
    dgm, deta, k, masses = tp[0], tp[1], tp[2], tp[3]
    for j in range(k):
        _to_jacobi_block(x, xj, gm, eta, dgm, deta, j, masses)
        _to_jacobi_block(v, vj, gm, eta, dgm, deta, j, masses)


@njit
def from_jacobi_tangent(xj, vj, gm, eta, x, v, tp):
    """Inverse of :func:`to_jacobi_tangent`."""
    n = gm.shape[0]
    from_jacobi(xj[:n], vj[:n], gm, eta, x[:n], v[:n])
    dgm, deta, k, masses = tp[0], tp[1], tp[2], tp[3]
    for j in range(k):
        _from_jacobi_block(xj, x, gm, eta, dgm, deta, j, masses)
        _from_jacobi_block(vj, v, gm, eta, dgm, deta, j, masses)


@njit
def to_heliocentric_tangent(x, v, gm, eta, xh, vb, tp):
    """:func:`~orbits._kernels.coordinates.to_democratic_heliocentric` of the
    bodies and of the first ``tp[2]`` tangent vectors (``eta`` unused)."""
    n = gm.shape[0]
    to_democratic_heliocentric(x[:n], v[:n], gm, xh[:n], vb[:n])
    dgm, k, masses = tp[0], tp[2], tp[3]
    mt = 0.0
    for i in range(n):
        mt += gm[i]
    for j in range(k):
        o = n * (1 + j)
        dmt = 0.0
        if masses:
            for i in range(n):
                dmt += dgm[j, i]
        for d in range(3):
            # X = sum m x / M and V = sum m v / M are rows 0 of xh, vb
            sx = 0.0
            sv = 0.0
            for i in range(n):
                sx += gm[i] * x[o + i, d]
                sv += gm[i] * v[o + i, d]
                if masses:
                    sx += dgm[j, i] * x[i, d]
                    sv += dgm[j, i] * v[i, d]
            dX = (sx - xh[0, d] * dmt) / mt
            dV = (sv - vb[0, d] * dmt) / mt
            for i in range(1, n):
                xh[o + i, d] = x[o + i, d] - x[o, d]
                vb[o + i, d] = v[o + i, d] - dV
            xh[o, d] = dX
            vb[o, d] = dV


@njit(inline="always")
def _from_heliocentric_block(xh, vb, gm, x, v, dgm, j, masses, mt):
    # tangent block j of from_democratic_heliocentric (mt: sum gm); the
    # bodies' rows xh[:n], vb[:n] for the derivative in the masses
    n = gm.shape[0]
    o = n * (1 + j)
    dmt = 0.0
    if masses:
        for i in range(n):
            dmt += dgm[j, i]
    for d in range(3):
        # x_0 = X - sum_{i>=1} m_i Q_i / M,  v_0 = V - sum_{i>=1} m_i V_i / m_0
        sx = 0.0
        sv = 0.0
        for i in range(1, n):
            sx += gm[i] * xh[o + i, d]
            sv += gm[i] * vb[o + i, d]
        dx0 = xh[o, d] - sx / mt
        dv0 = vb[o, d] - sv / gm[0]
        if masses:
            s = 0.0
            p = 0.0
            dsx = 0.0
            dsv = 0.0
            for i in range(1, n):
                s += gm[i] * xh[i, d]
                p += gm[i] * vb[i, d]
                dsx += dgm[j, i] * xh[i, d]
                dsv += dgm[j, i] * vb[i, d]
            dx0 += s * dmt / (mt * mt) - dsx / mt
            dv0 += p * dgm[j, 0] / (gm[0] * gm[0]) - dsv / gm[0]
        for i in range(1, n):
            x[o + i, d] = xh[o + i, d] + dx0
            v[o + i, d] = vb[o + i, d] + vb[o, d]
        x[o, d] = dx0
        v[o, d] = dv0


@njit
def from_heliocentric_tangent(xh, vb, gm, eta, x, v, tp):
    """Inverse of :func:`to_heliocentric_tangent`."""
    n = gm.shape[0]
    from_democratic_heliocentric(xh[:n], vb[:n], gm, x[:n], v[:n])
    dgm, k, masses = tp[0], tp[2], tp[3]
    mt = 0.0
    for i in range(n):
        mt += gm[i]
    for j in range(k):
        _from_heliocentric_block(xh, vb, gm, x, v, dgm, j, masses, mt)


@njit
def jacobi_inertial_tangent(xj, vj, gm, eta, x, v, tp):
    """Tangent vector 0 (rows ``[n, 2n)``) of the Jacobi ``xj``, ``vj`` in
    inertial coordinates, into the same rows of ``x``, ``v`` (the bodies'
    rows are not written)."""
    _from_jacobi_block(xj, x, gm, eta, tp[0], tp[1], 0, tp[3])
    _from_jacobi_block(vj, v, gm, eta, tp[0], tp[1], 0, tp[3])


@njit
def heliocentric_inertial_tangent(xh, vb, gm, eta, x, v, tp):
    """:func:`jacobi_inertial_tangent` from democratic heliocentric ``xh``, ``vb``."""
    mt = 0.0
    for i in range(gm.shape[0]):
        mt += gm[i]
    _from_heliocentric_block(xh, vb, gm, x, v, tp[0], 0, tp[3], mt)


# -- the Kepler drift ----------------------------------------------------------------------

@njit
def drift_tangent(xj, vj, eta, h, tp, w1, w2):
    """:func:`~orbits._kernels.wisdom_holman.kepler_drift_all` of the bodies
    (``n = eta.shape[0]`` rows, bit for bit) with their first ``tp[2]``
    tangent vectors; ``tp[1]`` holds the variations of ``eta``; ``w1``,
    ``w2`` (at least ``n`` rows of 3) are scratch.

    As in ``kepler_drift_all``, the short steps' anomalies of all the bodies
    come first, then each body's state and tangent rows from its anomaly
    and the same universal functions (quicker than each body through
    :func:`~orbits._kernels.kepler_tangent.kepler_drift_tangent`, see
    benchmarks/RESULTS.md); the other steps go through that function's
    bracketed solver."""
    n = eta.shape[0]
    deta, k = tp[1], tp[2]
    straight_drift(xj, vj, 0, h)
    for j in range(k):
        straight_drift(xj, vj, n * (1 + j), h)
    short_step_anomalies(xj, vj, eta, h, n, w1, w2)
    for i in range(1, n):
        s = w1[i, 0]
        if not (s == s and advance_tangent_by_anomaly(eta[i], xj, vj, i, n, deta, k, s,
                                                      w1[i, 1], w1[i, 2], w2[i, 0],
                                                      w2[i, 1])):
            kepler_drift_tangent(eta[i], xj, vj, i, h, deta, k)


# -- interaction kicks and the jump --------------------------------------------------------

@njit(inline="always")
def _pair_block_tangent(x, acc, gm, n_active, i, l, dx, dy, dz, ir3, ir5, dgm, k, masses):
    # the pair (i, l)'s share of the tangent rows of the accelerations, with
    # d = x_i - x_l, ir3 = 1 / r^3, ir5 = 3 / r^5: the block
    # I / r^3 - 3 d d^T / r^5 applied to the difference of the tangent rows,
    # weighted by the other body's mass, plus the pull of a mass variation
    n = gm.shape[0]
    for j in range(k):
        oi = i + n * (1 + j)
        ol = l + n * (1 + j)
        ex, ey, ez = row_difference(x, oi, ol)
        p = (dx * ex + dy * ey + dz * ez) * ir5
        tx = ir3 * ex - p * dx
        ty = ir3 * ey - p * dy
        tz = ir3 * ez - p * dz
        if l < n_active:
            acc[oi, 0] -= gm[l] * tx
            acc[oi, 1] -= gm[l] * ty
            acc[oi, 2] -= gm[l] * tz
        if i < n_active:
            acc[ol, 0] += gm[i] * tx
            acc[ol, 1] += gm[i] * ty
            acc[ol, 2] += gm[i] * tz
        if masses:
            add_pulls(acc, oi, ol, dgm[j, l] * ir3, dgm[j, i] * ir3, dx, dy, dz)


@njit(inline="always")
def _pair_tangent(x, acc, gm, n_active, first, skip_first_pair, dgm, k, masses):
    # acc's tangent rows = the derivative of pair_accelerations(x, gm, n_active,
    # 0, acc, first, skip_first_pair) along x's tangent rows (and dgm)
    n = gm.shape[0]
    for j in range(k):
        o = n * (1 + j)
        zero_rows(acc, o, o + n)
    for i in range(first + 1, n):
        # a mass variation of a test particle pulls too (the derivative of the
        # map in which every body is active, which at zero mass is this one)
        for l in range(first + 1 if (skip_first_pair and i == first + 1) else first,
                       i if masses else min(i, n_active)):
            dx, dy, dz = row_difference(x, i, l)
            r2 = dx * dx + dy * dy + dz * dz
            ir3 = 1.0 / (r2 * math.sqrt(r2))
            ir5 = 3.0 * ir3 / r2
            _pair_block_tangent(x, acc, gm, n_active, i, l, dx, dy, dz, ir3, ir5, dgm, k,
                                masses)


@njit
def interaction_kick_and_tangent(xj, vj, x, acc, gm, eta, n_active, h, tp):
    """:func:`~orbits._kernels.wisdom_holman.interaction_kick` of the bodies (bit
    for bit) and its tangent for the first ``tp[2]`` tangent vectors, in one
    pass: each pair's distance and ``1 / r^3``, and each Jacobi Kepler
    term's, serve both, which is quicker than the kick and then its tangent
    (benchmarks/RESULTS.md).  ``x`` and ``acc`` (``n (1 + K)`` rows) are
    scratch: the inertial positions and accelerations and their tangent
    rows."""
    n = gm.shape[0]
    if n <= 2:
        return
    dgm, deta, k, masses = tp[0], tp[1], tp[2], tp[3]
    # the bodies' inertial positions (from_jacobi_one's arithmetic) and the
    # tangent vectors'
    _from_jacobi_block(xj, x, gm, eta, dgm, deta, -1, False)
    for j in range(k):
        _from_jacobi_block(xj, x, gm, eta, dgm, deta, j, masses)
    zero_rows(acc, 0, n * (1 + k))
    # every pair but (0, 1): pair_accelerations' arithmetic for the bodies,
    # and each pair's share of the tangent rows
    for i in range(1, n):
        xi, yi, zi = row(x, i)
        gmi = gm[i]
        axi = 0.0
        ayi = 0.0
        azi = 0.0
        for l in range(1 if i == 1 else 0, i if masses else min(i, n_active)):
            dx = xi - x[l, 0]
            dy = yi - x[l, 1]
            dz = zi - x[l, 2]
            r2 = dx * dx + dy * dy + dz * dz
            ir3 = 1.0 / (r2 * math.sqrt(r2))
            if l < n_active:
                axi, ayi, azi = pull_with_sums(acc, l, gmi, gm[l], ir3, dx, dy, dz, axi, ayi,
                                               azi, i < n_active)
            _pair_block_tangent(x, acc, gm, n_active, i, l, dx, dy, dz, ir3, 3.0 * ir3 / r2,
                                dgm, k, masses)
        acc[i, 0] += axi
        acc[i, 1] += ayi
        acc[i, 2] += azi
    # the Jacobi transform of the accelerations with the Kepler terms i >= 2
    # (jacobi_velocity_kick's arithmetic for the bodies) and its tangent; the
    # tangent's running sums in the rows o of acc
    sx, sy, sz = row(acc, 0)
    for i in range(1, n):
        ax, ay, az, w, sx, sy, sz = jacobi_step(acc, i, gm, eta, i, sx, sy, sz)
        rx, ry, rz = row(xj, i)
        ir3 = 0.0
        if i >= 2:
            r2 = rx * rx + ry * ry + rz * rz
            r3 = r2 * math.sqrt(r2)
            s = eta[i] / r3
            ir3 = 1.0 / r3
            p3 = 3.0 * ir3 / r2
            q = eta[i] * ir3
            kx = ax + s * rx
            ky = ay + s * ry
            kz = az + s * rz
        else:
            kx = ax
            ky = ay
            kz = az
            p3 = 0.0
            q = 0.0
        vj[i, 0] += h * kx
        vj[i, 1] += h * ky
        vj[i, 2] += h * kz
        for j in range(k):
            o = n * (1 + j)
            bx, by, bz = row_difference(acc, o + i, o)
            acc[o, 0] += w * bx
            acc[o, 1] += w * by
            acc[o, 2] += w * bz
            if masses:
                dw = (dgm[j, i] - w * deta[j, i]) / eta[i]
                acc[o, 0] += dw * ax
                acc[o, 1] += dw * ay
                acc[o, 2] += dw * az
            if i >= 2:
                # d(eta_i r / |r|^3)
                ex = xj[o + i, 0]
                ey = xj[o + i, 1]
                ez = xj[o + i, 2]
                pe = p3 * (rx * ex + ry * ey + rz * ez)
                bx += q * ex - eta[i] * pe * rx
                by += q * ey - eta[i] * pe * ry
                bz += q * ez - eta[i] * pe * rz
                if masses:
                    qm = deta[j, i] * ir3
                    bx += qm * rx
                    by += qm * ry
                    bz += qm * rz
            vj[o + i, 0] += h * bx
            vj[o + i, 1] += h * by
            vj[o + i, 2] += h * bz


@njit
def jump_tangent(xh, vb, gm, n_active, h, tp):
    """The tangent of :func:`~orbits._kernels.wisdom_holman.jump` (before or
    after it: the jump moves positions and reads velocities)."""
    n = gm.shape[0]
    dgm, k, masses = tp[0], tp[2], tp[3]
    for j in range(k):
        o = n * (1 + j)
        for d in range(3):
            dp = 0.0
            for i in range(1, n_active):
                dp += gm[i] * vb[o + i, d]
            shift = h * dp / gm[0]
            if masses:
                p = 0.0
                q = 0.0
                for i in range(1, n_active):
                    p += gm[i] * vb[i, d]
                for i in range(1, n):
                    q += dgm[j, i] * vb[i, d]
                shift += h * (q - p * dgm[j, 0] / gm[0]) / gm[0]
            for i in range(1, n):
                xh[o + i, d] += shift


@njit
def heliocentric_kick_tangent(xh, vb, acc, gm, n_active, h, tp):
    """The tangent of
    :func:`~orbits._kernels.wisdom_holman.heliocentric_interaction_kick`;
    ``acc``'s tangent rows are scratch."""
    n = gm.shape[0]
    k = tp[2]
    _pair_tangent(xh, acc, gm, n_active, 1, False, tp[0], k, tp[3])
    for j in range(k):
        o = n * (1 + j)
        for i in range(1, n):
            vb[o + i, 0] += h * acc[o + i, 0]
            vb[o + i, 1] += h * acc[o + i, 1]
            vb[o + i, 2] += h * acc[o + i, 2]


def _terms_jacobian(x, targs):
    # the terms' da/dx at the bodies' inertial positions x[:n] into tp's jx
    tp = targs[1]
    jx, jv = tp[4], tp[5]
    n3 = jx.shape[0]
    for p in range(n3):
        for q in range(n3):
            jx[p, q] = 0.0
            jv[p, q] = 0.0
    n = n3 // 3
    # position-only terms: the kick passes the positions as velocities too
    term_jacobian(x[:n], x[:n], 0.0, targs[0], jx, jv)


def _jacobi_term_tangent(xj, vj, x, acc, gm, eta, n_active, h, targs):
    # the tangent of _jacobi_term_kick, after it: x[:n] are the bodies'
    # inertial positions, acc[:n] the terms' accelerations (only their
    # Jacobian is needed: mass variations are refused with terms)
    tp = targs[1]
    n = gm.shape[0]
    k = tp[2]
    jacobian(x, targs)
    for j in range(k):
        o = n * (1 + j)
        _from_jacobi_block(xj, x, gm, eta, tp[0], tp[1], j, False)
        # acc's tangent block j: the terms' da/dx times x's
        tangent_product(tp[4], tp[4], x, x, o, n, acc, False)
        tx, ty, tz = row(acc, o)
        for i in range(1, n):
            bx, by, bz, _, tx, ty, tz = jacobi_step(acc, o + i, gm, eta, i, tx, ty, tz)
            vj[o + i, 0] += h * bx
            vj[o + i, 1] += h * by
            vj[o + i, 2] += h * bz
        vj[o, 0] += h * tx
        vj[o, 1] += h * ty
        vj[o, 2] += h * tz


def _heliocentric_term_tangent(xh, vb, x, acc, gm, eta, n_active, h, targs):
    # the tangent of _heliocentric_term_kick, after it (x[:n], acc[:n] as
    # there): dx_0 = dX - sum_{i>=1} m_i dQ_i / M, dx_i = dQ_i + dx_0, and the
    # kick of P_i is F_i - (m_i / M) sum F, the centre of mass's sum F / M
    tp = targs[1]
    n = gm.shape[0]
    k = tp[2]
    mt = 0.0
    for i in range(n_active):
        mt += gm[i]
    jacobian(x, targs)
    for j in range(k):
        o = n * (1 + j)
        for d in range(3):
            s = 0.0
            for i in range(1, n_active):
                s += gm[i] * xh[o + i, d]
            x0 = xh[o, d] - s / mt
            x[o, d] = x0
            for i in range(1, n):
                x[o + i, d] = xh[o + i, d] + x0
        # acc's tangent block j: the terms' da/dx times x's
        tangent_product(tp[4], tp[4], x, x, o, n, acc, False)
        for d in range(3):
            f = 0.0
            for i in range(n_active):
                f += gm[i] * acc[o + i, d]
            f /= mt
            for i in range(1, n):
                vb[o + i, d] += h * (acc[o + i, d] - f)
            vb[o, d] += h * f


def _jacobi_perturbation(xj, vj, x, acc, gm, eta, n_active, h, targs):
    # the interaction kick of the bodies with its tangent (one pass), then
    # the terms' kick followed by its tangent
    n = gm.shape[0]
    tp = targs[1]
    interaction_kick_and_tangent(xj, vj, x, acc, gm, eta, n_active, h, tp)
    if TERMS:
        if table_rows(targs[0]) > 0:
            term_kick(xj[:n], vj[:n], x[:n], acc[:n], gm, eta, n_active, h,
                      targs[0])
            term_tangent(xj, vj, x, acc, gm, eta, n_active, h, targs)


def _heliocentric_perturbation(xh, vb, x, acc, gm, eta, n_active, h, targs):
    # J(h/2) I(h) [terms] J(h/2), each operator followed by its tangent
    n = gm.shape[0]
    tp = targs[1]
    jump_tangent(xh, vb, gm, n_active, 0.5 * h, tp)
    jump(xh[:n], vb[:n], gm, n_active, 0.5 * h)
    heliocentric_interaction_kick(xh[:n], vb[:n], acc[:n], gm, n_active, h)
    heliocentric_kick_tangent(xh, vb, acc, gm, n_active, h, tp)
    if TERMS:
        if table_rows(targs[0]) > 0:
            term_kick(xh[:n], vb[:n], x[:n], acc[:n], gm, eta, n_active, h,
                      targs[0])
            term_tangent(xh, vb, x, acc, gm, eta, n_active, h, targs)
    jump_tangent(xh, vb, gm, n_active, 0.5 * h, tp)
    jump(xh[:n], vb[:n], gm, n_active, 0.5 * h)


# -- the bindings of the Wisdom-Holman templates -------------------------------------------

@njit(inline="always")
def _drift(xj, vj, eta, h, w1, w2, targs):
    drift_tangent(xj, vj, eta, h, targs[1], w1, w2)


def _conversion(a, b, gm, eta, c, d, targs):
    # a change of coordinates of the bodies and their tangent vectors, in the
    # Wisdom-Holman templates' form: (a, b) into (c, d), the tangent
    # arguments targs[1]
    conversion(a, b, gm, eta, c, d, targs[1])


_to_jacobi, _from_jacobi, _to_heliocentric, _from_heliocentric = (
    specialize(_conversion, kernel.__name__, inline=True, conversion=kernel)
    for kernel in (to_jacobi_tangent, from_jacobi_tangent, to_heliocentric_tangent,
                   from_heliocentric_tangent))


@njit(inline="always")
def _carrying(targs, k):
    # targs with the tangent arguments set to carry k vectors (a value, so
    # that the kernels called with these targs compile once for every k)
    tp = targs[1]
    return (targs[0], (tp[0], tp[1], value(k), tp[3], tp[4], tp[5], tp[6], tp[7]))


def _tangent_record(xj, vj, t, mon, n_mon, mon_t, mon_out):
    # the monitors' recorder: the bodies alone synchronised, then recorded
    mon_args, (gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, correct) = mon
    synchronize(xj, vj, gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h,
                _carrying(targs, 0), correct)
    record(x, v, t, mon_args, n_mon, mon_t, mon_out)


def _tangent_bodies(xj, vj, sync):
    # the bodies alone synchronised into x, v (for the escape check)
    gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, correct = sync
    synchronize(xj, vj, gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h,
                _carrying(targs, 0), correct)


def _chaos_step(xj, vj, t, sync):
    # after every step, where the chaos indicators are on (tp[7]): the
    # accumulators advanced with tangent vector 0 in inertial coordinates at
    # the step's internal point (before the deferred half drift and the
    # corrector: see the module notes), and the vector's internal rows scaled
    # back when it has grown large
    gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, _ = sync
    tp = targs[1]
    if not tp[7]:
        return False
    n = gm.shape[0]
    inertial_tangent(xj, vj, gm, eta, xs, vs, tp)
    box = tp[6]
    if chaos_update(xs[n:2 * n], vs[n:2 * n], t, box):
        renormalise(xj, vj, n, box)
    return False


def _chaos_note(sync, mon_out, row):
    # the chaos indicators into the monitor row just recorded, by the
    # variational force's own note (its fargs[1][4] is the box, fargs[1][5][2]
    # the chaos flag)
    tp = sync.targs[1]
    note(((), (0, 0, 0, 0, tp[6], (0.0, 0.0, tp[7], tp[3]))), mon_out, row)


_INERTIAL_TANGENT = {"jacobi": jacobi_inertial_tangent,
                     "democratic-heliocentric": heliocentric_inertial_tangent}

_CONVERSIONS = {"jacobi": (_to_jacobi, _from_jacobi, _jacobi_perturbation,
                           _jacobi_term_kick, _jacobi_term_tangent),
                "democratic-heliocentric": (_to_heliocentric, _from_heliocentric,
                                            _heliocentric_perturbation,
                                            _heliocentric_term_kick,
                                            _heliocentric_term_tangent)}


def _kernels(coordinates, terms, key, cache):
    """The bound tangent kernels: (to internal, perturbation, corrector,
    synchronize)."""
    to_internal, from_internal, pert, term_kick, term_tangent = _CONVERSIONS[coordinates]
    nrt = _runtime(terms, cache)
    # the tangent kernels are calls, not inlined: a step's tangent costs far
    # more than a call, and inlining them all into every loop and corrector
    # would take minutes to compile
    if terms is None:
        perturbation = specialize(pert, key, cache=cache, nrt=nrt, TERMS=False,
                                  term_kick=None, term_tangent=None)
    else:
        kick = specialize(term_kick, key, cache=cache, inline=True, nrt=nrt,
                          extra=terms.accel)
        jac = specialize(_terms_jacobian, key, cache=cache, inline=True, nrt=nrt,
                         term_jacobian=terms.jacobian)
        tangent = specialize(term_tangent, key, cache=cache, nrt=nrt, jacobian=jac)
        perturbation = specialize(pert, key, cache=cache, nrt=nrt, TERMS=True,
                                  term_kick=kick, term_tangent=tangent)
    # the corrector and the synchronisation call the drift (see wisdom_holman._kernels)
    # compiled in: the tangent loop's corrector carries the tangent vectors,
    # and the loop ignores the pointer of the loops without variations
    corrector = specialize(_correct_compiled, f"corrector_{key}", cache=cache, inline=True,
                           nrt=nrt, corrector=specialize(
                               _apply_corrector, f"corrector_{key}", cache=cache, nrt=nrt,
                               drift=called(_drift, nrt), perturbation=perturbation))
    sync = specialize(_synchronize, f"synchronize_{key}", cache=cache, nrt=nrt,
                      drift=called(_drift, nrt), from_internal=from_internal,
                      corrector_kernel=corrector)
    return to_internal, perturbation, corrector, sync


def _runtime(terms, cache):
    # numba's runtime (reference counts, allocation) for a loop that a user's
    # function joins (not cached); the terms' kernels that allocate their
    # small work arrays (the Jacobians) run behind the table's C callables
    return not cache


def _key(coordinates, terms):
    # named by the terms, not by the force: the tangent loop kicks with its
    # own pairs (_pair_tangent) and never calls gravity's pair kernel, which
    # changes at gravity.LANES_FROM massive bodies, so that one loop serves
    # systems on both sides of it
    return f"tangent_{coordinates}_{'gravity' if terms is None else terms.key}"


def tangent_loop_escape(coordinates, terms, force, stopping, sync, conditions):
    """The ``escape`` argument of :func:`wh_tangent_loop`'s loop: the escape
    check on the bodies (:func:`~orbits._kernels.wisdom_holman.escape_pointer`)
    for a run with stopping ``conditions``, or without; ``stopping`` the
    stopping record and ``sync`` a
    :class:`~orbits._kernels.wisdom_holman.Sync` of the values the loop
    hands its synchronisation."""
    key = _key(coordinates, terms)
    cache = force.cache
    bodies = None
    if conditions:
        bodies = specialize(_tangent_bodies, key, cache=cache, inline=True,
                            nrt=_runtime(terms, cache),
                            synchronize=_kernels(coordinates, terms, key, cache)[3])
    return escape_pointer(key, bodies, stopping, sync, conditions, cache)


def tangent_synchronizer(coordinates, terms, force):
    """The compiled synchronisation (bodies and the tangent vectors that
    ``targs[1][2]`` counts) for a force with variations, ``force``, whose
    position-only ``terms`` (or None) join the perturbation step;
    arguments as :func:`orbits._kernels.wisdom_holman.synchronizer`'s, with
    ``targs = (terms' args, tp)``."""
    return _kernels(coordinates, terms, _key(coordinates, terms), force.cache)[3]


def wh_tangent_loop(coordinates, terms, force):
    """The Wisdom-Holman loop of :func:`orbits._kernels.wisdom_holman.wh_loop`
    compiled with the tangent of every operator, for a force with variations
    ``force`` (its ``inner`` the gravity, with ``terms``); with the chaos
    indicators after every step where they are on (data of the arguments), and with the escape check
    of :func:`~orbits._kernels.wisdom_holman.escape_kernels` on the bodies
    (its ``escape`` argument :func:`tangent_loop_escape`'s).
    Called with ``targs = (terms' args, tp)`` (see the module notes), ``gm``
    and ``eta`` of the bodies alone (``n`` entries), the state arrays of
    ``n (1 + K)`` rows and a stopping record
    (:func:`~orbits._kernels.stopping.stop_record`)."""
    key = _key(coordinates, terms)
    cache = force.cache
    nrt = _runtime(terms, cache)
    to_internal, perturbation, corrector, sync = _kernels(coordinates, terms, key, cache)
    # a run without terms takes the loop with terms, given an empty table
    # (its monitors carry it, as a run's with terms do)
    record = force.recorder
    if terms is not None and force.inner.terms is None:
        record = varied_recorder(terms_recorder(terms), cache=cache)
    recorder = specialize(_tangent_record, key, cache=cache, nrt=nrt, synchronize=sync,
                          record=record)
    step = specialize(_chaos_step, key, cache=cache, inline=True, nrt=nrt,
                      inertial_tangent=_INERTIAL_TANGENT[coordinates])
    # the note of the chaos indicators alone: wh takes conservative terms only,
    # which do no work, and _chaos_note hands the note no force arguments (the
    # note of gravity with terms would read their work box)
    gravity = force.inner if force.inner.terms is None else force.inner.base
    note = specialize(_chaos_note, key, cache=cache, inline=True, nrt=nrt,
                      note=variational_work_kernels(force, work_kernels(gravity))["work_note"])
    stop_args, stop = escape_kernels(key, cache=cache, nrt=nrt)
    return specialize(_wh_loop, f"wh_{key}", nrt=nrt, cache=cache,
                      to_internal=called(to_internal, nrt),
                      drift=_drift, owed_drift=called(_drift, nrt), perturbation=perturbation,
                      corrector_kernel=corrector,
                      step_end=epilogue(recorder, f"wh_{key}", cache=cache,
                                        work_note=note, tangent_step=step, stop=stop),
                      stop_args=stop_args)

"""The compiled loop of the Wisdom-Holman map and its relatives (SABA).

The Hamiltonian of N bodies in Jacobi coordinates is split as
``H = H_Kepler + H_interaction`` (Wisdom & Holman 1991)::

    H_Kepler      = sum_{i>=1} [ m'_i |v'_i|^2 / 2 - G m'_i eta_i / r'_i ]
    H_interaction = sum_{i>=2} G m'_i eta_i / r'_i - sum_{j<i} G m_i m_j / r_ij

with reduced masses ``m'_i = m_i eta_{i-1} / eta_i`` and interior masses
``eta_i = m_0 + ... + m_i``.  ``H_Kepler`` moves every Jacobi coordinate on
its own two-body orbit about ``G eta_i`` (:func:`kepler_drift`); the centre of
mass drifts in a straight line.  ``H_interaction`` depends on positions only
and changes the Jacobi velocities by (:func:`interaction_kick`)::

    dv'_i/dt = (J a)_i + G eta_i x'_i / r'_i^3     (i >= 2)
    dv'_1/dt = (J a)_1

where ``a`` are the inertial accelerations of all pairs except (0, 1) and
``J`` the Jacobi transformation (:mod:`orbits._kernels.coordinates`).  The pair
(0, 1) and the Kepler term of body 1 cancel exactly and are left out, so a
two-body problem is integrated exactly up to the Kepler solver.

Democratic heliocentric coordinates (Duncan, Levison & Lee 1998 [6]; "canonical
heliocentric" in Wisdom 2006 [5]): heliocentric positions ``Q_i`` and their
conjugate barycentric momenta ``P_i = m_i V_i`` (:mod:`orbits._kernels.coordinates`)
split the Hamiltonian three ways, besides the centre of mass, which drifts::

    H_Kepler      = sum_{i>=1} [ |P_i|^2 / (2 m_i) - G m_0 m_i / |Q_i| ]
    H_interaction = - sum_{1<=j<i} G m_i m_j / |Q_i - Q_j|
    H_jump        = |sum_{i>=1} P_i|^2 / (2 m_0)

``H_Kepler`` moves every body on its orbit about ``G m_0`` (the same
:func:`kepler_drift_all`, with ``mu_i = G m_0``); ``H_interaction`` kicks the
velocities by the planets' mutual pull only (the star's pull is all in the
Kepler part); ``H_jump`` shifts every heliocentric position by
``h sum_i m_i V_i / m_0`` (:func:`jump`).  Test particles feel the planets and
jump with them but move nothing.  The interaction and the jump commute:
the jump moves all ``Q_i`` by one vector and leaves the differences that
``H_interaction`` depends on alone, and the kicks, pairwise equal and
opposite, leave ``sum P_i`` alone.  So ``J(h/2) I(h) J(h/2)`` is the exact
flow of ``H_interaction + H_jump`` (:func:`jump_interaction_kick`), and the
Wisdom-Holman map in these coordinates is the same table as in Jacobi ones,
``K(h/2) [J(h/2) I(h) J(h/2)] K(h/2)``, the order REBOUND's WHFast uses in
this mode (the tests compare the two; Hernandez & Dehnen 2017 [7] analyse
the split's errors).  The perturbation ``H_interaction + H_jump`` is of order ``epsilon``
as in Jacobi coordinates, so the map's error is ``O(epsilon h^2)`` again
and the correctors below apply unchanged (they need only the exact flows
of the two parts).  What differs: every body, test particles included, is
treated alike whatever its order, but a lone massive companion is no
longer integrated exactly (its jump is part of the perturbation), and on
the outer solar system the position errors are a few times larger.

A step is a table of Kepler drifts and interaction kicks, data of the
loop's :class:`System` record (``kinds``, ``coefs``), so that one compiled
loop serves every table (wh, the SABA family) in a coordinate system.  A
table that ends with a drift defers it: the next step's first drift absorbs
it (the leapfrog's two half drifts become one), and :func:`synchronize` applies
it to a copy when the inertial state is wanted.  The internal state and the
deferred drift live in the workspace between calls.

Symplectic correctors (Wisdom, Holman & Touma 1996 [4]; Wisdom 2006 [5]).  The
map ``K = K(h/2) I(h) K(h/2)`` is, to first order in the mass ratio, conjugate
to the true flow ``T``: ``T = C K C^-1`` with a near-identity ``C`` built
from the stages ::

    Z(a, b) = K(a) I(-b) K(-2a) I(b) K(a)      (applied left to right)

(``I(b) = exp(b L_B)`` transported along the Kepler flow, whose first-order
generator is ``2 b sinh(a ad_A) H_int``).  ``C`` applies ``Z(a_m, b_m)`` first
and ``Z(a_1, b_1)`` last; ``C^-1`` applies ``Z(-a_1, b_1)`` first, the exact
inverse stage by stage (``I`` is the perturbation step of the coordinate
system, ``J(h/2) I(h) J(h/2)`` in democratic heliocentric ones).  The loop
starts from ``C^-1`` of the initial state (:func:`apply_corrector` with
``inverse``) and the output is ``C`` of the mapping state, so the error of
the output is that of ``T`` up to ``O(epsilon h^(n+1) + epsilon^2 h^2)``.
``C`` is applied only to the copy that :func:`synchronize` makes; the
mapping state goes on untouched.  The corrector of ``K(h)`` also conjugates
``K(-h) = K(h)^-1``, so it is built from ``|h|``: a run backwards keeps the
mapping state, and reversing a corrected run returns to its start up to
rounding.

References
----------
.. [1] Wisdom, J. & Holman, M. 1991, "Symplectic maps for the N-body
   problem", AJ 102, 1528.
.. [2] Rein, H. & Tamayo, D. 2015, "WHFAST: a fast and unbiased implementation
   of a symplectic Wisdom-Holman integrator for long-term gravitational
   simulations", MNRAS 452, 376 (lazy synchronisation).
.. [3] Laskar, J. & Robutel, P. 2001, Celest. Mech. Dyn. Astron. 80, 39.
.. [4] Wisdom, J., Holman, M. & Touma, J. 1996, "Symplectic correctors",
   Fields Institute Communications 10, 217.
.. [5] Wisdom, J. 2006, "Symplectic correctors for canonical heliocentric
   coordinates", AJ 131, 2294.
.. [6] Duncan, M. J., Levison, H. F. & Lee, M. H. 1998, "A multiple time step
   symplectic algorithm for integrating close encounters", AJ 116, 2067.
.. [7] Hernandez, D. M. & Dehnen, W. 2017, "A study of symplectic
   integrators for planetary system problems: error analysis and
   comparisons", MNRAS 468, 2614.
"""

import functools
import math
from typing import NamedTuple

import numba
import numpy as np
from numba.core import types as nbtypes

from ._jit import called, idle_pointer, njit, pointer, slots, specialize
from .coordinates import (from_democratic_heliocentric, from_jacobi, from_jacobi_one,
                          jacobi_step, to_democratic_heliocentric, to_jacobi,
                          weighted_sum)
from .gravity import pair_accelerations
from .kepler import (advance_by_anomaly, kepler_drift_bracketed, short_step_anomaly,
                     straight_drift)
from .status import Status
from .stepping import DRIFT, GO, _record, epilogue, first_record
from .stopping import no_stop
from .terms import table_rows
from .wh_lanes import (MEMO, PENDING, RETRY, kepler_drift_lanes, resident_drift_twice,
                       resident_finite, resident_jump_kick, resident_kick, resident_load,
                       resident_store)
from .wh_lanes import resident_drift as resident_drift_rows

# the names the templates below are written against, bound by specialize
(HELIOCENTRIC, convert, drift, extra, from_internal, owed_drift,
 perturbation, step, step_end, synchronize_bodies, term_kick, to_internal, sync_kernel,
 corrector_kernel, record, corrector) = slots(
    "HELIOCENTRIC", "convert", "drift", "extra",
    "from_internal", "owed_drift", "perturbation", "step", "step_end", "synchronize_bodies",
    "term_kick", "to_internal", "sync_kernel", "corrector_kernel", "record", "corrector")

__all__ = ["wh_loop", "synchronizer", "interaction_kick", "jacobi_velocity_kick", "jump",
           "heliocentric_interaction_kick", "jump_interaction_kick", "kepler_drift_all",
           "synchronize", "apply_corrector", "may_escape", "escape_kernels", "escape_pointer",
           "loop_escape",
           "COORDINATE_SYSTEMS", "ESCAPE_MARGIN"]


@njit(inline="always")
def short_step_anomalies(xj, vj, mu, h, n, w1, w2):
    """The first pass of :func:`kepler_drift_all`: the short-step universal
    anomaly of rows ``1 .. n - 1`` (:func:`~orbits._kernels.kepler.short_step_anomaly`,
    NaN where the step is not short) with what the second pass takes with
    it, ``(s, r0, 1 / r0)`` into ``w1[i]`` and ``(beta, zeta)`` into ``w2[i]``."""
    for i in range(1, n):
        s, r0, ir0, beta, zeta = short_step_anomaly(
            mu[i], xj[i, 0], xj[i, 1], xj[i, 2], vj[i, 0], vj[i, 1], vj[i, 2], h)
        w1[i, 0] = s
        w1[i, 1] = r0
        w1[i, 2] = ir0
        w2[i, 0] = beta
        w2[i, 1] = zeta


@njit(inline="always")
def kepler_drift_all(xj, vj, mu, h, w1, w2):
    """Drift every row by ``h``: row i >= 1 on its orbit about ``mu[i]``, the
    centre of mass (row 0) in a straight line.  ``w1``, ``w2`` (shape (N, 3))
    are scratch.

    The drifts are independent, and each is a long chain of dependent
    operations, so they are done in two passes over the bodies (the
    universal anomaly of every short step, then every state from its
    anomaly) that the processor can overlap, rather than one body after
    the other (benchmarks/RESULTS.md).  Steps that are
    not short take :func:`~orbits._kernels.kepler.kepler_drift`'s bracketed
    solver directly: :func:`~orbits._kernels.kepler.kepler_drift` would
    try the same short step again on the same numbers, fail again, and
    end there, so the result is the same bit for bit, and the loop does not
    compile the short step a second time.
    """
    straight_drift(xj, vj, 0, h)
    n = xj.shape[0]
    short_step_anomalies(xj, vj, mu, h, n, w1, w2)
    for i in range(1, n):
        s = w1[i, 0]
        if not (s == s and advance_by_anomaly(mu[i], xj, vj, i, s, w1[i, 1], w1[i, 2],
                                              w2[i, 0], w2[i, 1])):
            kepler_drift_bracketed(mu[i], xj, vj, i, h)


@njit(inline="always")
def interaction_kick(xj, vj, x, acc, gm, eta, n_active, h):
    """Kick the Jacobi velocities by ``h`` times the interaction accelerations.

    ``x`` and ``acc`` (shape (N, 3)) are scratch: the inertial positions and
    accelerations.  See the module notes for the formula.
    """
    n = xj.shape[0]
    if n <= 2:
        # only the pair (0, 1), which the Kepler drift holds entirely: the
        # kick is zero (and a third of a two-body step)
        return
    from_jacobi_one(xj, gm, eta, x)
    # every pair but (0, 1), whose pull the Kepler drift of body 1 holds
    pair_accelerations(x, gm, n_active, 0.0, acc, 0, True)
    # to Jacobi components, with the Kepler terms i >= 2; row 0 (the centre
    # of mass) feels no internal force
    jacobi_velocity_kick(xj, vj, acc, gm, eta, h, True)


@njit(inline="always")
def jacobi_velocity_kick(xj, vj, acc, gm, eta, h, kepler):
    """Kick the Jacobi velocities ``vj[1:]`` by ``h`` times the Jacobi transform of
    the inertial accelerations ``acc``; with ``kepler`` (a constant), rows
    ``i >= 2`` also get ``G eta_i x'_i / r'_i^3``, the Kepler term that the
    interaction Hamiltonian holds.  Returns the centre of mass's acceleration,
    ``sum m a / M``, which the caller applies to row 0 or not."""
    n = xj.shape[0]
    sx = acc[0, 0]
    sy = acc[0, 1]
    sz = acc[0, 2]
    for i in range(1, n):
        ax, ay, az, _, sx, sy, sz = jacobi_step(acc, i, gm, eta, i, sx, sy, sz)
        if kepler and i >= 2:
            rx = xj[i, 0]
            ry = xj[i, 1]
            rz = xj[i, 2]
            r2 = rx * rx + ry * ry + rz * rz
            s = eta[i] / (r2 * math.sqrt(r2))
            ax += s * rx
            ay += s * ry
            az += s * rz
        vj[i, 0] += h * ax
        vj[i, 1] += h * ay
        vj[i, 2] += h * az
    return sx, sy, sz


@njit(inline="always")
def jump(xh, vb, gm, n_active, h):
    """Shift every heliocentric position ``xh[1:]`` by ``h`` times
    ``sum_i m_i V_i / m_0`` (the flow of ``H_jump``); ``vb`` barycentric."""
    px, py, pz = weighted_sum(vb, gm, 1, n_active)
    s = h / gm[0]
    px *= s
    py *= s
    pz *= s
    for i in range(1, xh.shape[0]):
        xh[i, 0] += px
        xh[i, 1] += py
        xh[i, 2] += pz


@njit(inline="always")
def heliocentric_interaction_kick(xh, vb, acc, gm, n_active, h):
    """Kick the barycentric velocities ``vb[1:]`` by ``h`` times the pull of
    the other bodies except the central one (the flow of ``H_interaction``);
    ``acc`` (shape (N, 3)) is scratch."""
    # the planets' mutual pulls: every pair without the central body
    pair_accelerations(xh, gm, n_active, 0.0, acc, 1, False)
    _kick_all_but_first(vb, acc, h)


@njit(inline="always")
def _kick_all_but_first(v, acc, h):
    for i in range(1, v.shape[0]):
        v[i, 0] += h * acc[i, 0]
        v[i, 1] += h * acc[i, 1]
        v[i, 2] += h * acc[i, 2]


@njit(inline="always")
def jump_interaction_kick(xh, vb, x, acc, gm, mu, n_active, h):
    """The perturbation step in democratic heliocentric coordinates,
    ``J(h/2) I(h) J(h/2)``: the exact flow of ``H_interaction + H_jump`` for
    ``h``, as the two commute (see the module notes).  Arguments as
    :func:`interaction_kick`; ``x`` and ``mu`` are not used."""
    jump(xh, vb, gm, n_active, 0.5 * h)
    heliocentric_interaction_kick(xh, vb, acc, gm, n_active, h)
    jump(xh, vb, gm, n_active, 0.5 * h)


@njit(inline="always")
def _to_heliocentric(x, v, gm, mu, xh, vb):
    to_democratic_heliocentric(x, v, gm, xh, vb)


@njit(inline="always")
def _from_heliocentric(xh, vb, gm, mu, x, v):
    from_democratic_heliocentric(xh, vb, gm, x, v)


#: ``_apply_corrector``'s ``inverse``: C^-1, or C
INVERSE = 1.0
FORWARD = 0.0


def _apply_corrector(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs):
    """Apply the symplectic corrector ``C`` (or ``C^-1`` if ``inverse`` is
    not 0) for the step ``h`` to the internal state ``xj``, ``vj`` in place.

    ``corr`` (shape (m, 2)) holds the stages' ``(a_i, b_i)`` in units of the
    step; ``x`` and ``acc`` (shape (N, 3)) are scratch.  See the module notes.
    ``inverse`` is a float (:data:`INVERSE` or :data:`FORWARD`): a constant
    True or False would be typed as a literal, and numba would compile the
    corrector once for each, a large part of every loop's first
    compilation.
    """
    m = corr.shape[0]
    for k in range(m):
        if inverse != 0.0:
            a = -corr[k, 0] * h
            b = corr[k, 1] * h
        else:
            a = corr[m - 1 - k, 0] * h
            b = corr[m - 1 - k, 1] * h
        drift(xj, vj, eta, a, x, acc, targs)
        perturbation(xj, vj, x, acc, gm, eta, n_active, -b, targs)
        drift(xj, vj, eta, -2.0 * a, x, acc, targs)
        perturbation(xj, vj, x, acc, gm, eta, n_active, b, targs)
        drift(xj, vj, eta, a, x, acc, targs)


def _synchronize(xj, vj, gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, correct):
    """Inertial ``x``, ``v`` at the current time: the internal state with the
    deferred drift ``owed`` and then the corrector ``corr`` for the step ``h``
    (none if it has no rows) applied to a copy (``xs``, ``vs``); ``acc`` is
    scratch.  ``correct``: the loop's corrector pointer
    (:func:`corrector_pointer`), which the loops' synchronisation calls
    (:func:`_correct_through`); others ignore it."""
    for i in range(xj.shape[0]):
        for d in range(3):
            xs[i, d] = xj[i, d]
            vs[i, d] = vj[i, d]
    if owed != 0.0:
        drift(xs, vs, eta, owed, x, acc, targs)
    if corr.shape[0] > 0:
        corrector_kernel(xs, vs, x, acc, gm, eta, n_active, corr, h, FORWARD, targs, correct)
    from_internal(xs, vs, gm, eta, x, v, targs)


@njit(inline="always")
def _correct_through(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs, correct):
    # the corrector of the loops without variations: through the loop's
    # pointer, compiled only for a run with a corrector (corrector_pointer)
    correct(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs)


def _corrector_call(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs):
    # the body of the corrector's pointer (corrector_pointer): a call of the
    # compiled corrector, so that compiling it is announced and timed (numba
    # broadcasts its compile events for compiled functions, not for the C
    # callables that call them)
    corrector(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs)


def _correct_compiled(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs, correct):
    # the corrector compiled into its caller (the tangent loop's, the batch's
    # synchronisation), which ignores the pointer
    corrector(xj, vj, x, acc, gm, eta, n_active, corr, h, inverse, targs)


# An output of the lanes' loop (no added terms, four bodies or more) is noted
# at the end of its step and made at the start of the next one: the copy's
# owed drift beside that step's first drift, in the same passes over the
# lanes (wh_lanes.resident_drift_twice), so that the processor overlaps
# their chains of dependent operations; on its own, the output's drift would
# add its whole latency to the step (benchmarks/RESULTS.md).  That drift is
# inlined into the loop: compiled as a function of its own, its passes took
# their scalar loops at the outer solar system's few columns (LLVM's vector
# loops there start at 12 or 16), which cost 0.2 us more an output
# (benchmarks/RESULTS.md).  The loop makes a noted output before it returns,
# whatever the reason.  The results are those of the immediate
# synchronisation, bit for bit.  Other loops bind none of this: the defaults
# below do nothing.

@njit(inline="always")
def _no_output_pending(targs):
    return False


@njit(inline="always")
def _no_output_drift(xj, vj, eta, h, xs, vs, owed, x, acc, targs):
    pass


@njit(inline="always")
def _no_make_output(xa, va, owed, mon, mon_t, mon_out, gm, eta, xs, vs, x, v, acc, n_active,
                corr, h, targs, correct):
    pass


# The lanes' loop keeps its state in the lanes between outputs (see
# orbits._kernels.wh_lanes, "the state kept in the lanes"): RESIDENT binds
# its drift and perturbation step on the lanes' rows, which lanes_in loads
# when the loop starts and lanes_out writes back before the loop returns;
# lanes_check makes the epilogue's finite check on the lanes (the epilogue's
# own check is then off) and writes the state back where it is not finite.
# An output drifts its copy from the lanes (_resident_output_drift).  The
# defaults below do nothing.


@njit(inline="always")
def _no_resident_drift(xj, vj, eta, h, targs):
    pass


@njit(inline="always")
def _no_resident_perturbation(xj, vj, gm, eta, n_active, h, targs):
    pass


@njit(inline="always")
def _no_lanes_in(xj, vj, gm, eta, targs):
    pass


@njit(inline="always")
def _no_lanes_out(xj, vj, targs):
    pass


@njit(inline="always")
def _no_lanes_check(xj, vj, k, nsteps, until_check, check_every, until_record, targs):
    return True, until_check


# the lanes' slots, which other loops leave at these defaults
(RESIDENT, output_pending, output_drift, make_output, resident_drift, resident_perturbation,
 lanes_in, lanes_out, lanes_check) = slots(
    RESIDENT=False, output_pending=_no_output_pending, output_drift=_no_output_drift,
    make_output=_no_make_output, resident_drift=_no_resident_drift,
    resident_perturbation=_no_resident_perturbation, lanes_in=_no_lanes_in,
    lanes_out=_no_lanes_out, lanes_check=_no_lanes_check)


def _resident_drift(xj, vj, eta, h, targs):
    # the drift of the state kept in the lanes.  Unlike _lanes_drift it
    # always tries the lanes first: leaving drifts to kepler_drift_all would
    # write the state back and load it again around them, which costs more
    # than it saves (benchmarks/RESULTS.md)
    resident_drift_rows(xj, vj, eta, h, targs[0])


def _resident_in(xj, vj, gm, eta, targs):
    resident_load(xj, vj, gm, eta, targs[0])


def _resident_out(xj, vj, targs):
    resident_store(targs[0], xj, vj)


def _resident_check(xj, vj, k, nsteps, until_check, check_every, until_record, targs):
    # the epilogue's finite check (every check_every steps and after the
    # last) on the lanes; the state back in xj, vj where it is not finite
    # (the loop returns it).  An output the epilogue records is only noted
    # (_lanes_note), and its drift made from the lanes (_resident_output_drift).
    S = targs[0]
    until_check -= 1
    ok = True
    if until_check == 0 or k + 1 == nsteps:
        until_check = check_every
        ok = resident_finite(xj, vj, S)
    if not ok:
        resident_store(S, xj, vj)
    return ok, until_check


def _resident_jacobi(xj, vj, gm, eta, n_active, h, targs):
    resident_kick(xj, vj, gm, n_active, h, targs[0])


def _resident_heliocentric(xj, vj, gm, eta, n_active, h, targs):
    resident_jump_kick(xj, vj, gm, n_active, h, targs[0])


def _lanes_pending(targs):
    return targs[0][PENDING, 0] != 0.0


def _resident_output_drift(xj, vj, eta, h, xs, vs, owed, x, acc, targs):
    # the step's first drift h of the state kept in the lanes and the noted
    # output's owed drift of a copy into xs, vs (both from the same state;
    # with nothing owed the copy is the state), as the lanes' drift and
    # _synchronize would make them one after the other, in the same passes
    # over the lanes (wh_lanes.resident_drift_twice)
    S = targs[0]
    S[PENDING, 0] = 0.0
    resident_drift_twice(xj, vj, eta, h, xs, vs, owed, S)


def _lanes_output(xa, va, owed, mon, mon_t, mon_out, gm, eta, xs, vs, x, v, acc, n_active,
                  corr, h, targs, correct):
    # the noted output, by the usual synchronisation of the state xa, va that
    # still owes the drift owed: the loop's state when it returns, or the copy
    # that output_drift already drifted (owed 0; xa, va are then xs, vs),
    # which without a corrector is the state at the time: the
    # synchronisation's conversion then, without its copy and its call
    S = targs[0]
    S[PENDING, 0] = 0.0
    if owed == 0.0 and corr.shape[0] == 0:
        from_internal(xa, va, gm, eta, x, v, targs)
    else:
        sync_kernel(xa, va, gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h,
                    targs, correct)
    record(x, v, S[PENDING, 2], mon, int(S[PENDING, 1]), mon_t, mon_out)


def _lanes_note(xj, vj, t, mon, n_mon, mon_t, mon_out):
    # the lanes' loop's recorder: the output is noted, to be made beside the
    # next step's first drift (or when the loop returns); mon is a Recording
    S = mon.sync.targs[0]
    S[PENDING, 0] = 1.0
    S[PENDING, 1] = n_mon
    S[PENDING, 2] = t


class System(NamedTuple):
    """What the map needs of the bodies and of the method: ``G`` times each
    mass, ``eta`` (``G`` times the mass each row's Kepler drift orbits), the
    number of massive bodies, the corrector's coefficients (no rows without
    corrector), and the step's table: each operator's kind (:data:`DRIFT` or
    :data:`KICK`) and its fraction of the step."""
    gm: np.ndarray
    eta: np.ndarray
    n_active: int
    corrector: np.ndarray
    kinds: np.ndarray
    coefs: np.ndarray


class Work(NamedTuple):
    """The Wisdom-Holman loop's workspace: the internal (Jacobi or democratic
    heliocentric) state ``xj``, ``vj``; scratch ``acc``, ``xs``, ``vs``;
    ``state[0]`` (``xj``, ``vj`` hold the current state, else the loop
    starts from ``x``, ``v``); ``owed[0]``, the drift the internal state
    still owes, deferred from the last step's closing drift; ``cdt[0]``,
    the step the mapping state's corrector belongs to."""
    xj: np.ndarray
    vj: np.ndarray
    acc: np.ndarray
    xs: np.ndarray
    vs: np.ndarray
    state: np.ndarray
    owed: np.ndarray
    cdt: np.ndarray


class Sync(NamedTuple):
    """What the synchronisation takes besides the internal state: the
    system, the drift owed, scratch, the inertial state to write, the
    corrector and its step, the loop's ``targs`` and its corrector's
    pointer (:func:`corrector_pointer`; 0 where the loop ignores it)."""
    gm: np.ndarray
    eta: np.ndarray
    owed: float
    xs: np.ndarray
    vs: np.ndarray
    x: np.ndarray
    v: np.ndarray
    acc: np.ndarray
    n_active: int
    corr: np.ndarray
    h: float
    targs: tuple
    correct: object


class Recording(NamedTuple):
    """What the loop's recorder takes for its monitors: the monitors'
    settings and the synchronisation's arguments."""
    monitors: tuple
    sync: Sync


def _wh_loop(x, v, t, dt, nsteps, system, work, outputs, checks, check, escape, correct,
             targs):
    # system: a System record, work: a Work record; checks, check: the Checks
    # record (orbits._kernels.records) and the stopping conditions' pointer,
    # whose escape conditions the loops without lanes check through the
    # escape pointer (see escape_kernels; the lanes' loop takes 0 and reads
    # neither); correct: the corrector's pointer (corrector_pointer), which
    # the loops without variations call where the system has a corrector
    gm, eta, n_active, corr, kinds, coefs = system
    xj, vj, acc, xs, vs, state, owed_box, cdt = work
    mon, step0, mon_t, mon_out = outputs
    check_every, sargs = checks
    stopping = (sargs, check)
    every = mon[0]
    n_mon = 0
    corrected = corr.shape[0] > 0
    if state[0] == 0:
        to_internal(x, v, gm, eta, xj, vj, targs)
        state[0] = 1
        owed_box[0] = 0.0
        if corrected:
            corrector_kernel(xj, vj, xs, acc, gm, eta, n_active, corr, abs(dt), INVERSE, targs,
                             correct)
            cdt[0] = abs(dt)
    elif corrected and cdt[0] != abs(dt):
        # a new step size (a shorter last step): through the true state to the
        # mapping state of the new step's corrector
        if owed_box[0] != 0.0:
            owed_drift(xj, vj, eta, owed_box[0], xs, vs, targs)
            owed_box[0] = 0.0
        corrector_kernel(xj, vj, xs, acc, gm, eta, n_active, corr, cdt[0], FORWARD, targs,
                         correct)
        corrector_kernel(xj, vj, xs, acc, gm, eta, n_active, corr, abs(dt), INVERSE, targs,
                         correct)
        cdt[0] = abs(dt)
    owed = owed_box[0]
    lanes_in(xj, vj, gm, eta, targs)
    n_ops = kinds.shape[0]
    defer = kinds[n_ops - 1] == DRIFT
    until_check = check_every
    until_record = first_record(every, step0, mon_t)
    for k in range(nsteps):
        for op in range(n_ops):
            h = coefs[op] * dt
            if kinds[op] == DRIFT:
                if op == 0:
                    if output_pending(targs):
                        # the output noted at the end of the last step
                        # (the lanes' loop): its drift beside this one
                        output_drift(xj, vj, eta, h + owed, xs, vs, owed, x, acc, targs)
                        make_output(xs, vs, 0.0, mon, mon_t, mon_out, gm, eta, xs, vs, x, v,
                                    acc, n_active, corr, cdt[0], targs, correct)
                        owed = 0.0
                        continue
                    h += owed
                    owed = 0.0
                if op == n_ops - 1 and defer:
                    owed = h
                elif RESIDENT:
                    resident_drift(xj, vj, eta, h, targs)
                else:
                    drift(xj, vj, eta, h, xs, vs, targs)
            elif RESIDENT:
                resident_perturbation(xj, vj, gm, eta, n_active, h, targs)
            else:
                perturbation(xj, vj, xs, acc, gm, eta, n_active, h, targs)
        # the shared epilogue checks the internal state; its recorder
        # synchronises first, so the monitors see the inertial state at the
        # time; the synchronisation's arguments are also its fargs, for the
        # chaos indicators of a run with variations (orbits._kernels.wh_tangent)
        sync = Sync(gm, eta, owed, xs, vs, x, v, acc, n_active, corr, cdt[0], targs, correct)
        finite, until_check = lanes_check(xj, vj, k, nsteps, until_check, check_every,
                                          until_record, targs)
        if finite:
            status, done, until_check, until_record, n_mon = step_end(
                xj, vj, t + (k + 1) * dt, k, nsteps, not RESIDENT, until_check, check_every,
                until_record, every, Recording(mon, sync), n_mon, mon_t, mon_out,
                stop_args(stopping, sync, escape), sync)
        else:
            status, done = Status.NON_FINITE, k
        if status != GO:
            lanes_out(xj, vj, targs)
            # an output still noted is made before the loop returns
            if output_pending(targs):
                make_output(xj, vj, owed, mon, mon_t, mon_out, gm, eta, xs, vs, x, v, acc,
                            n_active, corr, cdt[0], targs, correct)
            owed_box[0] = owed
            return status, done, n_mon
    lanes_out(xj, vj, targs)
    if output_pending(targs):
        make_output(xj, vj, owed, mon, mon_t, mon_out, gm, eta, xs, vs, x, v, acc, n_active,
                    corr, cdt[0], targs, correct)
    owed_box[0] = owed
    return Status.OK, nsteps, n_mon


@njit(inline="always")
def _no_stop_args(stopping, sync, escape):
    # what the epilogue's stopping check takes: nothing in the lanes' loop,
    # which checks no conditions
    return ()


stop_args, = slots(stop_args=_no_stop_args)


#: Relative margin of :func:`may_escape`'s bound, for the rounding of the
#: Kepler drift and of the transformation to inertial coordinates (some
#: 1e-15 of the distances).
ESCAPE_MARGIN = 1e-8


@njit(inline="always")
def may_escape(xj, vj, gm, eta, owed, corr, esc2):
    """Whether a body may be farther than ``sqrt(esc2)`` from the centre of
    mass in the inertial state that :func:`synchronize` makes of the internal
    state ``xj``, ``vj`` (which owes the drift ``owed``); False only where none
    can be.

    Each internal row ``i >= 1`` drifts on its Kepler orbit about ``eta[i]``,
    so after any drift it lies within twice the orbit's semi-major axis,
    ``2 a = -eta_i / E_i >= a (1 + e)`` with ``E_i`` its Kepler energy per unit
    mass, of its origin (within its distance now, with nothing owed); the
    apocentre itself would cost a cross product, a square root and a
    division more a row, for a bound at most twice as tight.  The inertial
    position relative to the centre of mass is that row's vector less a
    mass-weighted sum of the others: ``x_i - X = (1 - w_i) x'_i - sum_{k>i}
    w_k x'_k`` with ``w_k = m_k / eta_k`` in Jacobi coordinates, ``Q_i -
    sum_k (m_k / M) Q_k`` in democratic heliocentric ones.  Both weights are
    at most ``m_k / m_0``, so every body is within ``R + sum_k (m_k / m_0)
    R_k`` of the centre of mass, ``R`` the largest of the bounds ``R_k``.  A
    row on an unbounded orbit while a drift is owed, a corrector (which moves
    the state by an amount not bounded here) or a non-finite state answers
    True.
    """
    if corr.shape[0] > 0:
        return True
    n = min(xj.shape[0], gm.shape[0])
    far = 0.0
    pull = 0.0
    for i in range(1, n):
        rx, ry, rz = xj[i, 0], xj[i, 1], xj[i, 2]
        ux, uy, uz = vj[i, 0], vj[i, 1], vj[i, 2]
        r = math.sqrt(rx * rx + ry * ry + rz * rz)
        if owed == 0.0:
            bound = r
        else:
            energy = 0.5 * (ux * ux + uy * uy + uz * uz) - eta[i] / r
            if not energy < 0.0:
                return True
            bound = -eta[i] / energy
        if bound > far:
            far = bound
        pull += gm[i] / gm[0] * bound
    reach = (far + pull) * (1.0 + ESCAPE_MARGIN)
    return not reach * reach <= esc2


def _escape_args(stopping, sync, escape):
    return (stopping, sync, escape)


@njit(inline="always")
def _escape_gate(xj, vj, t, args):
    # without conditions, a branch; with them, the bound of may_escape on the
    # internal state, and only where a body may be beyond the distance the
    # escape check through the loop's escape pointer (escape_pointer), which
    # synchronises: a call through a pointer hands over the records by value,
    # which would cost a step as much again
    stopping, sync, escape = args
    sargs = stopping[0]
    if sargs[0] == 0:
        return 0
    if not may_escape(xj, vj, sync.gm, sync.eta, sync.owed, sync.corr, sargs[3]):
        return 0
    return escape(xj, vj, t, stopping, sync)


def _escape_check(xj, vj, t, stopping, sync):
    # the escape conditions of orbits._kernels.stopping (ESCAPE, UNBOUND) on
    # the inertial state at the end of the step, synchronised into x, v (as
    # for an output), where _escape_gate found that a body may be beyond the
    # distance; stopping: the stopping record (sargs, check)
    synchronize_bodies(xj, vj, sync)
    return stopping[1](sync.x, sync.v, t, stopping[0])


def _synchronize_bodies(xj, vj, sync):
    gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, correct = sync
    sync_kernel(xj, vj, gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h,
                targs, correct)


def escape_kernels(key, cache=True, nrt=False):
    """The bindings of :func:`_wh_loop` and of its step epilogue's stopping
    check for a loop that checks escapes (``escape_distance``, and
    ``escape_unbound``, of :class:`orbits.Simulation`) where its stopping
    record has conditions, compiled under ``key``: ``(stop_args, check)``.
    The check calls the loop's ``escape`` argument, :func:`escape_pointer`'s,
    with the internal state, the stopping record and the synchronisation's
    arguments (a :class:`Sync`)."""
    args = specialize(_escape_args, key, cache=cache, inline=True, nrt=nrt)
    return args, _escape_gate


_ESCAPE_POINTERS = {}


def escape_pointer(key, synchronize_bodies, stopping, sync, conditions, cache=True):
    """The ``escape`` argument of a loop compiled with :func:`escape_kernels`
    under ``key``: the escape check as a C callable, which
    ``synchronize_bodies(xj, vj, sync)`` (writing the bodies' inertial state
    into ``x``, ``v`` of ``sync``) serves, compiled on first use and cached
    on disk; or, where the run has no stopping ``conditions``, a pointer of
    the same type that is never called (:func:`~._jit.idle_pointer`), so
    that a run without conditions compiles no escape check and one with
    them the check alone (which calls the stopping record's own pointer, the
    conditions' check every loop shares).  ``stopping``, ``sync``: the
    stopping record (:func:`~.stopping.stop_record`) and a :class:`Sync` of
    the values the loop hands the check (their types are the pointer's)."""
    signature = nbtypes.int64(nbtypes.float64[:, ::1], nbtypes.float64[:, ::1],
                              nbtypes.float64, numba.typeof(stopping), numba.typeof(sync))
    if not conditions:
        return idle_pointer(signature)
    found = _ESCAPE_POINTERS.get((key, signature, cache))
    if found is None:
        check = specialize(_escape_check, key, cache=cache, nrt=not cache,
                           synchronize_bodies=synchronize_bodies)
        found = _ESCAPE_POINTERS[key, signature, cache] = pointer(check, signature, cache)
    return found


def _wh_record(xj, vj, t, mon, n_mon, mon_t, mon_out):
    # the recorder the Wisdom-Holman loop hands the shared step epilogue:
    # mon is a Recording
    mon_args, (gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, correct) = mon
    sync_kernel(xj, vj, gm, eta, owed, xs, vs, x, v, acc, n_active, corr, h, targs, correct)
    record(x, v, t, mon_args, n_mon, mon_t, mon_out)


def _jacobi_term_kick(xj, vj, x, acc, gm, eta, n_active, h, targs):
    # the added terms' kick in Jacobi coordinates: inertial positions (left in
    # x by the interaction kick, which returns before computing them for two
    # bodies), the terms' inertial accelerations, and their Jacobi transform,
    # row 0 (the centre of mass) taking their mean
    n = xj.shape[0]
    if n <= 2:
        from_jacobi_one(xj, gm, eta, x)
    for i in range(n):
        acc[i, 0] = 0.0
        acc[i, 1] = 0.0
        acc[i, 2] = 0.0
    extra(x, x, 0.0, targs, acc)
    sx, sy, sz = jacobi_velocity_kick(xj, vj, acc, gm, eta, h, False)
    vj[0, 0] += h * sx
    vj[0, 1] += h * sy
    vj[0, 2] += h * sz


def _heliocentric_term_kick(xh, vb, x, acc, gm, eta, n_active, h, targs):
    # the added terms' kick in democratic heliocentric coordinates: with
    # x_0 = X - sum_k m_k Q_k / M, the kick of P_i = m_i V_i (i >= 1) is
    # F_i - (m_i / M) sum_k F_k, and the centre of mass takes sum_k F_k / M
    n = xh.shape[0]
    mt = 0.0
    cx = 0.0
    cy = 0.0
    cz = 0.0
    for i in range(n_active):
        mt += gm[i]
    for i in range(1, n_active):
        cx += gm[i] * xh[i, 0]
        cy += gm[i] * xh[i, 1]
        cz += gm[i] * xh[i, 2]
    x[0, 0] = xh[0, 0] - cx / mt
    x[0, 1] = xh[0, 1] - cy / mt
    x[0, 2] = xh[0, 2] - cz / mt
    for i in range(1, n):
        x[i, 0] = xh[i, 0] + x[0, 0]
        x[i, 1] = xh[i, 1] + x[0, 1]
        x[i, 2] = xh[i, 2] + x[0, 2]
    for i in range(n):
        acc[i, 0] = 0.0
        acc[i, 1] = 0.0
        acc[i, 2] = 0.0
    extra(x, x, 0.0, targs, acc)
    fx = 0.0
    fy = 0.0
    fz = 0.0
    for i in range(n_active):
        fx += gm[i] * acc[i, 0]
        fy += gm[i] * acc[i, 1]
        fz += gm[i] * acc[i, 2]
    fx /= mt
    fy /= mt
    fz /= mt
    for i in range(1, n):
        vb[i, 0] += h * (acc[i, 0] - fx)
        vb[i, 1] += h * (acc[i, 1] - fy)
        vb[i, 2] += h * (acc[i, 2] - fz)
    vb[0, 0] += h * fx
    vb[0, 1] += h * fy
    vb[0, 2] += h * fz


@njit(inline="always")
def _plain_drift(xj, vj, eta, h, w1, w2, targs):
    # the Kepler drift of a run without variations (a run with them binds
    # orbits._kernels.wh_tangent's, which also carries the tangent rows)
    kepler_drift_all(xj, vj, eta, h, w1, w2)


@njit(inline="always")
def _lanes_drift(xj, vj, eta, h, w1, w2, targs):
    # the Kepler drift with the planets in vector lanes (orbits._kernels.wh_lanes),
    # bit for bit _plain_drift's, of arrays (N, 3): the outputs' synchronising
    # drift in the lanes' loop (a run without added terms, whose targs then
    # carry the lanes' scratch instead of the terms' arguments).
    # Where the lanes declined more than a quarter of the planets (steps
    # long against their orbits), the scalar drift takes the next RETRY
    # drifts: there the lanes' pass is wasted work on top of the declined
    # planets' scalar drifts, which, one at a time, overlap less than in
    # kepler_drift_all (benchmarks/RESULTS.md)
    S = targs[0]
    if S[MEMO, 0] > 0.0:
        S[MEMO, 0] -= 1.0
        kepler_drift_all(xj, vj, eta, h, w1, w2)
    elif 4 * kepler_drift_lanes(xj, vj, eta, h, S) > xj.shape[0] - 1:
        S[MEMO, 0] = RETRY


def _plain_convert(a, b, gm, eta, c, d, targs):
    convert(a, b, gm, eta, c, d)


def _plain_perturbation(xj, vj, x, acc, gm, eta, n_active, h, targs):
    step(xj, vj, x, acc, gm, eta, n_active, h)


def _targs_emptied7(a, b, c, d, e, f, targs):
    convert(a, b, c, d, e, f, ())


def _targs_emptied9(a, b, c, d, e, f, g, h, targs):
    convert(a, b, c, d, e, f, g, h, ())


def _plain_call(kernel, name, nrt, plain):
    """The called copy of ``kernel``, an operator of the plain loop that
    reads no ``targs`` (the drift, a conversion, gravity's perturbation
    step), as the plain loop calls it (``plain``); for a loop whose
    ``targs`` hold something (a table of terms, the lanes' scratch), an
    operator that calls that copy with the plain loop's empty ``targs``, so
    that every loop calls the plain loop's compilation, where a call with
    the loop's own ``targs`` compiles it again for their type (4-5 CPU s
    for the drift).  The same code, so the same results bit for bit."""
    op = called(kernel, nrt)
    if plain:
        return op
    template = _targs_emptied7 if op.py_func.__code__.co_argcount == 7 else _targs_emptied9
    return specialize(template, name, inline=True, nrt=nrt, convert=op)


#: the Kepler drift of every planet that the plain loop calls (and its
#: corrector, synchronisation and owed drift), compiled without numba's
#: runtime; trace's segments with flags call it too
plain_drift_call = called(_plain_drift, nrt=False)


def _perturbation_with_terms(xj, vj, x, acc, gm, eta, n_active, h, targs):
    # gravity's perturbation step, then the terms' kick where the table
    # ``targs`` has rows: both depend on positions only, so the kicks commute
    # (in democratic heliocentric coordinates the terms kick between the two
    # half jumps).  With an empty table, the plain loop's step, bit for bit
    if HELIOCENTRIC:
        jump(xj, vj, gm, n_active, 0.5 * h)
        heliocentric_interaction_kick(xj, vj, acc, gm, n_active, h)
        if table_rows(targs) > 0:
            term_kick(xj, vj, x, acc, gm, eta, n_active, h, targs)
        jump(xj, vj, gm, n_active, 0.5 * h)
    else:
        interaction_kick(xj, vj, x, acc, gm, eta, n_active, h)
        if table_rows(targs) > 0:
            term_kick(xj, vj, x, acc, gm, eta, n_active, h, targs)


#: coordinate system -> (to internal, from internal, perturbation step, the
#: added terms' kick, the perturbation step of the lanes' loop on the state
#: kept in the lanes); each takes ``(.., gm, eta, ..)`` with ``eta`` the rows'
#: Kepler ``G M``
COORDINATE_SYSTEMS = {
    "jacobi": (to_jacobi, from_jacobi, interaction_kick, _jacobi_term_kick,
               _resident_jacobi),
    "democratic-heliocentric": (_to_heliocentric, _from_heliocentric,
                                jump_interaction_kick, _heliocentric_term_kick,
                                _resident_heliocentric),
}


# The getters of the compiled kernels below are asked at every call of the
# loop and of the synchronisation (a run's call asks four or five times):
# each answer is kept, instead of being put together again from some twenty
# lookups of specialize's (benchmarks/RESULTS.md)

@functools.lru_cache(maxsize=None)
def _kernels(coordinates, terms=None, lanes=False, through=True):
    """``terms``: a :class:`~orbits._kernels.terms.TermKernel` of position-only
    terms added to the interaction step, or None; ``lanes``: the
    synchronisation's owed drift with the planets in vector lanes (the
    loop's ``targs`` then hold the lanes' scratch); ``through``: the
    synchronisation calls the corrector through the loop's pointer (else it
    compiles the corrector in).  Returns (to internal, perturbation step,
    corrector, synchronisation, from internal, the corrector's call)."""
    to_internal, from_internal, step, term_kick, _ = COORDINATE_SYSTEMS[coordinates]
    key = coordinates if terms is None else f"{coordinates}_{terms.key}"
    cache = terms is None or terms.cache
    to_internal = specialize(_plain_convert, f"to_{coordinates}", inline=True,
                             convert=to_internal)
    from_internal = specialize(_plain_convert, f"from_{coordinates}", inline=True,
                               convert=from_internal)
    # without numba's runtime: these allocate nothing, and the reference
    # counts of the inlined kernels' array arguments would cost more than a
    # two-body step's kick (see orbits._kernels._jit).  A user's term (not
    # cacheable) may return a new array every call, which only the runtime
    # frees: with it, it runs with the runtime.
    nrt = not cache
    if terms is None:
        perturbation = specialize(_plain_perturbation, key, inline=True, nrt=nrt,
                                  step=step)
    else:
        # the terms' kick is called: it runs only where the table has rows,
        # and the loop's step inlines gravity's perturbation alone
        kick = called(specialize(term_kick, key, cache=cache, inline=True, nrt=nrt,
                                 extra=terms.accel), nrt)
        perturbation = specialize(_perturbation_with_terms, key, cache=cache, inline=True,
                                  nrt=nrt, term_kick=kick,
                                  HELIOCENTRIC=coordinates != "jacobi")
    # the corrector and an output's synchronisation run once a call or an
    # output: they call the drift and the perturbation step, compiled once,
    # instead of inlining a copy at each of their call sites.  Both drift
    # every planet: in lanes, bit for bit, where the loop drifts in lanes (so
    # that the loop compiles one drift of arrays (N, 3), not two)
    # (the loops with terms or lanes call the plain loop's compilations of
    # what reads no targs: _plain_call)
    if lanes:
        drift = called(_lanes_drift, nrt)
    else:
        drift = _plain_call(_plain_drift, "drift", nrt, terms is None)
    if terms is None:
        perturbation_call = _plain_call(perturbation, f"perturbation_{coordinates}", nrt,
                                        not lanes)
    else:
        perturbation_call = called(perturbation, nrt)
    corrector = specialize(_apply_corrector, f"corrector_{key}", cache=cache, nrt=nrt,
                           drift=drift, perturbation=perturbation_call)
    # the loops call the corrector through a pointer (corrector_pointer): a
    # run without a corrector, the default, compiles none
    correct = _correct_through if through else specialize(
        _correct_compiled, f"corrector_{key}", cache=cache, inline=True, nrt=nrt,
        corrector=corrector)
    sync = specialize(_synchronize, f"synchronize_{key}" + ("_lanes" if lanes else "")
                      + ("" if through else "_compiled"),
                      cache=cache, nrt=nrt, drift=drift, from_internal=from_internal,
                      corrector_kernel=correct)
    return to_internal, perturbation, corrector, sync, from_internal, correct


_CORRECTORS = {}


def corrector_signature(xj, gm, eta, corr, targs):
    """The type of the corrector's pointer (:func:`corrector_pointer`) that a
    loop takes, from the values it hands the corrector: the internal state
    ``xj`` (and arrays like it), ``gm``, ``eta``, the stages ``corr`` and the
    loop's ``targs``."""
    a = numba.typeof(xj)
    return nbtypes.none(a, a, a, a, numba.typeof(gm), numba.typeof(eta), nbtypes.int64,
                        numba.typeof(corr), nbtypes.float64, nbtypes.float64,
                        numba.typeof(targs))


def corrector_pointer(coordinates, terms, lanes, signature, corrected):
    """The ``correct`` argument of :func:`wh_loop`'s loop for ``coordinates``,
    ``terms`` and ``lanes``, and of its synchronisation: the symplectic
    corrector (:func:`_apply_corrector`) as a C callable of ``signature``
    (:func:`corrector_signature`), compiled on first use and cached on
    disk, for a run whose method has a corrector (``corrected``); else a
    pointer of the same type that is never called
    (:func:`~._jit.idle_pointer`).  So one loop serves runs with and
    without a corrector, and a run without one compiles none."""
    if not corrected:
        return idle_pointer(signature)
    cache = terms is None or terms.cache
    key = (coordinates, None if terms is None else terms.key, bool(lanes), signature, cache)
    found = _CORRECTORS.get(key)
    if found is None:
        # without numba's runtime where its kernels have none (a user's
        # term may allocate: see _kernels)
        call = specialize(_corrector_call, f"corrector_{coordinates}", cache=cache,
                          nrt=not cache, corrector=_kernels(coordinates, terms, lanes)[2])
        found = _CORRECTORS[key] = pointer(call, signature, cache, nrt=not cache)
    return found


def synchronizer(coordinates, terms=None, lanes=False):
    """The compiled :func:`synchronize` for ``coordinates`` (and added ``terms``;
    with ``lanes``, for the loop whose planets drift in vector lanes)."""
    return _kernels(coordinates, terms, lanes)[3]


@functools.lru_cache(maxsize=None)
def wh_loop(coordinates="jacobi", terms=None, record=_record, lanes=False):
    """The Wisdom-Holman loop compiled for ``coordinates`` (a key of
    :data:`COORDINATE_SYSTEMS`), for every table of Kepler drifts (DRIFT) and
    perturbation steps (KICK), which the :class:`System` record carries.  ``terms`` (a
    :class:`~orbits._kernels.terms.TermKernel` of position-only terms) join
    the perturbation step, and ``record`` records the monitors.  ``lanes``
    (without terms only): the steps' operators with the planets in vector
    lanes (:mod:`orbits._kernels.wh_lanes`), bit for bit the same results;
    the loop's ``targs`` are then ``(wh_lanes.lanes_scratch(N),)``.  The
    corrector and the synchronisation stay scalar (they run once a call or
    an output).  The loop takes ``(x, v, t, dt, nsteps, system, work,
    outputs, checks, check, escape, correct, targs)``: a :class:`System`, a
    :class:`Work`, the records of :mod:`orbits._kernels.records`, the
    stopping conditions' pointer (:func:`~orbits._kernels.stopping.stop_record`),
    the escape check's (:func:`loop_escape`), the corrector's
    (:func:`corrector_pointer`) and the terms' arguments or the lanes'
    scratch; without ``lanes`` it checks the escape conditions of
    :mod:`orbits._kernels.stopping` after every step on the synchronised
    state where the record has conditions (:func:`escape_kernels`); the
    lanes' loop checks none, calls neither pointer and takes 0 for the
    escape check's."""
    if lanes and terms is not None:
        raise ValueError("wh_loop: the lanes' loop takes no added terms")
    to_internal, perturbation, _, sync, from_internal, correct = _kernels(coordinates, terms,
                                                                          lanes)
    key = coordinates if terms is None else f"{coordinates}_{terms.key}"
    cache = terms is None or terms.cache
    nrt = not cache
    # the scalar loop, which a first, shorter run takes (the lanes' loop
    # serves the long ones: orbits.integrators.wisdom_holman's lanes option),
    # calls the drift that its synchronisation and corrector call instead of
    # inlining a copy: 2.3 s less to compile for 2-5 % more a step
    # (benchmarks/RESULTS.md); with terms, the plain loop's compilation
    drift = _plain_call(_plain_drift, "drift", nrt, terms is None)
    outputs = {}
    if lanes:
        # the state kept in the lanes between outputs, and outputs made beside
        # the next step's first drift (see _lanes_note)
        drift = _lanes_drift
        key = f"{key}_lanes"
        # the kernels that work on the lanes alone are the same for both
        # coordinate systems (each row's Kepler G M is data): named without
        # them, those it calls compile once for both
        lanes = "lanes"
        recorder = specialize(_lanes_note, lanes, cache=cache, nrt=nrt)
        outputs = dict(
            RESIDENT=True,
            resident_drift=specialize(_resident_drift, lanes, cache=cache, inline=True,
                                      nrt=nrt),
            resident_perturbation=specialize(COORDINATE_SYSTEMS[coordinates][4], key,
                                             cache=cache, inline=True, nrt=nrt),
            lanes_in=called(specialize(_resident_in, lanes, cache=cache, inline=True, nrt=nrt),
                            nrt),
            lanes_out=called(specialize(_resident_out, lanes, cache=cache, inline=True,
                                        nrt=nrt), nrt),
            lanes_check=specialize(_resident_check, lanes, cache=cache, inline=True, nrt=nrt),
            output_pending=specialize(_lanes_pending, lanes, cache=cache, inline=True, nrt=nrt),
            output_drift=specialize(_resident_output_drift, lanes, cache=cache, inline=True,
                                    nrt=nrt),
            make_output=specialize(_lanes_output, key, cache=cache, nrt=nrt,
                                   sync_kernel=sync, from_internal=from_internal,
                                   record=record))
    else:
        recorder = specialize(_wh_record, key, cache=cache, nrt=nrt, sync_kernel=sync,
                              record=record)
    stop = no_stop
    if not lanes:
        outputs["stop_args"], stop = escape_kernels(key, cache=cache, nrt=nrt)
    return specialize(_wh_loop, f"wh_{key}", nrt=nrt, cache=cache,
                      to_internal=_plain_call(to_internal, f"to_{coordinates}", nrt,
                                              terms is None and not lanes),
                      drift=drift,
                      owed_drift=called(drift, nrt) if lanes else _plain_call(
                          _plain_drift, "drift", nrt, terms is None),
                      perturbation=perturbation,
                      corrector_kernel=correct,
                      step_end=epilogue(recorder, f"wh_{key}", cache=cache, stop=stop),
                      **outputs)


def loop_escape(coordinates, terms, stopping, sync, conditions):
    """The ``escape`` argument of :func:`wh_loop`'s loop without lanes for
    ``coordinates`` and ``terms``: :func:`escape_pointer`'s, for a run with
    stopping ``conditions`` or without; ``stopping`` the stopping record and
    ``sync`` a :class:`Sync` of the values the loop hands its
    synchronisation."""
    key = coordinates if terms is None else f"{coordinates}_{terms.key}"
    cache = terms is None or terms.cache
    bodies = None
    if conditions:
        bodies = specialize(_synchronize_bodies, key, cache=cache, inline=True, nrt=not cache,
                            sync_kernel=_kernels(coordinates, terms)[3])
    return escape_pointer(key, bodies, stopping, sync, conditions, cache)


#: the Jacobi versions with the corrector compiled in (the batch's
#: synchronisation, which hands 0 for the pointer), compiled on first use
apply_corrector = _kernels("jacobi", through=False)[2]
synchronize = _kernels("jacobi", through=False)[3]

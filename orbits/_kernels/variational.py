"""First-order variational equations and the chaos indicators built on them.

A tangent vector ``delta = (dx, dv, dm)`` follows the linearised motion

    d(dx)/dt = dv,    d(dv)/dt = (da/dx) dx + (da/dv) dv + (da/dm) dm,

with ``dm`` constant.  Every integrator other than the Wisdom-Holman family
integrates it by integrating the augmented system: the state arrays hold the
bodies in rows ``[0, n)`` and tangent vector ``j`` in rows
``[n (1 + j), n (2 + j))`` (``dx`` in the positions, ``dv`` in the
velocities), and :func:`with_variations` makes a force whose accelerations of
those rows are ``(da/dx) dx + (da/dv) dv + (da/dm) dm``.  A Runge-Kutta
method, a splitting method, IAS15 or an implicit method applied to the
augmented system gives, in the tangent rows, the exact derivative of the
method's own map (the discrete tangent map), because each of these methods
commutes with linearisation (Hairer, Lubich & Wanner 2006, section VI.4).
``da/dx`` and ``da/dv`` are the force's Jacobian
(:func:`orbits._kernels.jacobians.jacobian_for`: analytic for gravity and the
package's terms); ``da/dm`` is gravity's, ``G (x_l - x_i) / s^3`` for the pull
of body ``l`` on body ``i``.  The Wisdom-Holman family propagates the tangent
through its own Kepler drifts and kicks (:mod:`.wh_tangent`; Rein & Tamayo
2016).

The step size control of adaptive methods measures the bodies' rows only
(:func:`measured_rows`), so that asking for variations does not change the
steps; the tangent is that of the map with those steps.

Chaos indicators (tangent vector 0 when they are asked for).  With ``L(t) =
ln |delta(t) / delta(0)|`` (the Euclidean norm over positions and velocities
in the internal units, as REBOUND's), MEGNO (Cincotta & Simo 2000) is

    Y(t) = (2 / t) int_0^t s (d/ds) L(s) ds = 2 L(t) - (2 / t) int_0^t L(s) ds,

the second form by integration by parts, and its running mean ``<Y>(t) = (1 /
t) int_0^t Y(s) ds``, which tends to 2 on a regular (quasi-periodic) orbit,
where ``|delta|`` grows linearly, and grows as ``lambda t / 2`` on a chaotic
one.  The second form needs ``|delta|`` alone, not its derivative: after
every step :func:`chaos_update` adds the step's trapezoid to ``int L`` and to
``int Y``.  The largest Lyapunov exponent's estimate is ``L(t) / t`` and the
fast Lyapunov indicator (Froeschle, Lega & Gonczi 1997) ``max_{s <= t} L(s)``
(natural logarithm).  ``|delta|`` grows without bound on a chaotic orbit, so
when it passes ``2^RENORMALISE_EXPONENT`` the vector is scaled by an exact
power of two and the logarithm it lost is kept in the accumulators
(renormalisation, Benettin et al. 1980): the linear equations make this exact.

The accumulators live in a float64 array ``box`` (:data:`CHAOS`), the
workspace's ``"chaos"`` array, saved and restored with the state.
"""

import math

import numpy as np

from ._jit import njit, slots, specialize
from .coordinates import row_difference
from .invariants import MONITOR_COLUMNS
from .jacobians import jacobian_for

# the names the templates below are written against, bound by specialize
(MEGNO_COLUMN, inner, inner_add, inner_note, inner_rate, inner_record, jacobian, reads,
 inner_reads, table_reads, inner_on) = slots(
    "MEGNO_COLUMN", "inner", "inner_add", "inner_note", "inner_rate", "inner_record",
    "jacobian", "reads", "inner_reads", "table_reads", "inner_on")

__all__ = ["with_variations", "variation_args", "chaos_update", "chaos_rescaled",
           "chaos_values", "chaos_box", "measured_rows", "CHAOS", "RENORMALISE_EXPONENT",
           "tangent_kernels", "tangent_product"]

#: slots of the chaos accumulator box
CHAOS = dict(t0=0, t_prev=1, L_prev=2, offset=3, int_L=4, int_Y=5, Y_prev=6, fli=7, L=8,
             on=9)
_T0, _TP, _LP, _OFF, _IL, _IY, _YP, _FLI, _L, _ON = range(10)

#: |delta| above 2**RENORMALISE_EXPONENT is scaled back to about 1 (at most
#: once in e**208 of growth: rare, and far from overflow at 2**1024)
RENORMALISE_EXPONENT = 300

_LN2 = math.log(2.0)


def chaos_box(t0):
    """A fresh accumulator array for a run starting at time ``t0`` (internal
    units) with a unit tangent vector."""
    box = np.zeros(len(CHAOS))
    box[_T0] = t0
    box[_TP] = t0
    return box


@njit
def chaos_update(dx, dv, t, box):
    """Advance the chaos accumulators ``box`` to time ``t`` with the tangent
    vector ``(dx, dv)`` there; returns True when ``|delta|`` should be
    renormalised (see the module notes)."""
    s = 0.0
    for i in range(dx.shape[0]):
        for d in range(3):
            s += dx[i, d] * dx[i, d] + dv[i, d] * dv[i, d]
    L = 0.5 * math.log(s) + box[_OFF]
    h = t - box[_TP]
    box[_IL] += 0.5 * h * (L + box[_LP])
    span = t - box[_T0]
    Y = 2.0 * L - 2.0 * box[_IL] / span if span != 0.0 else 0.0
    box[_IY] += 0.5 * h * (Y + box[_YP])
    box[_YP] = Y
    box[_LP] = L
    box[_TP] = t
    box[_L] = L
    if L > box[_FLI]:
        box[_FLI] = L
    return s > 4.0 ** RENORMALISE_EXPONENT


@njit
def chaos_rescaled(box, e):
    """The tangent vector was multiplied by ``2**-e``: keep its logarithm."""
    box[_OFF] += e * _LN2


@njit
def _exponent(dx, dv):
    # e with |delta| 2**-e in [0.5, 1)
    s = 0.0
    for i in range(dx.shape[0]):
        for d in range(3):
            s += dx[i, d] * dx[i, d] + dv[i, d] * dv[i, d]
    return int(math.floor(0.5 * math.log2(s))) + 1


@njit
def renormalise(x, v, n, box):
    """Scale tangent vector 0 (rows ``[n, 2n)`` of ``x`` and ``v``) by an exact
    power of two to a norm in [0.5, 1) and note it in ``box``."""
    e = _exponent(x[n:2 * n], v[n:2 * n])
    f = 2.0 ** -e
    for i in range(n, 2 * n):
        for d in range(3):
            x[i, d] *= f
            v[i, d] *= f
    chaos_rescaled(box, e)


def chaos_values(box):
    """``(megno, lyapunov, fli)`` from the accumulators: the running mean of
    MEGNO, ``L / t`` and ``max L`` (0.0 at the start)."""
    span = box[_TP] - box[_T0]
    if span == 0.0:
        return 0.0, 0.0, 0.0
    return box[_IY] / span, box[_L] / span, box[_FLI]


# -- the force of the augmented system ------------------------------------------------------

@njit(inline="always")
def tangent_product(jx, jv, x, v, o, n, acc, velocity):
    """The accelerations' tangent vector in the rows ``o .. o + n - 1`` of
    ``acc``: ``da/dx`` (``jx``, shape (3n, 3n)) times the positions' tangent
    vector in those rows of ``x``, plus, with ``velocity``, ``da/dv``
    (``jv``) times the velocities' in ``v``, summed body by body."""
    for i in range(n):
        for d in range(3):
            r = 3 * i + d
            s = 0.0
            for c in range(n):
                s += (jx[r, 3 * c] * x[o + c, 0] + jx[r, 3 * c + 1] * x[o + c, 1]
                      + jx[r, 3 * c + 2] * x[o + c, 2])
                if velocity:
                    s += (jv[r, 3 * c] * v[o + c, 0] + jv[r, 3 * c + 1] * v[o + c, 1]
                          + jv[r, 3 * c + 2] * v[o + c, 2])
            acc[o + i, d] = s


def _varied(x, v, t, fargs, acc):
    inner_args, vargs = fargs[0], fargs[1]
    n, dm, jx, jv = vargs[0], vargs[1], vargs[2], vargs[3]
    inner(x[:n], v[:n], t, inner_args, acc[:n])
    velocity = reads(inner_args)
    for p in range(3 * n):
        for q in range(3 * n):
            jx[p, q] = 0.0
            if velocity:
                jv[p, q] = 0.0
    jacobian(x[:n], v[:n], t, inner_args, jx, jv)
    k = dm.shape[0]
    G, eps2, masses = vargs[5][0], vargs[5][1], vargs[5][3]
    for j in range(k):
        o = n * (j + 1)
        tangent_product(jx, jv, x, v, o, n, acc, velocity)
        if masses:
            # gravity's da/dm dm
            for l in range(n):
                g = G * dm[j, l]
                if g == 0.0:
                    continue
                for i in range(n):
                    if i == l:
                        continue
                    d0, d1, d2 = row_difference(x, l, i)
                    s2 = d0 * d0 + d1 * d1 + d2 * d2 + eps2
                    f = g / (s2 * math.sqrt(s2))
                    acc[o + i, 0] += f * d0
                    acc[o + i, 1] += f * d1
                    acc[o + i, 2] += f * d2


def _varied_jacobian(x, v, t, fargs, jx, jv):
    # for implicit methods: the augmented system's Jacobian without the
    # second derivatives (the blocks coupling the tangent to the bodies), so a
    # simplified Newton iteration, which converges to the same solution
    inner_args, vargs = fargs[0], fargs[1]
    n, sx, sv = vargs[0], vargs[2], vargs[3]
    m = jx.shape[0]
    for p in range(m):
        for q in range(m):
            jx[p, q] = 0.0
            jv[p, q] = 0.0
    for p in range(3 * n):
        for q in range(3 * n):
            sx[p, q] = 0.0
            sv[p, q] = 0.0
    jacobian(x[:n], v[:n], t, inner_args, sx, sv)
    blocks = m // (3 * n)
    for b in range(blocks):
        o = 3 * n * b
        for p in range(3 * n):
            for q in range(3 * n):
                jx[o + p, o + q] = sx[p, q]
                jv[o + p, o + q] = sv[p, q]


def _varied_record(x, v, t, mon, n_mon, mon_t, mon_out):
    # the bodies' monitors: the masses in mon say how many rows are bodies
    n = mon[2].shape[0]
    inner_record(x[:n], v[:n], t, mon, n_mon, mon_t, mon_out)


def _varied_work_rate(x, v, t, fargs):
    n = fargs[1][0]
    return inner_rate(x[:n], v[:n], t, fargs[0])


def _varied_work_add(fargs, dw):
    inner_add(fargs[0], dw)


def _varied_note(fargs, mon_out, row):
    # the work, then the chaos indicators, into the monitor row just recorded
    inner_note(fargs[0], mon_out, row)
    if fargs[1][5][2]:
        box = fargs[1][4]
        span = box[1] - box[0]
        if span != 0.0:
            mon_out[row, MEGNO_COLUMN] = box[5] / span
            mon_out[row, MEGNO_COLUMN + 1] = box[8] / span
            mon_out[row, MEGNO_COLUMN + 2] = box[7]


def _tangent_step(x, v, t, fargs):
    # after every step: the chaos accumulators (tangent vector 0), where the
    # chaos indicators are on; True asks the loop to stop for a renormalisation
    vargs = fargs[1]
    if vargs[5][2]:
        n = vargs[0]
        return chaos_update(x[n:2 * n], v[n:2 * n], t, vargs[4])
    return False


@njit(inline="always")
def _no_tangent_step(x, v, t, fargs):
    return False


def _measured(x, fargs):
    return fargs[1][0]


@njit(inline="always")
def _all_rows(x, fargs):
    return x.shape[0]


def measured_rows(force):
    """The kernel ``rows(x, fargs)`` giving how many leading rows of the state an
    adaptive method's error estimate measures: all of them, or the bodies'
    for a force with variations."""
    if force.inner is None:
        return _all_rows
    return specialize(_measured, "measured", inline=True)


def tangent_kernels(force):
    """The bindings of the step epilogue for ``force``: ``tangent_step(x, v, t,
    fargs) -> bool`` (the chaos accumulators after a step; True: renormalise)."""
    if force.inner is None:
        return dict(tangent_step=_no_tangent_step)
    return dict(tangent_step=specialize(_tangent_step, force.key, cache=force.cache,
                                        inline=True))


def _varied_work_on(fargs):
    return inner_on(fargs[0])


def variational_work_kernels(force, inner_kernels):
    """The work and note kernels (see :func:`orbits._kernels.stepping.work_kernels`)
    of a force with variations, from its inner force's ``inner_kernels``: on
    the bodies' rows, and the note also writes the chaos indicators."""
    key = force.key
    cache = force.cache
    return dict(
        HAS_WORK=inner_kernels["HAS_WORK"],
        work_rate=specialize(_varied_work_rate, key, cache=cache, inline=True,
                             inner_rate=inner_kernels["work_rate"]),
        work_add=specialize(_varied_work_add, key, cache=cache, inline=True,
                            inner_add=inner_kernels["work_add"]),
        work_on=specialize(_varied_work_on, key, cache=cache, inline=True,
                           inner_on=inner_kernels["work_on"]),
        # (named without the force, as with_variations' record)
        work_note=specialize(_varied_note, "var", cache=cache, inline=True,
                             inner_note=inner_kernels["work_note"],
                             MEGNO_COLUMN=MONITOR_COLUMNS.index("megno")))


@njit(inline="always")
def _never_reads(fargs):
    return False


@njit(inline="always")
def _always_reads(fargs):
    return True


def _terms_read(fargs):
    return table_reads(fargs[1])


def _inner_reads_of(fargs):
    return inner_reads(fargs[0])


def velocity_reader(force):
    """``reads(fargs) -> bool``: whether ``force`` (a
    :class:`~orbits._kernels.stepping.ForceKernel`) with the arguments
    ``fargs`` reads the velocities.  For gravity with terms it is their
    table's to say, at run time, so that one loop serves terms that do and
    terms that do not; a force with variations asks its inner force.  A
    loop that runs as Python (a user's Python function) gets the answer of
    the force's flag as a plain function."""
    if not force.jit:
        flag = bool(force.velocity_dependent or force.opaque)
        return (_always_reads if flag else _never_reads).py_func
    if force.inner is not None:
        return specialize(_inner_reads_of, force.key, cache=force.cache, inline=True,
                          inner_reads=velocity_reader(force.inner))
    if force.terms is not None:
        return specialize(_terms_read, force.terms.key, cache=force.cache, inline=True,
                          table_reads=force.terms.reads_velocities)
    return _always_reads if (force.velocity_dependent or force.opaque) else _never_reads


def varied_recorder(inner_record, jit=True, cache=True):
    """The monitor recorder of a force with variations whose inner force
    records with ``inner_record``: the bodies' rows alone."""
    return specialize(_varied_record, "var", jit=jit, cache=cache, inner_record=inner_record)


def with_variations(force, chaos):
    """The force of the augmented system (see the module notes) for ``force``
    (a :class:`~orbits._kernels.stepping.ForceKernel`), with its arguments
    ``(fargs, vargs)`` (:func:`variation_args`).  ``chaos``: tangent vector 0
    carries the chaos indicators.  Both are data of the arguments (the mass
    variations ``dm``, the chaos flag), so one compiled loop serves every
    kind of variations with and without the chaos indicators."""
    vd = bool(force.velocity_dependent)
    jac, jkey = jacobian_for(force, vd)
    key = f"var({force.key};{jkey})"
    kernel = specialize(_varied, key, jit=force.jit, cache=force.cache, inline=True,
                        inner=force.kernel, jacobian=jac, reads=velocity_reader(force))
    jacobian = specialize(_varied_jacobian, key, jit=force.jit, cache=force.cache,
                          jacobian=jac)
    # the record calls the inner force's recorder, not the force: named
    # without the force (the copy's name carries its bindings' too), so that
    # loops that take the record but kick with their own pairs (wh's tangent
    # loop) are one compilation for every gravity kernel
    record = varied_recorder(force.recorder, force.jit, force.cache)
    # the record of force's own type (stepping.ForceKernel, whose loops' module
    # imports this one for the epilogue's tangent step and the work kernels)
    return type(force)(kernel, key, force.jit, force.cache, jacobian=jacobian,
                       velocity_dependent=vd, record=record, allocates=True,
                       work=force.work, inner=force, chaos=bool(chaos),
                       dissipative=force.dissipative)


def variation_args(fargs, n, dm, box, G, eps2, chaos):
    """The arguments of a force made by :func:`with_variations`: ``(fargs,
    (n, dm, jx, jv, box, (G, eps2, chaos, masses)))`` with ``dm`` of shape
    (k, n), the mass variation of each tangent vector, ``box`` the chaos
    accumulators, ``chaos`` whether tangent vector 0 carries them and
    ``masses`` whether any vector varies a mass."""
    m = 3 * n
    dm = np.ascontiguousarray(dm, dtype=float)
    return (fargs, (n, dm, np.zeros((m, m)), np.zeros((m, m)), box,
                    (float(G), float(eps2), bool(chaos), bool(np.any(dm != 0.0)))))

"""The Stumpff functions ``c0(z) .. c5(z)`` of the universal Kepler equation.

``c_k(z) = sum_j (-z)^j / (k + 2j)!``: ``c0 = cos sqrt(z)``, ``c1 = sin
sqrt(z) / sqrt(z)``, ``c2 = (1 - c0) / z``, ``c3 = (1 - c1) / z`` (hyperbolic
functions of ``sqrt(-z)`` for ``z < 0``), continuous through ``z = 0``.
:func:`stumpff` is the general form; the Kepler drift (:mod:`.kepler`) takes
the inlined short-step forms (four or nine terms of the series for the
steps of a planetary integration), the planets' and systems' lanes
(:mod:`.wh_lanes`, :mod:`.wh_batch`) the branch-free :func:`stumpff_lane`
and :func:`stumpff_medium_lane`, bit for bit the same inside their domain,
and the drift's tangent (:mod:`.kepler_tangent`) ``c4`` and ``c5`` as well.

References
----------
Stumpff, K. 1959, *Himmelsmechanik*, Band I, VEB Deutscher Verlag der
Wissenschaften; Danby, J. M. A. 1988, *Fundamentals of Celestial Mechanics*,
2nd ed., Willmann-Bell, sect. 6.9.
"""

import math

from ._jit import fma, njit

__all__ = ["stumpff", "stumpff_lane", "stumpff_medium_lane"]

# Stumpff functions: |z| above this is evaluated from cos/sin (cosh/sinh)
# directly, where 1 - cos sqrt(z) and 1 - sin sqrt(z) / sqrt(z) lose at most
# a bit to cancellation; below it from the series after quartering z to below
# _STUMPFF_SERIES_Z and doubling back.
_STUMPFF_DIRECT_Z = 4.0
# |z| < 0.1: the series below to z^6 is exact to 0.1^7 / 17! ~ 3e-22.
_STUMPFF_SERIES_Z = 0.1
# |z| < 2e-3 (a step of up to 0.045 rad of eccentric anomaly: the steps of a
# planetary integration): four terms suffice, the first omitted one being
# (2e-3)^4 / 10! ~ 4e-18 against c2 = 1/2.
_STUMPFF_SHORT_Z = 2e-3
# |z| <= 1 (a step of up to a radian of eccentric anomaly: a twentieth to a
# sixth of an orbit, the steps people take with Wisdom-Holman): nine terms of
# each series, the first omitted one being 1 / 20! ~ 4e-19 against c2(1) =
# 0.46 and 1 / 21! ~ 2e-20 against c3(1) = 0.16; every term is smaller than
# the one before, so the alternating sum loses nothing to cancellation.
_STUMPFF_MEDIUM_Z = 1.0
_SIXTH = 1.0 / 6.0


@njit(inline="always")
def _stumpff_series(z):
    """Stumpff functions from their series, for ``|z| <= _STUMPFF_SERIES_Z``."""
    # c2 = 1/2! - z/4! + z^2/6! - ..., c3 = 1/3! - z/5! + z^2/7! - ... (Horner)
    c2 = (1.0 / 2 - z * (1.0 / 24 - z * (1.0 / 720 - z * (1.0 / 40320 - z * (
        1.0 / 3628800 - z * (1.0 / 479001600 - z * (1.0 / 87178291200)))))))
    c3 = (1.0 / 6 - z * (1.0 / 120 - z * (1.0 / 5040 - z * (1.0 / 362880 - z * (
        1.0 / 39916800 - z * (1.0 / 6227020800 - z * (1.0 / 1307674368000)))))))
    return 1.0 - z * c2, 1.0 - z * c3, c2, c3


@njit(inline="always")
def _stumpff_inline(z):
    """:func:`stumpff`, with its most common case (``|z|`` small) inlined."""
    if -_STUMPFF_SERIES_Z <= z <= _STUMPFF_SERIES_Z:
        return _stumpff_series(z)
    return stumpff(z)


@njit(inline="always")
def _stumpff_short(z):
    """:func:`stumpff` for the steps of a planetary integration: for
    ``|z| <= _STUMPFF_SHORT_Z`` four terms of each series, for ``|z| <=
    _STUMPFF_MEDIUM_Z`` nine, both in Estrin's form (independent parts, for a
    shorter chain of dependent operations), beyond that :func:`stumpff`."""
    if -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z:
        return _estrin(z)
    if -_STUMPFF_MEDIUM_Z <= z <= _STUMPFF_MEDIUM_Z:
        return _estrin_medium(z)
    return _stumpff_inline(z)


@njit
def stumpff(z):
    """Stumpff functions ``c0(z), c1(z), c2(z), c3(z)``.

    Parameters
    ----------
    z : float
        Argument (``beta s^2`` in the universal Kepler equation); any sign.

    Returns
    -------
    c0, c1, c2, c3 : float
        ``c0 = cos sqrt(z)``, ``c1 = sin sqrt(z) / sqrt(z)``,
        ``c2 = (1 - c0) / z``, ``c3 = (1 - c1) / z`` (hyperbolic functions of
        ``sqrt(-z)`` for ``z < 0``), continuous through ``z = 0`` where they
        are ``1, 1, 1/2, 1/6``.

    Notes
    -----
    For ``|z| <= 4`` the argument is quartered until it is below 0.1, ``c2``
    and ``c3`` are summed from their series ``c_k(z) = sum_j (-z)^j /
    (k + 2j)!``, and the quarter-argument identities
    ``c2(4z) = c1(z)^2 / 2``, ``c3(4z) = (c2(z) + c0(z) c3(z)) / 4`` bring
    them back, with ``c0 = 1 - z c2`` and ``c1 = 1 - z c3`` at every level.

    References
    ----------
    Stumpff, K. 1959, *Himmelsmechanik*, Band I, VEB Deutscher Verlag der
    Wissenschaften; Danby, J. M. A. 1988, *Fundamentals of Celestial
    Mechanics*, 2nd ed., sect. 6.9.
    """
    if z > _STUMPFF_DIRECT_Z:
        sz = math.sqrt(z)
        c0 = math.cos(sz)
        c1 = math.sin(sz) / sz
        return c0, c1, (1.0 - c0) / z, (1.0 - c1) / z
    if z < -_STUMPFF_DIRECT_Z:
        sz = math.sqrt(-z)
        c0 = math.cosh(sz)
        c1 = math.sinh(sz) / sz
        return c0, c1, (1.0 - c0) / z, (1.0 - c1) / z
    n = 0
    while abs(z) > _STUMPFF_SERIES_Z:
        z *= 0.25
        n += 1
    c0, c1, c2, c3 = _stumpff_series(z)
    for _ in range(n):
        c3 = 0.25 * (c2 + c0 * c3)
        c2 = 0.5 * c1 * c1
        z *= 4.0
        c0 = 1.0 - z * c2
        c1 = 1.0 - z * c3
    return c0, c1, c2, c3


# quarterings of a Stumpff argument that stumpff_lane takes: |z| <= 4 (above
# it stumpff uses the trigonometric form directly) needs at most 3, as
# 4 / 4^3 < _STUMPFF_SERIES_Z
_LANE_QUARTERINGS = 3


@njit(inline="always")
def _estrin(z):
    # _stumpff_short's four terms of each series, in Estrin's form with fused
    # multiply-adds: c2 = (1/2 - z/4!) + z^2 (1/6! - z/8!), c3 = (1/3! -
    # z/5!) + z^2 (1/7! - z/9!), c0 = 1 - z c2, c1 = 1 - z c3
    z2 = z * z
    c2 = fma(z2, fma(-z, 1.0 / 40320, 1.0 / 720), fma(-z, 1.0 / 24, 0.5))
    c3 = fma(z2, fma(-z, 1.0 / 362880, 1.0 / 5040), fma(-z, 1.0 / 120, 1.0 / 6))
    return fma(-z, c2, 1.0), fma(-z, c3, 1.0), c2, c3


@njit(inline="always")
def _estrin_medium(z):
    # _stumpff_short's nine terms of each series (|z| <= _STUMPFF_MEDIUM_Z),
    # c_k = sum_j (-z)^j / (k + 2j)!, j = 0 .. 8, in Estrin's form: pairs of
    # terms p_i = a_2i - z a_(2i+1), then (p0 + z^2 p1) + z^4 ((p2 + z^2 p3)
    # + z^4 a_8), with fused multiply-adds
    z2 = z * z
    z4 = z2 * z2
    c2 = fma(z4, fma(z4, 1.0 / 6402373705728000,
                     fma(z2, fma(-z, 1.0 / 20922789888000, 1.0 / 87178291200),
                         fma(-z, 1.0 / 479001600, 1.0 / 3628800))),
             fma(z2, fma(-z, 1.0 / 40320, 1.0 / 720), fma(-z, 1.0 / 24, 0.5)))
    c3 = fma(z4, fma(z4, 1.0 / 121645100408832000,
                     fma(z2, fma(-z, 1.0 / 355687428096000, 1.0 / 1307674368000),
                         fma(-z, 1.0 / 6227020800, 1.0 / 39916800))),
             fma(z2, fma(-z, 1.0 / 362880, 1.0 / 5040), fma(-z, 1.0 / 120, 1.0 / 6)))
    return fma(-z, c2, 1.0), fma(-z, c3, 1.0), c2, c3


@njit(inline="always")
def stumpff_medium_lane(z):
    """:func:`_stumpff_short` without a branch for ``|z| <=
    _STUMPFF_MEDIUM_Z`` (the four-term and the nine-term series, each lane
    taking the one the scalar form takes), and whether ``z`` is there; a
    lane outside must take the scalar path."""
    e0, e1, e2, e3 = _estrin(z)
    m0, m1, m2, m3 = _estrin_medium(z)
    short = -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z
    inside = -_STUMPFF_MEDIUM_Z <= z <= _STUMPFF_MEDIUM_Z
    if short:
        return e0, e1, e2, e3, inside
    return m0, m1, m2, m3, inside


@njit(inline="always")
def stumpff_lane(z, general):
    """:func:`_stumpff_short` without a branch, for loops that LLVM turns into
    vector instructions (one orbit per lane), and whether ``z`` is in its
    domain (``|z| <= 4``; beyond it the caller must take the scalar path).
    ``general`` (the same for every lane) False: only the four-term series,
    valid when every lane has ``|z| <= _STUMPFF_SHORT_Z``.  Bit for bit
    :func:`_stumpff_short` inside the domain: the same operations, the
    branches of :func:`stumpff` taken as masked selects."""
    e0, e1, e2, e3 = _estrin(z)
    if not general:
        return e0, e1, e2, e3, True
    m0, m1, m2, m3 = _estrin_medium(z)
    # beyond the nine-term series, stumpff: quarter until |z| <= 0.1
    # (masked), the seven-term series there, and the quarter-argument
    # identities back
    zq = z
    n = 0
    for _ in range(_LANE_QUARTERINGS):
        big = abs(zq) > _STUMPFF_SERIES_Z
        zq = zq * 0.25 if big else zq
        n += 1 if big else 0
    c2 = (1.0 / 2 - zq * (1.0 / 24 - zq * (1.0 / 720 - zq * (1.0 / 40320 - zq * (
        1.0 / 3628800 - zq * (1.0 / 479001600 - zq * (1.0 / 87178291200)))))))
    c3 = (1.0 / 6 - zq * (1.0 / 120 - zq * (1.0 / 5040 - zq * (1.0 / 362880 - zq * (
        1.0 / 39916800 - zq * (1.0 / 6227020800 - zq * (1.0 / 1307674368000)))))))
    c0 = 1.0 - zq * c2
    c1 = 1.0 - zq * c3
    for k in range(_LANE_QUARTERINGS):
        up = k < n
        d3 = 0.25 * (c2 + c0 * c3)
        d2 = 0.5 * c1 * c1
        zu = zq * 4.0
        c3 = d3 if up else c3
        c2 = d2 if up else c2
        zq = zu if up else zq
        d0 = 1.0 - zq * c2
        d1 = 1.0 - zq * c3
        c0 = d0 if up else c0
        c1 = d1 if up else c1
    short = -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z
    medium = -_STUMPFF_MEDIUM_Z <= z <= _STUMPFF_MEDIUM_Z
    ok = not (z > _STUMPFF_DIRECT_Z or z < -_STUMPFF_DIRECT_Z)
    if short:
        return e0, e1, e2, e3, ok
    if medium:
        return m0, m1, m2, m3, ok
    return c0, c1, c2, c3, ok


# |z| below this: c4 and c5 from their series (to the z^8 term, whose
# successor is below 1e-17 of the sum for |z| < 1); above it from c2, c3,
# where (1/2 - c2) / z and (1/6 - c3) / z lose at most log2(12) bits.
_STUMPFF45_SERIES_Z = 1.0


@njit(inline="always")
def _stumpff45(z):
    """The next two Stumpff functions ``c4 = (1/2 - c2) / z``, ``c5 = (1/6 - c3) / z``
    (``1/24``, ``1/120`` at ``z = 0``), which the derivatives of ``G_2`` and
    ``G_3`` in ``beta`` need."""
    if -_STUMPFF45_SERIES_Z < z < _STUMPFF45_SERIES_Z:
        # c_k = sum_j (-z)^j / (k + 2j)!  (Horner)
        c4 = (1.0 / 24 - z * (1.0 / 720 - z * (1.0 / 40320 - z * (1.0 / 3628800 - z * (
            1.0 / 479001600 - z * (1.0 / 87178291200 - z * (1.0 / 20922789888000 - z * (
                1.0 / 6402373705728000 - z * (1.0 / 2432902008176640000)))))))))
        c5 = (1.0 / 120 - z * (1.0 / 5040 - z * (1.0 / 362880 - z * (1.0 / 39916800 - z * (
            1.0 / 6227020800 - z * (1.0 / 1307674368000 - z * (1.0 / 355687428096000 - z * (
                1.0 / 121645100408832000 - z * (1.0 / 51090942171709440000)))))))))
        return c4, c5
    c0, c1, c2, c3 = stumpff(z)
    return (0.5 - c2) / z, (_SIXTH - c3) / z


@njit(inline="always")
def _stumpff45_short(z):
    """:func:`_stumpff45` for the short steps of a planetary integration:
    four terms of each series for ``|z| <= _STUMPFF_SHORT_Z`` (the first
    omitted, ``z^4 / 12!``, below 1e-18 of ``c4``), in Estrin's form."""
    if -_STUMPFF_SHORT_Z <= z <= _STUMPFF_SHORT_Z:
        z2 = z * z
        c4 = (1.0 / 24 - z * (1.0 / 720)) + z2 * ((1.0 / 40320) - z * (1.0 / 3628800))
        c5 = (1.0 / 120 - z * (1.0 / 5040)) + z2 * ((1.0 / 362880) - z * (1.0 / 39916800))
        return c4, c5
    return _stumpff45(z)

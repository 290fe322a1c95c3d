"""Laskar's numerical analysis of fundamental frequencies (NAFF) of an evenly
sampled signal: :func:`frequencies` and the steps of the algorithm."""

import math
import warnings

import astropy.units as u
import numpy as np

from ..errors import OrbitsWarning
from ._sampling import as_plain, sampling_interval, whole_number, wrap_angle
from .decomposition import Frequencies

__all__ = ["frequencies", "SPACING_RTOL"]

#: Largest spread of the sampling intervals, relative to their mean, that
#: counts as even: the rounding of times ``t0 + k dt`` stays below 2e-9 of
#: ``dt`` up to 1e7 outputs, while outputs that snap to the steps of a
#: fixed-step run vary by a whole step, 1 / (steps per output) of ``dt``.
SPACING_RTOL = 1e-8

# The coarse peak comes from an FFT zero-padded to this many times the
# signal's length, so that it lies within an eighth of a resolution element
# 2 pi / T of the refined one and the refinement starts on the right lobe.
_PADDING = 4

# A term whose residual would be this far below the signal (weighted rms) is
# rounding: the decomposition stops there.
_RESIDUAL_FLOOR = 1e-13

# A new basis function whose part independent of those already found is
# smaller than this (weighted norm, of one) is a frequency NAFF cannot tell
# apart from one it has; adding it would divide by rounding.
_MIN_INDEPENDENCE = 1e-6

# After each new term, every frequency found is searched for again with all
# the other terms subtracted, at most _CORRECTIONS times: the error
# of each then comes from the errors of the others, not from their whole
# leakage, and falls geometrically (by 1e2 a pass for terms 3 resolution
# elements 2 pi / T apart, by 2 for terms 1.6 apart).  It stops when no
# frequency moves by more than _CORRECTED of 2 pi / T, or when the residual
# (the terms not fitted, in a signal that has more than n) shrinks by less
# than _STALLED of itself.
_CORRECTIONS = 50
_CORRECTED = 1e-11
_STALLED = 1e-6

_MAX_NEWTON = 100          # iterations of the safeguarded Newton refinement
_MAX_BRACKET = 64          # widenings (by one padded bin) to bracket the peak


def frequencies(times, signal, n=5, window=1):
    """Frequencies, amplitudes and phases of a quasi-periodic signal (NAFF).

    Finds the ``n`` terms of largest amplitude in ``f(t) = sum_k a_k exp(i
    nu_k t)`` one after the other: each frequency is the maximum of the
    windowed projection of what the terms already found leave, and the
    amplitudes are the projection of the signal on the span of the terms
    found.

    Parameters
    ----------
    times : Quantity or array_like, shape (N,)
        Evenly spaced, increasing (``N >= 8``).  A Quantity of any unit: the
        frequencies are then in rad per that unit.
    signal : Quantity or array_like, shape (N,)
        Complex (``h + i k``, ``p + i q``, ``exp(i theta)``) or real.
    n : int
        Number of terms wanted, at most ``N // 2`` (``N // 4`` for a real
        signal, whose terms each take a pair of frequencies ``+nu`` and
        ``-nu``).  Fewer come back, with an
        :class:`~orbits.errors.OrbitsWarning`, where the rest of the signal
        is rounding or its next frequency cannot be told apart from one
        already found.
    window : int
        Exponent ``p`` of the window ``(1 + cos(2 pi (t - t_mid) / T))**p``
        over the span ``T`` of the times: 1 (default) is Hanning's; 0 is no
        window (the error of each frequency then goes as ``1/T**2``, not
        ``1/T**4``); larger ``p`` suppress distant terms better at the cost
        of a wider peak.

    Returns
    -------
    Frequencies
        ``frequencies`` (``nu_k``), ``amplitudes`` (``A_k >= 0``) and
        ``phases`` (``phi_k``, at ``t = 0`` of ``times``) in order of
        decreasing amplitude, and ``periods``.  For a complex signal
        ``f(t) ~ sum_k A_k exp(i (nu_k t + phi_k))``, frequencies of either
        sign.  For a real one ``f(t) ~ sum_k A_k cos(nu_k t + phi_k)`` with
        ``nu_k >= 0`` (a constant part is a term with ``nu = 0``).

    Raises
    ------
    ValueError
        ``times`` is not one-dimensional, increasing and evenly spaced (to
        :data:`~orbits.analysis.naff.SPACING_RTOL`), or not of the length of ``signal``; either is
        not finite; ``n`` or ``window`` is not a whole number in range.

    Notes
    -----
    With the inner product ``<f, g> = sum_j w_j f(t_j) conj(g(t_j)) / sum_j
    w_j`` and the window weights ``w_j``, each step

    1. takes the residual ``r = f - P f``, where ``P`` projects on the span
       of ``exp(i nu_1 t), ..., exp(i nu_{k-1} t)``;
    2. finds the peak of ``|FFT(w r)|`` (zero-padded ``4x``) and refines it
       to the maximum of ``|<r, exp(i nu t)>|``, a root of its derivative
       found by Newton's method kept inside a bracket;
    3. orthonormalises ``exp(i nu_k t)`` against the basis found so far by
       (modified) Gram–Schmidt, and projects ``f`` on the new basis;
    4. searches for each frequency found so far again, with all the other
       terms subtracted, until none moves by more than ``1e-11`` of the
       resolution ``2 pi / T`` (or the fit stops improving).

    The amplitudes of the original, non-orthogonal terms follow from the
    triangular change of basis.  The peak of an FFT is off by up to half a
    resolution element; the maximum of the windowed projection is off only
    by the leakage of the other terms, which falls as ``1/T**(2p + 2)``:
    ``1/T**4`` for Hanning's window (Laskar 2003).  The orthogonalisation
    keeps close frequencies from pulling on each other's amplitudes.  Step 4
    (as the frequency-modified Fourier transform of Šidlichovský & Nesvorný
    1996 corrects frequencies) leaves only the other terms' errors to leak
    into each: a signal that is exactly a sum of terms gives its frequencies
    to rounding (1e-15 relative for terms three resolution elements apart,
    1e-12 for terms one apart), and the next term is looked for in a
    residual that is rounding once all are found.  A real signal is analysed
    as complex, each term adding the pair ``exp(+-i nu t)`` to the basis.

    References
    ----------
    .. [1] Laskar, J. 1990, "The chaotic motion of the solar system: a
       numerical estimate of the size of the chaotic zones", Icarus 88, 266.
    .. [2] Laskar, J. 2003, "Frequency map analysis and quasi periodic
       decompositions", in *Hamiltonian Systems and Fourier Analysis*,
       Benest et al. (eds.), arXiv:math/0305364.
    .. [3] Šidlichovský, M. & Nesvorný, D. 1996, "Frequency modified Fourier
       transform and its application to asteroids", Celest. Mech. Dyn.
       Astron. 65, 137.

    Examples
    --------
    >>> from orbits.analysis import frequencies
    >>> t = np.linspace(0, 1e5, 10001) * u.yr
    >>> x = t.to_value(u.yr)
    >>> z = 0.04 * np.exp(2e-5j * x + 0.3j) + 0.015 * np.exp(1.4e-4j * x - 1j)
    >>> fa = frequencies(t, z, n=2)
    >>> fa.frequencies.to(u.rad / u.yr).round(14)
    <Quantity [2.0e-05, 1.4e-04] rad / yr>
    >>> fa.amplitudes.round(10), fa.phases.round(10)
    (array([0.04 , 0.015]), <Quantity [ 0.3, -1. ] rad>)
    """
    t, t_unit = as_plain(times, "times")
    f, f_unit = as_plain(signal, "signal")
    if t.ndim != 1 or f.ndim != 1 or len(t) != len(f):
        raise ValueError(f"times and signal must be one-dimensional and of the same "
                         f"length; got shapes {t.shape} and {f.shape}")
    N = len(t)
    if N < 8:
        raise ValueError(f"times: a frequency analysis needs at least 8 samples, got {N}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
        raise ValueError("times and signal must be finite")
    dt = sampling_interval(t, SPACING_RTOL)
    real = not np.iscomplexobj(f)
    limit = N // 4 if real else N // 2
    n = whole_number(n, "n", 1, limit, f" (at most N // {4 if real else 2} = {limit} terms "
               f"from N = {N} samples of a {'real' if real else 'complex'} signal)")
    p = whole_number(window, "window", 0, None, "")

    nus, amps = _naff(f.astype(complex), dt, n, p, real)
    # phases at t = 0 of the times given; the analysis used t - t_mid
    t_mid = 0.5 * (t[0] + t[-1])
    if real:
        # a term less than a resolution element from zero frequency may have
        # been refined to just below it: cos(-nu t + phi) is cos(nu t - phi)
        below = nus < 0
        nus[below], amps[below] = -nus[below], np.conj(amps[below])
        A = 2 * np.abs(amps)
        A[nus == 0] /= 2
    else:
        A = np.abs(amps)
    phi = wrap_angle(np.angle(amps) - nus * t_mid)
    order = np.argsort(-A, kind="stable")
    nus, A, phi = nus[order], A[order], phi[order]
    if t_unit is not None:
        nus = nus << u.rad / t_unit
        phi = phi << u.rad
    if f_unit is not None:
        A = A << f_unit
    return Frequencies(nus, A, phi, real)


def _naff(f, dt, n, p, real):
    """Frequencies (internal unit, rad per unit of ``dt``) and complex amplitudes about t_mid."""
    N = len(f)
    tau = (np.arange(N) - 0.5 * (N - 1)) * dt        # symmetric about the middle
    span = (N - 1) * dt
    w = (1.0 + np.cos(2 * math.pi * tau / span)) ** p if p else np.ones(N)
    w = w / w.sum()
    M = 1 << int(math.ceil(math.log2(_PADDING * N)))
    bin_width = 2 * math.pi / (M * dt)

    norm_f = _norm(f, w)
    terms, columns = [], []       # one frequency per term; +-nu per term of a real signal
    a = np.zeros(0, dtype=complex)
    residual, misfit = f, norm_f
    why = None
    for _ in range(n):
        if misfit <= _RESIDUAL_FLOOR * norm_f:
            why = "the rest of the signal is rounding"
            break
        nu = _peak(residual * w, tau, M, bin_width, real)
        new_columns = columns + _pair(nu, real)
        new_a, independence, new_misfit, new_residual = _amplitudes(f, new_columns, tau, w)
        if independence < _MIN_INDEPENDENCE:
            why = (f"the next frequency ({nu:.10g}) cannot be told apart from those "
                   f"already found")
            break
        terms, columns, a, misfit, residual = ([*terms, nu], new_columns, new_a, new_misfit,
                                               new_residual)
        terms, columns, a, misfit, residual = _corrected(f, terms, columns, a, misfit,
                                                         residual, tau, w, bin_width, real)
    if why is not None:
        warnings.warn(f"found {len(terms)} of the {n} terms asked for: {why}",
                      OrbitsWarning, stacklevel=3)
    nus = np.array(terms, dtype=float)
    amps = np.empty(len(terms), dtype=complex)
    col = 0
    for k, nu in enumerate(terms):
        if real and nu != 0:
            # a exp(i nu t) + b exp(-i nu t), b = conj(a) up to rounding
            amps[k] = 0.5 * (a[col] + np.conj(a[col + 1]))
            col += 2
        else:
            amps[k] = a[col]
            col += 1
    return nus, amps


def _pair(nu, real):
    """The basis frequencies of one term."""
    return [nu] if (not real or nu == 0) else [nu, -nu]


def _corrected(f, terms, columns, a, misfit, residual, tau, w, h, real):
    """The terms after up to ``_CORRECTIONS`` passes of :func:`_correct`."""
    for _ in range(_CORRECTIONS):
        new_terms, changed = _correct(f, terms, columns, a, tau, w, h, real)
        new_columns = [c for nu in new_terms for c in _pair(nu, real)]
        new_a, independence, new_misfit, new_residual = _amplitudes(f, new_columns, tau, w)
        if independence < _MIN_INDEPENDENCE or not new_misfit <= misfit:
            break           # the corrections stopped helping: keep the last good terms
        stalled = new_misfit > (1 - _STALLED) * misfit
        terms, columns, a, misfit, residual = (new_terms, new_columns, new_a, new_misfit,
                                               new_residual)
        if changed <= _CORRECTED or stalled:
            break
    return terms, columns, a, misfit, residual


def _correct(f, terms, columns, a, tau, w, h, real):
    """Each frequency searched for again with all the other terms subtracted.

    Returns the new frequencies and the largest change, relative to the
    resolution ``2 pi / T``.
    """
    model = np.exp(1j * np.outer(tau, columns)) * a
    rest = f - model.sum(axis=1)
    span = tau[-1] - tau[0]
    largest = 0.0
    col = 0
    new_terms = []
    for nu in terms:
        if real and nu == 0:
            new = nu
        else:
            # the term's own exp(+i nu t) stays in; its exp(-i nu t) image, if any, goes
            new = _refine((rest + model[:, col]) * w, tau, nu, h / _PADDING, False)
            largest = max(largest, abs(new - nu) * span / (2 * math.pi))
        col += len(_pair(nu, real))
        new_terms.append(new)
    return new_terms, largest


def _amplitudes(f, columns, tau, w):
    """The projection of ``f`` on ``exp(i nu tau)`` for the given frequencies.

    Returns the amplitudes of those functions (by modified Gram–Schmidt and
    the triangular change of basis), the smallest norm of a function's part
    independent of those before it, and the residual and its norm.
    """
    basis, R, coeffs = [], np.zeros((0, 0), dtype=complex), []
    residual = f
    smallest = 1.0
    for nu in columns:
        basis, R, independence = _orthonormalise(np.exp(1j * nu * tau), basis, R, w)
        smallest = min(smallest, independence)
        if independence == 0:
            return None, 0.0, math.inf, None
        c = _dot(residual, basis[-1], w)
        residual = residual - c * basis[-1]
        coeffs.append(c)
    return _back_substitute(R, np.array(coeffs)), smallest, _norm(residual, w), residual


def _norm(x, w):
    return math.sqrt(max(_dot(x, x, w).real, 0.0))


def _dot(x, y, w):
    """The windowed inner product ``sum w x conj(y)`` (``w`` sums to one)."""
    return np.sum(w * x * np.conj(y))


def _orthonormalise(e, basis, R, w):
    """Add ``e`` to an orthonormal basis by modified Gram–Schmidt.

    Returns the longer basis, ``R`` grown by one column (``e_k = sum_j R[j, k] q_j``),
    and the norm of the part of ``e`` independent of the basis (``|e| = 1``).
    """
    k = len(basis)
    R_new = np.zeros((k + 1, k + 1), dtype=complex)
    R_new[:k, :k] = R
    v = e.astype(complex)
    for j, q in enumerate(basis):
        c = _dot(v, q, w)
        R_new[j, k] = c
        v = v - c * q
    norm = math.sqrt(max(_dot(v, v, w).real, 0.0))
    R_new[k, k] = norm
    if norm > 0:
        v = v / norm
    return [*basis, v], R_new, norm


def _back_substitute(R, c):
    """Solve the upper-triangular ``R a = c``."""
    a = np.zeros(len(c), dtype=complex)
    for i in range(len(c) - 1, -1, -1):
        a[i] = (c[i] - R[i, i + 1:] @ a[i + 1:]) / R[i, i]
    return a


def _peak(rw, tau, M, bin_width, real):
    """The frequency at which ``|<r, exp(i nu tau)>|`` is largest, ``rw = w r``."""
    spectrum = np.abs(np.fft.fft(rw, M))
    if real:
        half = M // 2 + 1
        m = int(np.argmax(spectrum[:half]))
        if m == 0:
            return 0.0
    else:
        m = int(np.argmax(spectrum))
        if m >= M // 2:
            m -= M
    return _refine(rw, tau, m * bin_width, bin_width, real)


def _slope(rw, tau, nu):
    """``phi = d/dnu |A|^2 / 2`` and ``dphi/dnu`` for ``A(nu) = sum rw exp(-i nu tau)``.

    The FFT's ``exp(-i nu j dt)`` and this ``exp(-i nu tau)`` differ by a
    phase only, which leaves ``|A|`` as it is.
    """
    z = rw * np.exp(-1j * nu * tau)
    zt = z * tau
    s0 = z.sum()
    s1 = -1j * zt.sum()
    s2 = -(zt * tau).sum()
    phi = (np.conj(s0) * s1).real
    dphi = abs(s1) ** 2 + (np.conj(s0) * s2).real
    return phi, dphi


def _refine(rw, tau, nu0, h, real):
    """Maximum of ``|A(nu)|`` near ``nu0``: a root of its derivative, by Newton in a bracket."""
    lo, hi = nu0 - h, nu0 + h
    if real:
        lo = max(lo, 0.0)
    phi_lo = _slope(rw, tau, lo)[0]
    for _ in range(_MAX_BRACKET):
        if phi_lo > 0 or (real and lo == 0.0):
            break
        lo -= h
        phi_lo = _slope(rw, tau, lo)[0]
    phi_hi = _slope(rw, tau, hi)[0]
    for _ in range(_MAX_BRACKET):
        if phi_hi < 0:
            break
        hi += h
        phi_hi = _slope(rw, tau, hi)[0]
    if not (phi_lo >= 0 >= phi_hi):
        return nu0          # no peak found near the coarse one: keep it
    x = min(max(nu0, lo), hi)
    tol = 4 * np.finfo(float).eps * max(abs(lo), abs(hi), 1.0 / (tau[-1] - tau[0]))
    for _ in range(_MAX_NEWTON):
        phi, dphi = _slope(rw, tau, x)
        if phi > 0:
            lo = x
        elif phi < 0:
            hi = x
        else:
            return x
        if dphi < 0:            # concave: Newton's step goes towards the maximum
            step = -phi / dphi
            if lo <= x + step <= hi:
                x += step
                if abs(step) <= tol:
                    return x
                continue
        x = 0.5 * (lo + hi)     # otherwise bisect the bracket
        if hi - lo <= tol:
            return x
    return x

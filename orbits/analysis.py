"""Frequency analysis of quasi-periodic signals and of planetary runs.

:func:`frequencies` is Laskar's numerical analysis of fundamental
frequencies (NAFF): it writes an evenly sampled signal, complex (``h + i k``,
``p + i q``) or real, as a sum of terms ``A exp(i (nu t + phi))`` and finds
the frequencies ``nu`` far more precisely than the peaks of a Fourier
transform.  :func:`secular_frequencies` applies it to a body's eccentricity
and inclination variables in a :class:`~orbits.Result` (the ``g`` and ``s``
frequencies of secular theory), and :func:`mean_motion_frequencies` to its
mean longitude or to a combination of mean longitudes, such as the great
inequality ``2 lambda_J - 5 lambda_S`` of Jupiter and Saturn.
"""

import copy as _copy
import dataclasses
import math
import numbers
import warnings

import astropy.units as u
import numpy as np

from .errors import BodyError, OrbitsWarning

__all__ = ["Frequencies", "SecularFrequencies", "frequencies", "secular_frequencies",
           "mean_motion_frequencies", "SPACING_RTOL", "PLANES"]

#: Largest spread of the sampling intervals, relative to their mean, that
#: counts as even: the rounding of times ``t0 + k dt`` stays below 2e-9 of
#: ``dt`` up to 1e7 outputs, while outputs that snap to the steps of a
#: fixed-step run vary by a whole step, 1 / (steps per output) of ``dt``.
SPACING_RTOL = 1e-8

#: Reference planes of :func:`secular_frequencies` and :func:`mean_motion_frequencies`.
PLANES = ("invariable", "run")

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


@dataclasses.dataclass(frozen=True, repr=False)
class Frequencies:
    """A quasi-periodic decomposition: what :func:`frequencies` returns.

    For a complex signal ``f(t) ~ sum_k A_k exp(i (nu_k t + phi_k))``; for a
    real one ``f(t) ~ sum_k A_k cos(nu_k t + phi_k)`` with ``nu_k >= 0``.
    Terms are in order of decreasing amplitude.

    Attributes
    ----------
    frequencies : Quantity or ndarray, shape (n,)
        Angular frequencies ``nu_k``: rad per the unit of the times when they
        were a Quantity, plain floats (rad per unit of time) otherwise.
    amplitudes : Quantity or ndarray, shape (n,)
        ``A_k >= 0``, in the unit of the signal.
    phases : Quantity or ndarray, shape (n,)
        ``phi_k`` in (-pi, pi], at time zero of the times given (rad).
    real : bool
        Whether the signal was real (cosine terms, frequencies >= 0).

    Examples
    --------
    >>> import numpy as np
    >>> from orbits.analysis import frequencies
    >>> t = np.arange(2000) * 0.5
    >>> fa = frequencies(t, 2 * np.cos(0.3 * t + 1), n=1)
    >>> len(fa), fa.real, round(float(fa.frequencies[0]), 12)
    (1, True, 0.3)
    >>> fa.evaluate(t[:2]).round(6)
    array([1.080605, 0.816975])
    """

    frequencies: object
    amplitudes: object
    phases: object
    real: bool

    def __len__(self):
        return len(self.frequencies)

    @property
    def periods(self):
        """``2 pi / |nu_k|``, shape (n,), in the unit of the times (inf for ``nu = 0``).

        Examples
        --------
        >>> import astropy.units as u
        >>> import numpy as np
        >>> from orbits.analysis import frequencies
        >>> t = np.arange(1000) * u.yr
        >>> frequencies(t, np.exp(-2j * np.pi * t.value / 50), n=1).periods.round(9)
        <Quantity [50.] yr>
        """
        nu = self.frequencies
        with np.errstate(divide="ignore"):
            if isinstance(nu, u.Quantity):
                return (2 * math.pi * u.rad / np.abs(nu)).to(1 / (nu.unit / u.rad))
            return 2 * math.pi / np.abs(nu)

    def evaluate(self, times):
        """The decomposition's sum at the given times.

        Parameters
        ----------
        times : Quantity or array_like, shape (m,)
            In a unit of the kind the frequencies are per (plain floats if
            the frequencies are).

        Returns
        -------
        Quantity or ndarray, shape (m,)
            Complex for a complex signal, real for a real one, in the unit of
            the amplitudes.

        Examples
        --------
        >>> import numpy as np
        >>> from orbits.analysis import frequencies
        >>> t = np.linspace(0, 100, 1001)
        >>> f = np.exp(1.5j * t) + 0.1 * np.exp(-0.4j * t)
        >>> fa = frequencies(t, f, n=2)
        >>> bool(np.abs(fa.evaluate(t) - f).max() < 1e-10)
        True
        """
        nu, phi, amp = self.frequencies, self.phases, self.amplitudes
        if isinstance(nu, u.Quantity):
            t = u.Quantity(times).to_value(u.rad / nu.unit)
            nu = nu.value
        else:
            t = np.asarray(times, dtype=float)
        phi = phi.to_value(u.rad) if isinstance(phi, u.Quantity) else np.asarray(phi)
        unit = amp.unit if isinstance(amp, u.Quantity) else None
        a = amp.value if unit is not None else np.asarray(amp)
        arg = np.outer(np.atleast_1d(t), nu) + phi
        out = (np.cos(arg) @ a) if self.real else (np.exp(1j * arg) @ a)
        out = out.reshape(np.shape(t))
        return out if unit is None else out << unit

    def __repr__(self):
        nu = self.frequencies
        funit = f" [{nu.unit}]" if isinstance(nu, u.Quantity) else ""
        periods = self.periods
        punit = f" [{periods.unit}]" if isinstance(periods, u.Quantity) else ""
        amp = self.amplitudes
        aunit = f" [{amp.unit}]" if isinstance(amp, u.Quantity) and str(amp.unit) else ""
        kind = "real" if self.real else "complex"
        lines = [f"<Frequencies: {len(self)} term{'' if len(self) == 1 else 's'} of a "
                 f"{kind} signal",
                 f"{'':>4}{'frequency' + funit:>26}{'period' + punit:>20}"
                 f"{'amplitude' + aunit:>16}{'phase [rad]':>14}"]
        for k in range(len(self)):
            lines.append(f"{k:>4}{_value(nu[k]):>26.14g}{_value(periods[k]):>20.10g}"
                         f"{_value(amp[k]):>16.8g}{_value(self.phases[k]):>14.8f}")
        return "\n".join(lines) + ">"


@dataclasses.dataclass(frozen=True, repr=False)
class SecularFrequencies:
    """What :func:`secular_frequencies` returns: the decompositions of a body's
    eccentricity and inclination variables.

    Attributes
    ----------
    g : Frequencies
        Of ``z = e exp(i varpi)`` (``k + i h``): its leading frequency is the
        body's own ``g`` mode (``g5`` for Jupiter, ``g6`` for Saturn).
    s : Frequencies
        Of ``zeta = sin(inc/2) exp(i Omega)`` (``q + i p``): its leading
        frequency is the body's ``s`` mode (``s6`` for Jupiter and Saturn).
    body, primary, plane : str
        What they were computed for: the body, the body its elements are
        about, and the reference plane (``"invariable"`` or ``"run"``).

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.analysis import secular_frequencies
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=146.1 * u.day)
    >>> result = sim.run(until=1e5 * u.yr, outputs=501, progress=False)
    >>> sf = secular_frequencies(result, "Jupiter", n=2)
    >>> sf.body, sf.primary, sf.plane, len(sf.g), len(sf.s)
    ('Jupiter', 'Sun', 'invariable', 2, 2)
    """

    g: Frequencies
    s: Frequencies
    body: str
    primary: str
    plane: str

    def __repr__(self):
        def lead(fa):
            if not len(fa):
                return "none"
            nu = fa.frequencies[:3]
            if isinstance(nu, u.Quantity) and nu.unit.is_equivalent(u.rad / u.s):
                return ", ".join(f"{v:.6g}" for v in nu.to_value(u.arcsec / u.yr)) + " arcsec / yr"
            return ", ".join(f"{_value(v):.6g}" for v in nu)
        return (f"<SecularFrequencies of {self.body} about {self.primary}, {self.plane} "
                f"plane: g {lead(self.g)}; s {lead(self.s)}>")


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
        :data:`SPACING_RTOL`), or not of the length of ``signal``; either is
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
    >>> import astropy.units as u
    >>> import numpy as np
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
    t, t_unit = _plain(times, "times")
    f, f_unit = _plain(signal, "signal")
    if t.ndim != 1 or f.ndim != 1 or len(t) != len(f):
        raise ValueError(f"times and signal must be one-dimensional and of the same "
                         f"length; got shapes {t.shape} and {f.shape}")
    N = len(t)
    if N < 8:
        raise ValueError(f"times: a frequency analysis needs at least 8 samples, got {N}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
        raise ValueError("times and signal must be finite")
    dt = _spacing(t)
    real = not np.iscomplexobj(f)
    limit = N // 4 if real else N // 2
    n = _whole(n, "n", 1, limit, f" (at most N // {4 if real else 2} = {limit} terms "
               f"from N = {N} samples of a {'real' if real else 'complex'} signal)")
    p = _whole(window, "window", 0, None, "")

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
    phi = _wrap(np.angle(amps) - nus * t_mid)
    order = np.argsort(-A, kind="stable")
    nus, A, phi = nus[order], A[order], phi[order]
    if t_unit is not None:
        nus = nus << u.rad / t_unit
        phi = phi << u.rad
    if f_unit is not None:
        A = A << f_unit
    return Frequencies(nus, A, phi, real)


def secular_frequencies(result, body, n=10, primary=None, plane="invariable", window=1):
    """The secular frequencies of a body in a run: ``g`` of its perihelion, ``s`` of its node.

    Frequency analysis (:func:`frequencies`) of the body's eccentricity and
    inclination variables at the run's outputs:
    ``z = e exp(i varpi) = k + i h`` and
    ``zeta = sin(inc/2) exp(i Omega) = q + i p``, with
    ``varpi = Omega + omega``, from osculating heliocentric elements.

    Parameters
    ----------
    result : Result
        A run with evenly spaced outputs (a fixed-step run: choose ``dt`` so
        that the interval between outputs is a whole number of steps).  The
        outputs must be dense enough for the frequencies sought (at least two
        per period) and the run long enough to separate them: the resolution
        is ``2 pi / T`` and NAFF does far better than that only for terms
        several resolution elements apart.
    body : str
        The body's name.
    n : int
        Terms wanted in each decomposition.
    primary : str, optional
        The body the elements are about.  Default: the most massive body
        (heliocentric elements).
    plane : {"invariable", "run"}
        Reference plane of the angles: ``"invariable"`` (default), the plane
        normal to the total angular momentum at the first output, with ``x``
        along its ascending node on the run's ``xy`` plane; or ``"run"``, the
        run's own ``xy`` plane.  Frequencies do not depend on a fixed plane,
        but in a plane tilted to the invariable one (the equatorial frame of
        :func:`orbits.scenes.outer_solar_system`, 23 degrees) ``zeta`` is
        dominated by the constant tilt and each mode appears at both ``+s``
        and ``-s``.
    window : int
        As for :func:`frequencies`.

    Returns
    -------
    SecularFrequencies
        ``g`` and ``s``, each a :class:`Frequencies` with frequencies in rad
        per the unit of ``result.times`` (convert with
        ``.to(u.arcsec / u.yr)``).

    Raises
    ------
    UnknownBodyError, BodyError, ElementsError
        As :meth:`orbits.Result.elements` raises them; BodyError also where
        ``body`` is the most massive body and no ``primary`` is named.
    ValueError
        The outputs are not evenly spaced; ``plane`` is not one of
        :data:`PLANES`; as :func:`frequencies` raises it.

    Notes
    -----
    For the Sun, Jupiter and Saturn alone, Lagrange–Laplace secular theory
    gives ``z_J = a_55 exp(i g5 t) + a_56 exp(i g6 t)``: Jupiter's ``z`` is
    dominated by ``g5``, Saturn's by ``g6``; both ``zeta`` are dominated by
    ``s6`` (the other inclination mode, ``s5 = 0``, is the invariable plane,
    and has no amplitude in it).  Laskar et al. (2004, table 3) give
    ``g5 = 4.257``, ``g6 = 28.245`` and ``s6 = -26.348`` arcsec/yr for the
    solar system.  The scene :func:`orbits.scenes.outer_solar_system` gives
    4.2426, 28.278 and -26.328 over 10 Myr (4.2412, 28.277, -26.323 over 1
    Myr): a model of the giant planets alone, with initial conditions that
    put Saturn's mean motion 5e-5 below the mean one (see
    :func:`mean_motion_frequencies`) and without the inner planets'
    quadrupole and relativity, which add about 0.013 arcsec/yr to ``g5``.

    References
    ----------
    .. [1] Laskar, J. 1990, Icarus 88, 266.
    .. [2] Laskar, J., Robutel, P., Joutel, F., Gastineau, M., Correia, A. C.
       M. & Levrard, B. 2004, "A long-term numerical solution for the
       insolation quantities of the Earth", A&A 428, 261.
    .. [3] Murray, C. D. & Dermott, S. F. 1999, *Solar System Dynamics*,
       chapter 7.

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.analysis import secular_frequencies
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=146.1 * u.day)
    >>> result = sim.run(until=2e5 * u.yr, outputs=1001, progress=False)   # every 200 yr
    >>> sf = secular_frequencies(result, "Saturn", n=4)
    >>> sf.g.frequencies[0].to(u.arcsec / u.yr).round(1)      # g6
    <Quantity 28.3 arcsec / yr>
    >>> sf.s.frequencies[0].to(u.arcsec / u.yr).round(1)      # s6
    <Quantity -26.3 arcsec / yr>
    """
    _check_outputs(result.times)
    el, primary = _elements(result, body, primary, plane)
    e = el["e"].to_value(u.one)
    inc = el["inc"].to_value(u.rad)
    node = el["Omega"].to_value(u.rad)
    varpi = node + el["omega"].to_value(u.rad)
    z = e * np.exp(1j * varpi)
    zeta = np.sin(inc / 2) * np.exp(1j * node)
    times = result.times
    return SecularFrequencies(g=frequencies(times, z, n=n, window=window),
                              s=frequencies(times, zeta, n=n, window=window),
                              body=body, primary=primary, plane=plane)


def mean_motion_frequencies(result, bodies, n=5, primary=None, plane="invariable", window=1):
    """Frequencies of a body's mean longitude, or of a combination of mean longitudes.

    Frequency analysis (:func:`frequencies`) of ``exp(i theta)`` with
    ``theta = sum_b k_b lambda_b`` and the mean longitudes
    ``lambda = Omega + omega + M`` of osculating heliocentric elements.  The
    leading frequency is the combination's mean rate ``sum_b k_b n_b``: the
    mean motion of one body, or the frequency of a near commensurability,
    such as the great inequality of Jupiter and Saturn,
    ``2 n_J - 5 n_S`` (``bodies={"Jupiter": 2, "Saturn": -5}``).

    The signal is ``exp(i theta)`` rather than ``theta`` itself, or a
    semi-major axis, because it needs no unwrapping of angles that turn many
    times between outputs, and because its leading term has amplitude one
    whatever the run's short-period terms: outputs need sample only the
    combination's own period, not the orbits (880 yr for the great
    inequality, not Jupiter's 12 yr).  Terms faster than half the output
    rate are aliased, as in any sampled signal.

    Parameters
    ----------
    result : Result
        A run with evenly spaced outputs, at least two per period of the
        combination.
    bodies : str or dict of str to int
        A body's name (its mean motion), or bodies and the whole numbers
        they multiply.
    n : int
        Terms wanted.
    primary, plane, window
        As for :func:`secular_frequencies`.

    Returns
    -------
    Frequencies
        Of ``exp(i theta)``; frequencies in rad per the unit of
        ``result.times``.  ``periods[0]`` is the combination's period.

    Raises
    ------
    UnknownBodyError, BodyError, ElementsError
        As :meth:`orbits.Result.elements` raises them.
    ValueError
        A coefficient is not a whole number, ``bodies`` is empty, or as
        :func:`secular_frequencies` raises it.

    Notes
    -----
    Newcomb's mean motions, ``n_J = 30.349043`` and ``n_S = 12.221133``
    degrees per year (as tabulated in the *Encyclopaedia Britannica*, 11th
    edition, 1911), give ``5 n_S - 2 n_J = 0.40758`` degrees per year: a
    great inequality of 883.3 years.  The scene
    :func:`orbits.scenes.outer_solar_system` gives 891.2 years: its initial
    conditions put Saturn's mean motion 5e-5 below Newcomb's, and the near
    commensurability amplifies that 150 times; the same model started from
    DE421's states gives 885.0 years.

    Examples
    --------
    >>> import astropy.units as u
    >>> import orbits
    >>> from orbits.analysis import mean_motion_frequencies
    >>> sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "wh", dt=146.1 * u.day)
    >>> result = sim.run(until=2e5 * u.yr, outputs=1001, progress=False)   # every 200 yr
    >>> gi = mean_motion_frequencies(result, {"Jupiter": 2, "Saturn": -5}, n=3)
    >>> gi.periods[0].to(u.yr).round(0)
    <Quantity 891. yr>
    >>> float(gi.amplitudes[0].round(2))
    0.97
    """
    _check_outputs(result.times)
    if isinstance(bodies, str):
        bodies = {bodies: 1}
    if not bodies:
        raise ValueError("bodies: expected a body's name or a dict of names to whole "
                         "numbers, got an empty dict")
    theta = 0.0
    for name, k in dict(bodies).items():
        if (isinstance(k, bool) or not isinstance(k, numbers.Integral)) and not (
                isinstance(k, numbers.Real) and float(k).is_integer()):
            raise ValueError(f"bodies: the coefficient of {name!r} must be a whole number, "
                             f"got {k!r}")
        if int(k) == 0:
            continue
        el, _ = _elements(result, name, primary, plane)
        lam = sum(el[key].to_value(u.rad) for key in ("Omega", "omega", "M"))
        theta = theta + int(k) * lam
    if np.isscalar(theta):
        raise ValueError(f"bodies: expected at least one non-zero coefficient, got {bodies!r}")
    signal = np.exp(1j * theta)
    return frequencies(result.times, signal, n=n, window=window)


# -- the algorithm ---------------------------------------------------------------------
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


# -- helpers ---------------------------------------------------------------------------
def _plain(q, name):
    """Plain values and unit (None when not a Quantity)."""
    if isinstance(q, u.Quantity):
        return np.asarray(q.value), q.unit
    try:
        return np.asarray(q), None
    except Exception as exc:            # pragma: no cover - np.asarray takes nearly anything
        raise ValueError(f"{name}: expected an array, got {q!r}") from exc


def _spacing(t, hint=""):
    """The sampling interval of evenly spaced ``t``; a ValueError otherwise
    (``hint``, on how to space them evenly, ends the message of uneven ones)."""
    d = np.diff(t.astype(float))
    mean = (t[-1] - t[0]) / (len(t) - 1)
    if np.any(d <= 0):
        k = int(np.argmax(d <= 0))
        raise ValueError(f"times: expected increasing times; times[{k + 1}] = {t[k + 1]:.10g} "
                         f"is not after times[{k}] = {t[k]:.10g}")
    if not mean > 0:
        raise ValueError("times: expected increasing times")
    spread = float(np.max(np.abs(d - mean))) / mean
    if spread > SPACING_RTOL:
        k = int(np.argmax(np.abs(d - mean)))
        raise ValueError(f"times: expected evenly spaced times (to {SPACING_RTOL:g} of the "
                         f"interval); interval {k} is {d[k]:.10g} against a mean of "
                         f"{mean:.10g} (relative difference {spread:.3g}){hint}")
    return float(mean)


def _whole(value, name, low, high, detail):
    if (isinstance(value, bool) or not isinstance(value, numbers.Integral)) and not (
            isinstance(value, numbers.Real) and float(value).is_integer()):
        raise ValueError(f"{name}: expected a whole number, got {value!r}")
    value = int(value)
    if value < low or (high is not None and value > high):
        bound = f">= {low}" if high is None else f"from {low} to {high}"
        raise ValueError(f"{name}: expected a whole number {bound}, got {value}{detail}")
    return value


def _wrap(angle):
    """Angles reduced to (-pi, pi]."""
    return -((-np.asarray(angle) + math.pi) % (2 * math.pi) - math.pi)


def _value(x):
    return float(x.value) if isinstance(x, u.Quantity) else float(x)


def _check_outputs(times):
    """The outputs of a run are evenly spaced; a ValueError that says how to get them otherwise."""
    t, _ = _plain(times, "times")
    if t.ndim == 1 and len(t) >= 2:
        _spacing(np.asarray(t, dtype=float),
                 "; a fixed-step run takes each output at the step nearest its even spacing: "
                 "choose dt so that the interval between outputs is a whole number of steps")


def _elements(result, body, primary, plane):
    """Elements of ``body`` in the chosen plane, and the name of the primary used."""
    if plane not in PLANES:
        raise ValueError(f"plane: expected one of {', '.join(map(repr, PLANES))}, "
                         f"got {plane!r}")
    if primary is None:
        primary = result.names[int(np.argmax(result.masses.value))]
        if primary == body:
            raise BodyError("this is the most massive body, which the elements are about "
                            "by default; name another primary=", body=body, field="primary")
    if plane == "invariable":
        result = _in_invariable_plane(result)
    return result.elements(body, primary=primary), primary


def _in_invariable_plane(result):
    """A copy of ``result`` with positions and velocities rotated to the invariable plane."""
    m = result.masses.value
    x = result.positions[0].value
    v = result.velocities[0].value
    total = m.sum()
    xc = x - (m @ x) / total
    vc = v - (m @ v) / total
    L = (m[:, None] * np.cross(xc, vc)).sum(axis=0)
    size = np.linalg.norm(L)
    if not size > 0:
        raise ValueError("plane='invariable': the bodies' total angular momentum is zero, "
                         "so there is no invariable plane; use plane='run'")
    zhat = L / size
    node = np.cross([0.0, 0.0, 1.0], zhat)
    if np.linalg.norm(node) < 1e-15:
        node = np.array([1.0, 0.0, 0.0])
    xhat = node / np.linalg.norm(node)
    yhat = np.cross(zhat, xhat)
    rot = np.array([xhat, yhat, zhat])
    out = _copy.copy(result)
    out.positions = result.positions @ rot.T
    out.velocities = result.velocities @ rot.T
    return out

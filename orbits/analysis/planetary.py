"""The frequencies of a planetary run: a body's secular frequencies (``g`` of its
perihelion, ``s`` of its node) and the frequencies of a combination of mean
longitudes, each by :func:`~orbits.analysis.frequencies` of the osculating
elements at the run's outputs."""

import copy as _copy
import dataclasses

import astropy.units as u
import numpy as np

from .. import geometry as _geometry
from ..errors import BodyError
from ._sampling import as_plain, is_whole, sampling_interval, to_float
from .decomposition import Frequencies
from .naff import SPACING_RTOL, frequencies

__all__ = ["SecularFrequencies", "secular_frequencies", "mean_motion_frequencies", "PLANES"]

#: Reference planes of :func:`secular_frequencies` and :func:`mean_motion_frequencies`.
PLANES = ("invariable", "run")


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
    The worked example of :mod:`orbits.analysis` makes one for Saturn.
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
            return ", ".join(f"{to_float(v):.6g}" for v in nu)
        return (f"<SecularFrequencies of {self.body} about {self.primary}, {self.plane} "
                f"plane: g {lead(self.g)}; s {lead(self.s)}>")


def secular_frequencies(result, body, n=10, primary=None, plane="invariable", window=1):
    """The secular frequencies of a body in a run: ``g`` of its perihelion, ``s`` of its node.

    Frequency analysis (:func:`~orbits.analysis.frequencies`) of the body's eccentricity and
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
        As for :func:`~orbits.analysis.frequencies`.

    Returns
    -------
    SecularFrequencies
        ``g`` and ``s``, each a :class:`~orbits.analysis.Frequencies` with frequencies in rad
        per the unit of ``result.times`` (convert with
        ``.to(u.arcsec / u.yr)``).

    Raises
    ------
    UnknownBodyError, BodyError, ElementsError
        As :meth:`orbits.Result.elements` raises them; BodyError also where
        ``body`` is the most massive body and no ``primary`` is named.
    ValueError
        The outputs are not evenly spaced; ``plane`` is not one of
        :data:`~orbits.analysis.planetary.PLANES`; as :func:`~orbits.analysis.frequencies` raises it.

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
    The worked example of :mod:`orbits.analysis` finds Saturn's ``g6`` and ``s6``
    over 200,000 years.
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

    Frequency analysis (:func:`~orbits.analysis.frequencies`) of ``exp(i theta)`` with
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
    The worked example of :mod:`orbits.analysis` finds the great inequality of
    Jupiter and Saturn over 200,000 years.
    """
    _check_outputs(result.times)
    if isinstance(bodies, str):
        bodies = {bodies: 1}
    if not bodies:
        raise ValueError("bodies: expected a body's name or a dict of names to whole "
                         "numbers, got an empty dict")
    theta = 0.0
    for name, k in dict(bodies).items():
        if not is_whole(k):
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


def _check_outputs(times):
    """The outputs of a run are evenly spaced; a ValueError that says how to get them otherwise."""
    t, _ = as_plain(times, "times")
    if t.ndim == 1 and len(t) >= 2:
        sampling_interval(np.asarray(t, dtype=float), SPACING_RTOL,
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
    """A copy of ``result`` with positions and velocities rotated to the invariable
    plane of its first output (:func:`orbits.geometry.invariable_plane_rotation`)."""
    L = _geometry.angular_momentum(result.masses.value, result.positions[0].value,
                                   result.velocities[0].value)
    if not np.linalg.norm(L) > 0:
        raise ValueError("plane='invariable': the bodies' total angular momentum is zero, "
                         "so there is no invariable plane; use plane='run'")
    rot = _geometry.invariable_plane_rotation(L)
    out = _copy.copy(result)
    out.positions = result.positions @ rot.T
    out.velocities = result.velocities @ rot.T
    return out

"""Scenes drawn at random: a Plummer-sphere star cluster and a ring of
planetesimals.  Equal seeds give equal sets."""

import math

import astropy.units as u
import numpy as np

from ..bodies import BodySet
from ..units import UnitSystem
from ._provenance import record

__all__ = ["plummer", "planetesimal_ring", "PLUMMER_MASS_CUT"]

# Radii beyond this fraction of the Plummer mass are not sampled: the
# untruncated model has no outer edge, and one star at r ~ 1000 would set the
# size of every plot and the step of every integrator.
PLUMMER_MASS_CUT = 0.999

# Bound on g(q) = q^2 (1 - q^2)^(7/2) for the rejection sampling of speeds;
# its maximum is 0.0922 at q^2 = 2/9 (Aarseth, Henon & Wielen 1974 use 0.1).
_PLUMMER_G_BOUND = 0.1


def plummer(n=1000, seed=None, mass_cut=PLUMMER_MASS_CUT):
    """A Plummer-sphere star cluster of ``n`` equal masses, in Hénon units.

    Sampled by the method of Aarseth, Hénon & Wielen (1974): the radius by
    inverting the cumulative mass ``M(r) = r^3 / (r^2 + b^2)^(3/2)``, isotropic
    directions for position and velocity, and the speed, as a fraction ``q``
    of the local escape speed, by von Neumann rejection on
    ``g(q) = q^2 (1 - q^2)^(7/2)``.

    Parameters
    ----------
    n : int
        Number of stars, ``>= 2``.  Default 1000.  Building takes linear time
        (10^5 stars in well under a second).
    seed : int, numpy.random.Generator or None
        Passed to :func:`numpy.random.default_rng`; equal seeds give equal sets.
    mass_cut : float
        Radii are drawn from the inner ``mass_cut`` of the mass,
        ``0 < mass_cut < 1``.  Default 0.999 (radii below ``38.7 b`` = 22.8
        Hénon length units); with the masses still summing to 1, the expected
        energy becomes -0.2507 and the virial ratio 0.999.

    Returns
    -------
    BodySet
        Bodies ``"0"`` ... ``"n-1"`` of mass ``1/n`` in N-body units
        (:meth:`UnitSystem.nbody`, G = 1), moved to the centre-of-mass frame.
        Hénon units (G = M = 1, E = -1/4) make the Plummer scale radius
        ``b = 3 pi / 16``; the sample's energy and virial ratio ``2T/|W|``
        scatter about -1/4 and 1 by a few times ``1/sqrt(n)``.

    Raises
    ------
    ValueError
        ``n`` is not an integer >= 2, or ``mass_cut`` is outside (0, 1).

    Notes
    -----
    With the radius ``r`` in units of ``b`` from ``X`` uniform in
    ``(0, mass_cut)``: ``r = (X^(-2/3) - 1)^(-1/2)``.  The escape speed at
    radius ``r`` (Hénon units) is ``sqrt(2) (r^2 + b^2)^(-1/4)``.

    References
    ----------
    .. [1] Aarseth, S. J., Hénon, M. & Wielen, R. 1974, "A comparison of
       numerical methods for the study of star cluster dynamics", A&A 37, 183.
    .. [2] Plummer, H. C. 1911, "On the problem of distribution in globular
       star clusters", MNRAS 71, 460.
    .. [3] Hénon, M. 1971, "The Monte Carlo method", Ap&SS 14, 151 (the units).

    Examples
    --------
    >>> from orbits import scenes
    >>> cluster = scenes.plummer(1000, seed=42)
    >>> len(cluster)
    1000
    >>> round(float(cluster.total_mass), 12)
    1.0
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    n = int(n)
    if n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n}")
    mass_cut = float(mass_cut)
    if not 0.0 < mass_cut < 1.0:
        raise ValueError(f"mass_cut must be in (0, 1), got {mass_cut}")
    rng = np.random.default_rng(seed)
    b = 3.0 * math.pi / 16.0

    # 1 - uniform lies in (0, 1], so 0 < X <= mass_cut < 1 and r is finite.
    X = mass_cut * (1.0 - rng.random(n))
    r = b / np.sqrt(X ** (-2.0 / 3.0) - 1.0)
    positions = r[:, None] * _isotropic(rng, n)

    q = _plummer_speed_fractions(rng, n)
    speed = q * math.sqrt(2.0) * (r ** 2 + b ** 2) ** -0.25
    velocities = speed[:, None] * _isotropic(rng, n)

    bodies = BodySet.from_arrays(np.full(n, 1.0 / n), positions, velocities,
                                 units=UnitSystem.nbody())
    bodies.move_to_com()
    return record(bodies, "plummer", n=n, seed=None if seed is None else repr(seed),
                  mass_cut=mass_cut, units="Henon (G = M = 1, E = -1/4)",
                  source="Aarseth, Henon & Wielen 1974")


def _isotropic(rng, n):
    """``n`` unit vectors uniformly distributed on the sphere."""
    z = 2.0 * rng.random(n) - 1.0
    phi = 2.0 * math.pi * rng.random(n)
    s = np.sqrt(1.0 - z ** 2)
    return np.column_stack([s * np.cos(phi), s * np.sin(phi), z])


def _plummer_speed_fractions(rng, n):
    """``n`` draws of q in [0, 1) with density proportional to q^2 (1 - q^2)^(7/2)."""
    out = np.empty(n)
    filled = 0
    while filled < n:
        # About 43% of the candidates are accepted; ask for enough at once.
        want = n - filled
        m = int(want / 0.4) + 16
        q = rng.random(m)
        y = _PLUMMER_G_BOUND * rng.random(m)
        keep = q[y < q ** 2 * (1.0 - q ** 2) ** 3.5][:want]
        out[filled:filled + keep.size] = keep
        filled += keep.size
    return out


def planetesimal_ring(n=80, seed=1, radius=5e-4 * u.au, total_mass=2 * u.Mearth):
    """A ring of planetesimals with radii between 0.9 and 1.1 au about a Sun-mass star.

    ``n`` equal masses (``total_mass`` in all) on nearly circular, nearly
    coplanar orbits: semi-major axes uniform in [0.9, 1.1] au, eccentricities
    and inclinations Rayleigh distributed with scales 0.01 and 0.005 rad,
    the angles uniform.  The radii are inflated (5e-4 au by default, 75 000
    km) so that collisions come within a few hundred orbits: a scene for
    ``collisions="merge"`` (``examples/planetesimal_accretion.py``).

    Parameters
    ----------
    n : int
        Number of planetesimals, ``>= 1``.  Default 80.
    seed : int or None
        Passed to :func:`numpy.random.default_rng`; equal seeds give equal sets.
    radius : Quantity, length
        Each planetesimal's radius; the star's is the Sun's.
    total_mass : Quantity, mass

    Returns
    -------
    BodySet
        ``"Sun"`` and ``"p000"`` ... in au, Msun and days, moved to the
        centre-of-mass frame.

    References
    ----------
    Ida & Makino (1992), Icarus 96, 107: Rayleigh distributions of the
    planetesimals' eccentricities and inclinations.  Kokubo & Ida (1996),
    Icarus 123, 180: planetesimal radii enlarged so that collisions come
    within an affordable run.

    Examples
    --------
    >>> from orbits import scenes
    >>> ring = scenes.planetesimal_ring(n=20)
    >>> len(ring), ring.names[:2], ring.radii[1]
    (21, ['Sun', 'p000'], <Quantity 0.0005 AU>)
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n must be a whole number of planetesimals >= 1, got {n!r}")
    rng = np.random.default_rng(seed)
    b = BodySet()
    b.add("Sun", mass=1 * u.Msun, radius=1 * u.Rsun)
    for k in range(int(n)):
        b.add(f"p{k:03d}", mass=total_mass / n, primary="Sun",
              a=rng.uniform(0.9, 1.1) * u.au, e=rng.rayleigh(0.01),
              inc=rng.rayleigh(0.005) * u.rad, Omega=rng.uniform(0, 360) * u.deg,
              omega=rng.uniform(0, 360) * u.deg, M=rng.uniform(0, 360) * u.deg,
              radius=radius)
    b.move_to_com()
    return record(b, "planetesimal-ring", n=int(n), seed=seed,
                  radius=float(radius.to_value(u.au)),
                  total_mass=float(total_mass.to_value(u.Mearth)))

"""Scenes whose initial conditions are printed in the literature: the
Hairer–Lubich–Wanner outer solar system, Burrau's Pythagorean problem and the
figure-eight choreography."""

import astropy.units as u
import numpy as np

from ..bodies import BodySet
from ..units import UnitSystem
from ._provenance import record

__all__ = ["outer_solar_system", "pythagorean", "figure_eight", "FIGURE_EIGHT_PERIOD",
           "HLW_G"]

#: Period of the figure-eight choreography in N-body units (G = m = 1), from
#: Simó's computation quoted by Chenciner & Montgomery (2000).
FIGURE_EIGHT_PERIOD = 6.32591398

#: The gravitational constant of the Hairer-Lubich-Wanner outer solar system,
#: in au^3 / (Msun day^2) (Hairer, Lubich & Wanner 2006, sect. I.2.4).
HLW_G = 2.95912208286e-4

# Hairer, Lubich & Wanner (2006), Table I.2.1: masses relative to the Sun
# (the Sun's including the inner planets), positions in au and velocities in
# au/day, to the digits printed in the book.  The Sun is at rest at the origin.
_HLW_NAMES = ("Sun", "Jupiter", "Saturn", "Uranus", "Neptune", "Pluto")
_HLW_MASSES = (1.00000597682, 0.000954786104043, 0.000285583733151,
               0.0000437273164546, 0.0000517759138449, 1 / 1.3e8)
_HLW_POSITIONS = (
    (0.0, 0.0, 0.0),
    (-3.5023653, -3.8169847, -1.5507963),
    (9.0755314, -3.0458353, -1.6483708),
    (8.3101420, -16.2901086, -7.2521278),
    (11.4707666, -25.7294829, -10.8169456),
    (-15.5387357, -25.2225594, -3.1902382),
)
_HLW_VELOCITIES = (
    (0.0, 0.0, 0.0),
    (0.00565429, -0.00412490, -0.00190589),
    (0.00168318, 0.00483525, 0.00192462),
    (0.00354178, 0.00137102, 0.00055029),
    (0.00288930, 0.00114527, 0.00039677),
    (0.00276725, -0.00170702, -0.00136504),
)


def outer_solar_system(com=False):
    """The Hairer–Lubich–Wanner outer solar system: Sun, four giant planets and Pluto.

    The standard test problem of geometric numerical integration: the Sun
    (its mass including the inner planets), Jupiter, Saturn, Uranus, Neptune
    and Pluto, with the initial positions and velocities of 1994 September 5
    printed in the book, and its own value of G.

    Parameters
    ----------
    com : bool
        Move to the centre-of-mass frame.  Default False: keep the published
        frame, in which the Sun is at rest at the origin (heliocentric
        positions and velocities) and the axes are equatorial (the planets'
        orbits are inclined about 23 deg to the xy plane).  In that frame the
        centre of mass drifts at 6.8e-6 au/day (250 au in 1e5 years);
        integrators do not mind, but plots in that frame would.
        :meth:`orbits.Result.plot` and ``orbits plot`` draw about the Sun by
        default, and :meth:`orbits.Result.relative_to` or
        :meth:`orbits.Result.barycentric` change the frame of a result.

    Returns
    -------
    BodySet
        Bodies ``"Sun"``, ``"Jupiter"``, ``"Saturn"``, ``"Uranus"``,
        ``"Neptune"``, ``"Pluto"``, in au, solar masses and days with
        ``G = 2.95912208286e-4`` au^3/(Msun day^2) (:data:`~orbits.scenes.published.HLW_G`; the book's
        value, 1.4e-12 relative from Gauss's constant squared).  Masses:
        ``m0 = 1.00000597682`` (Sun plus inner planets),
        ``m1 = 0.000954786104043``, ``m2 = 0.000285583733151``,
        ``m3 = 0.0000437273164546``, ``m4 = 0.0000517759138449``,
        ``m5 = 1 / 1.3e8``.

    References
    ----------
    .. [1] Hairer, E., Lubich, C. & Wanner, G. 2006, *Geometric Numerical
       Integration: Structure-Preserving Algorithms for Ordinary Differential
       Equations*, 2nd ed., Springer Series in Computational Mathematics 31,
       section I.2.4 and table 2.1.

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.outer_solar_system()
    >>> bodies.units.G
    0.000295912208286
    >>> bodies.positions[1].to_value(u.au).tolist()
    [-3.5023653, -3.8169847, -1.5507963]
    """
    units = UnitSystem(length=u.au, mass=u.Msun, time=u.day, G=HLW_G, name="hlw",
                       G_source="Hairer, Lubich & Wanner 2006, sect. I.2.4")
    bodies = BodySet.from_arrays(np.array(_HLW_MASSES), np.array(_HLW_POSITIONS),
                                 np.array(_HLW_VELOCITIES), names=_HLW_NAMES,
                                 units=units)
    if com:
        bodies.move_to_com()
    return record(bodies, "outer-solar-system", com=bool(com),
                  epoch="1994-09-05",
                  source="Hairer, Lubich & Wanner 2006, table I.2.1")


def pythagorean():
    """Burrau's Pythagorean three-body problem.

    Masses 3, 4 and 5 start at rest at the corners of a 3-4-5 right triangle,
    each opposite the side of its own length: at (1, 3), (-2, -1) and (1, -1),
    with ``G = 1``.  The motion is chaotic, with close encounters, and ends
    (near t = 60) with the two heavier bodies (4 and 5) leaving as a binary
    and the lightest (3) escaping the other way, as Szebehely & Peters found;
    a hard test of adaptive step control.

    Returns
    -------
    BodySet
        Bodies ``"1"`` (m = 3), ``"2"`` (m = 4) and ``"3"`` (m = 5) in the
        plane z = 0, in N-body units (:meth:`UnitSystem.nbody`, G = 1).  The
        centre of mass is at rest at the origin as given; the total energy is
        ``-769/60``.

    References
    ----------
    .. [1] Burrau, C. 1913, "Numerische Berechnung eines Spezialfalles des
       Dreikörperproblems", Astron. Nachr. 195, 113.
    .. [2] Szebehely, V. & Peters, C. F. 1967, "Complete solution of a general
       problem of three bodies", AJ 72, 876.

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.pythagorean()
    >>> bodies.masses
    <Quantity [3., 4., 5.]>
    """
    bodies = BodySet.from_arrays(
        np.array([3.0, 4.0, 5.0]),
        np.array([[1.0, 3.0, 0.0], [-2.0, -1.0, 0.0], [1.0, -1.0, 0.0]]),
        np.zeros((3, 3)), names=["1", "2", "3"], units=UnitSystem.nbody())
    bodies.move_to_com()
    return record(bodies, "pythagorean", source="Burrau 1913; Szebehely & Peters 1967")


def figure_eight():
    """The figure-eight choreography of three equal masses.

    Three bodies of mass 1 chase one another around one figure-eight curve,
    with ``G = 1`` and period :data:`~orbits.scenes.published.FIGURE_EIGHT_PERIOD` (6.32591398).  The
    initial conditions are Simó's, as given by Chenciner & Montgomery:
    ``x1 = -x2 = (0.97000436, -0.24308753, 0)``, ``x3 = 0``,
    ``v3 = (-0.93240737, -0.86473146, 0)``, ``v1 = v2 = -v3 / 2``.
    The total momentum and angular momentum are zero.

    Returns
    -------
    BodySet
        Bodies ``"1"``, ``"2"``, ``"3"`` in the plane z = 0, in N-body units
        (:meth:`UnitSystem.nbody`, G = 1), already in the centre-of-mass frame.

    References
    ----------
    .. [1] Chenciner, A. & Montgomery, R. 2000, "A remarkable periodic solution
       of the three-body problem in the case of equal masses", Annals of
       Mathematics 152, 881.
    .. [2] Moore, C. 1993, "Braids in classical dynamics", Phys. Rev. Lett. 70,
       3675 (first found numerically).

    Examples
    --------
    >>> from orbits import scenes
    >>> bodies = scenes.figure_eight()
    >>> bodies.velocities[0].value.tolist()
    [0.466203685, 0.43236573, -0.0]
    """
    x1 = np.array([0.97000436, -0.24308753, 0.0])
    v3 = np.array([-0.93240737, -0.86473146, 0.0])
    bodies = BodySet.from_arrays(
        np.ones(3), np.array([x1, -x1, np.zeros(3)]),
        np.array([-v3 / 2, -v3 / 2, v3]), names=["1", "2", "3"],
        units=UnitSystem.nbody())
    return record(bodies, "figure-eight", period=FIGURE_EIGHT_PERIOD,
                  source="Chenciner & Montgomery 2000 (Simo's initial conditions)")

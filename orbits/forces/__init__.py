"""Force terms: physics beyond Newtonian point-mass gravity.

A simulation integrates Newtonian gravity plus the terms it is given::

    sim = orbits.Simulation(bodies, "ias15", forces=[orbits.forces.GR("Sun")])

Every term is compiled into the same loop as gravity and reaches every
integrator that can honour it, the energy monitor, output files, restarts
and ensembles.  A term declares what the rest of the package needs to know,
so that nothing downstream asks for its name:

* ``velocity_dependent``: its accelerations read velocities (``ias15``
  predicts them at its substeps; the leapfrog and its compositions solve
  the kick implicitly);
* its energy: the potential, or the first post-Newtonian correction to the
  conserved energy, which the energy monitor adds, so that
  ``result.energy_error`` measures the integration and not the physics;
  ``conservative`` is False for a term without one, whose work ``W`` the
  loops integrate instead (:attr:`orbits.Simulation.work`), the energy error
  being that of ``E + W``;
* its Jacobian ``da/dx``, ``da/dv``, for the implicit methods (analytic for
  :class:`GR`, :class:`GRPotential`, :class:`ZonalHarmonics`, :class:`Migration`,
  :class:`TidesConstantTimeLag` and :class:`RadiationPressure`; central
  differences of the term alone for :class:`GRFull` and :class:`UserForce`);
* ``wisdom_holman``: whether the Wisdom-Holman map can take it in its
  interaction step and stay symplectic (conservative, positions only).

The dissipative terms (:class:`Migration`, :class:`TidesConstantTimeLag`,
:class:`RadiationPressure`) add nothing to the conserved energy: their energy
kernel is zero and ``conservative`` is False.

Which integrators take which term:

=============================  ==========================================  ==================
term                           Wisdom-Holman family (``wh``, ``saba*``)    every other method
=============================  ==========================================  ==================
:class:`GRPotential`           yes, symplectic                             yes
:class:`ZonalHarmonics`        yes, symplectic                             yes
:class:`UserForce`             with ``potential``, not velocity-dependent  yes
:class:`GR`                    no (velocities)                             yes
:class:`GRFull`                no (velocities)                             yes
:class:`Migration`             no (dissipative, velocities)                yes
:class:`TidesConstantTimeLag`  no (dissipative, velocities)                yes
:class:`RadiationPressure`     no (dissipative, velocities)                yes
=============================  ==========================================  ==================

With a velocity-dependent term the leapfrog, Verlet and the compositions
kick with ``v' = v + h a(x, (v + v') / 2)``, solved by fixed-point
iteration to round-off: the kick is then symmetric and the methods keep
their order (2 for the leapfrog; measured in the tests), but they are no
longer symplectic, and energy errors grow slowly.

Parameters given as Quantities are converted once, through the body set's
:class:`~orbits.units.UnitSystem`; the speed of light defaults to astropy's
``c`` in those units.

The package holds a module for each kind of term (``_gravity``,
``_relativity``, ``_zonal``, ``_dissipative``, ``_user``) over ``_base``
(:class:`ForceTerm`, its dictionary and the registry by name), ``_binding``
(what a term is bound to and what binding gives) and ``_parameters`` (a
term's parameters checked and converted); a new term is one class there, its
kernel in :mod:`orbits._kernels.terms`, and a test.

References
----------
Anderson et al. 1975, ApJ 200, 221 (:class:`GR`); Nobili & Roxburgh 1986,
IAU Symp. 114, 105 (:class:`GRPotential`); Newhall, Standish & Williams 1983,
A&A 125, 150 (:class:`GRFull`); Murray & Dermott 1999, *Solar System
Dynamics*, sect. 4.9 (:class:`ZonalHarmonics`); Papaloizou & Larwood 2000, MNRAS
315, 823 (:class:`Migration`); Hut 1981, A&A 99, 126 (:class:`TidesConstantTimeLag`);
Burns, Lamy & Soter 1979, Icarus 40, 1 (:class:`RadiationPressure`).
"""

from ._base import ForceTerm, from_dict, functions_needed, functions_of
from ._binding import BoundTerm, Context
from ._dissipative import Migration, RadiationPressure, TidesConstantTimeLag
from ._gravity import Gravity
from ._relativity import GR, GRFull, GRPotential
from ._user import UserForce
from ._zonal import ZonalHarmonics

__all__ = ["ForceTerm", "Gravity", "GR", "GRPotential", "GRFull", "ZonalHarmonics",
           "Migration", "TidesConstantTimeLag", "RadiationPressure", "UserForce",
           "from_dict", "functions_needed", "functions_of", "BoundTerm"]

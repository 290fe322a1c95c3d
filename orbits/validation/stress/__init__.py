"""The stress suite: where each integrator is accurate, where it degrades, where it fails.

Six sweeps push every integrator of the registry towards the edge of what it
can do, one parameter at a time:

* **eccentricity** of a Kepler orbit, 0 to 0.9999, against the analytic orbit
  (Kepler's equation, :mod:`orbits._kernels.anomalies`: an oracle that shares no
  code with any integrator);
* **step size** on the outer solar system, against REBOUND's IAS15: the step
  for fixed-step methods, the tolerance for adaptive ones (they have no step
  to set);
* **mass ratio** of a two-body orbit, 1e-12 to 1, against the analytic orbit;
* **close encounters** of two Earth-mass planets about a star, passing at
  1e-3 to 1e-8 au, against REBOUND's IAS15.  The initial state is made by
  integrating the moment of closest approach backwards (REBOUND IAS15), so
  the pass distance is what the column says; the reference run measures it
  again;
* the **Pythagorean problem**: step and tolerance against the largest energy
  error (the motion is chaotic, so final positions would measure the
  reference as much as the method);
* the **stiff spring** ``x'' = -k x`` (m = 1, x0 = 1, v0 = 0) for k = 1 to 1e6
  at a fixed step dt = 0.01 (the integrator-choice guide's step), through
  :func:`orbits.integrate`, against ``cos(sqrt(k) t)``.

Each cell of a map is one run, classified by the thresholds below as
accurate, degraded or failed; a run that raised one of the named run errors
(``NonFiniteState``, ``StepSizeUnderflow``, ``ConvergenceFailure``,
``WallTimeExceeded``) is failed and shows the error's abbreviation.  Nothing
is left to hang: every run has a wall-time limit.  An integrator that does
not apply to a sweep is drawn grey and listed with the reason.

This package follows the report's part protocol: :data:`TITLE`,
:func:`tasks` (the measurements, run in parallel by
:func:`orbits.validation._runner.run_tasks`) and :func:`section` (maps and
Markdown from their rows).  Its modules: :mod:`~.classes` (how a cell is
classified), :mod:`~.problems` (the problems beyond the scenes, with their
oracles), :mod:`~.sweeps` (the sweeps, their runs and tasks) and
:mod:`~.maps` (the section).
"""

from .classes import (ACCURATE, ACCURATE_ENERGY, ACCURATE_POSITION, DEGRADED, FAILED,
                      FAILED_ENERGY, FAILED_POSITION, LEFT_OUT, abbreviation, classify)
from .maps import TITLE, section
from .problems import ENCOUNTER_TIME, encounter_bodies, kepler_reference, pass_distance
from .sweeps import (SWEEPS, VARIANTS, WALL_LIMIT_FULL, WALL_LIMIT_QUICK, Sweep, measure,
                     reference, tasks)

__all__ = ["TITLE", "tasks", "section", "classify", "abbreviation", "encounter_bodies",
           "pass_distance", "kepler_reference", "measure", "reference", "Sweep", "SWEEPS",
           "VARIANTS", "ACCURATE", "DEGRADED", "FAILED", "LEFT_OUT", "ACCURATE_POSITION",
           "FAILED_POSITION", "ACCURATE_ENERGY", "FAILED_ENERGY", "WALL_LIMIT_QUICK",
           "WALL_LIMIT_FULL", "ENCOUNTER_TIME"]

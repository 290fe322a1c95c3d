"""orbits: N-body orbital mechanics with astropy units and compiled integrators.

>>> import astropy.units as u
>>> import orbits
>>> bodies = orbits.scenes.outer_solar_system()
>>> sim = orbits.Simulation(bodies, integrator="leapfrog", dt=10 * u.day)
>>> result = sim.run(until=1000 * u.yr, outputs=100, progress=False)
>>> print(result.summary())                               # doctest: +SKIP
"""

from importlib.metadata import PackageNotFoundError, version as _version

from . import analysis, errors, forces, integrators, io, monitors, scenes, systemfile
from .bodies import BodySet
from .custom import Trajectory, integrate
from .errors import (BodyError, BodyUnitsError, CloseEncounter, Collision, ConvergenceFailure,
                     ElementsError, Escape, ForceTermError, IntegratorOptionError,
                     NonFiniteState, OrbitsError, RunInterrupted, SimulationOptionError,
                     StepSizeUnderflow, SystemFileError, UnknownIntegratorError,
                     WallTimeExceeded)
from .result import Result
from .simulation import Simulation
from .units import UnitSystem
from .io.hdf5 import load

try:
    __version__ = _version("orbits")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = ["BodySet", "Simulation", "Result", "UnitSystem", "integrate", "Trajectory",
           "scenes", "integrators", "monitors", "analysis", "errors", "forces", "OrbitsError",
           "BodyError", "ForceTermError",
           "BodyUnitsError", "ElementsError", "IntegratorOptionError",
           "UnknownIntegratorError", "NonFiniteState", "StepSizeUnderflow", "ConvergenceFailure",
           "CloseEncounter", "Collision", "Escape", "SimulationOptionError", "WallTimeExceeded", "RunInterrupted", "SystemFileError", "systemfile",
           "load", "io", "Ensemble", "__version__"]


def __getattr__(name):
    # Ensemble needs dask and pandas: imported on first use, not with orbits
    if name == "Ensemble":
        from .ensemble import Ensemble
        return Ensemble
    raise AttributeError(f"module 'orbits' has no attribute {name!r}")

"""orbits: N-body orbital mechanics with astropy units and compiled integrators.

>>> import astropy.units as u
>>> import orbits
>>> bodies = orbits.scenes.outer_solar_system()
>>> sim = orbits.Simulation(bodies, integrator="leapfrog", dt=10 * u.day)
>>> result = sim.run(until=1000 * u.yr, outputs=100, progress=False)
>>> print(result.summary())                               # doctest: +SKIP

The names below are imported on first use (PEP 562): ``import orbits`` alone
loads neither astropy, numba nor h5py, so that ``orbits --help`` and a script's
start stay quick; ``orbits.Simulation`` or ``from orbits import Simulation``
imports what it needs.
"""

import os as _os
from importlib import import_module as _import_module
from importlib.util import find_spec as _find_spec

# numba formats a message for every overload it tries and rejects while it
# types a kernel, thousands in a loop's first compilation; where colorama is
# installed each one re-wraps the standard streams to highlight the message.
# numba's switch for that (read once, when numba is first imported) takes a
# few per cent off a first compilation: benchmarks/RESULTS.md,
# "bench_first_compile".
# A user's own setting stands; a numba imported before this package keeps the
# highlighting it chose.
_os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")

#: public name -> the module that defines it, relative to this package; a name
#: whose module is itself (``scenes``) is a submodule
_EXPORTS = {
    "BodySet": ".bodies",
    "Simulation": ".simulation",
    "Result": ".result",
    "UnitSystem": ".units",
    "integrate": ".custom",
    "compile_ahead": "._ahead",
    "Trajectory": ".custom",
    "load": ".io.h5md",
    # Ensemble needs dask and pandas when it runs; its module imports them itself
    "Ensemble": ".ensemble",
    **{name: f".{name}" for name in ("scenes", "integrators", "monitors", "analysis",
                                      "errors", "forces", "systemfile", "io")},
    **{name: ".errors" for name in (
        "OrbitsError", "BodyError", "ForceTermError", "BodyUnitsError", "ElementsError",
        "IntegratorOptionError", "UnknownIntegratorError", "NonFiniteState",
        "StepSizeUnderflow", "ConvergenceFailure", "CloseEncounter", "Collision", "Escape",
        "SimulationOptionError", "WallTimeExceeded", "RunInterrupted", "SystemFileError")},
}

__all__ = ["BodySet", "Simulation", "Result", "UnitSystem", "integrate", "Trajectory",
           "compile_ahead",
           "scenes", "integrators", "monitors", "analysis", "errors", "forces", "OrbitsError",
           "BodyError", "ForceTermError",
           "BodyUnitsError", "ElementsError", "IntegratorOptionError",
           "UnknownIntegratorError", "NonFiniteState", "StepSizeUnderflow", "ConvergenceFailure",
           "CloseEncounter", "Collision", "Escape", "SimulationOptionError", "WallTimeExceeded", "RunInterrupted", "SystemFileError", "systemfile",
           "load", "io", "Ensemble", "__version__"]


def _version():
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("orbits")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0+unknown"


def __getattr__(name):
    if name == "__version__":
        value = _version()
    elif name in _EXPORTS:
        module = _import_module(_EXPORTS[name], __name__)
        value = module if _EXPORTS[name] == f".{name}" else getattr(module, name)
    elif name.isidentifier() and not name.startswith("__") \
            and _find_spec(f"{__name__}.{name}") is not None:
        # any other submodule, as ``orbits.bodies`` was reachable when this
        # package imported all of them
        value = _import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))

"""The names the examples in the package's docstrings take as given.

Every docstring example runs with ``u`` (``astropy.units``), ``np`` (numpy) and
``orbits`` imported, and one that uses ``sim`` before making it gets a fresh
simulation of a star and a planet (``orbits.scenes.kepler()``, in days) with
``leapfrog`` at a step of one day: the set-up the examples of
:class:`orbits.Simulation`'s members start from, as its docstring says.
"""

import astropy.units as u
import numpy as np
import pytest

import orbits


def kepler_simulation():
    """``sim`` of the examples: a fresh one for each."""
    return orbits.Simulation(orbits.scenes.kepler(), integrator="leapfrog", dt=1 * u.day)


@pytest.fixture(autouse=True)
def _doctest_names(request, doctest_namespace):
    dtest = getattr(request.node, "dtest", None)
    if dtest is None:
        yield
        return
    doctest_namespace.update(u=u, np=np, orbits=orbits)
    if "sim." in dtest.docstring and ">>> sim = " not in dtest.docstring.split("sim.")[0]:
        doctest_namespace["sim"] = kepler_simulation()
    yield
    doctest_namespace.pop("sim", None)

"""The names the examples in the package's docstrings take as given.

Every docstring example runs with ``u`` (``astropy.units``), ``np`` (numpy) and
``orbits`` imported, as the documentation's pages do (``doctest_global_setup``
in ``docs/conf.py``); one that uses ``sim`` before making it gets a fresh
simulation of a star and a planet (``orbits.scenes.kepler()``, in days) with
``leapfrog`` at a step of one day: the set-up the examples of
:class:`orbits.Simulation`'s members start from, as its docstring says.  Two
runs that the examples of :class:`orbits.Result` show being made are there
too: ``two_body`` (:func:`orbits.scenes.kepler` with ``leapfrog``, a step of a
day, ten years, 11 outputs) and ``planets`` (the outer solar system with
``leapfrog``, a step of ten days, a century, 11 outputs), made once a test
process when a doctest first asks for them; the examples only read them.

``pytest --doctest-modules`` gives each example a namespace with them, so that
an example starts with what it shows rather than with its imports.
"""

import functools

import astropy.units as u
import numpy as np
import pytest

import orbits


def kepler_simulation():
    """``sim`` of the examples: a fresh one for each."""
    return orbits.Simulation(orbits.scenes.kepler(), integrator="leapfrog", dt=1 * u.day)


@functools.cache
def _runs():
    def run(bodies, dt, until):
        return orbits.Simulation(bodies, "leapfrog", dt=dt).run(until=until, outputs=11,
                                                                progress=False)

    return {"two_body": run(orbits.scenes.kepler(), 1 * u.day, 10 * u.yr),
            "planets": run(orbits.scenes.outer_solar_system(), 10 * u.day, 100 * u.yr)}


@pytest.fixture(autouse=True)
def _doctest_names(request, doctest_namespace):
    # doctests only: the other tests make what they use
    dtest = getattr(request.node, "dtest", None)
    if dtest is None:
        yield
        return
    doctest_namespace.update(u=u, np=np, orbits=orbits)
    text = dtest.docstring or ""
    if "two_body" in text or "planets" in text:
        doctest_namespace.update(_runs())
    if "sim." in text and ">>> sim = " not in text.split("sim.")[0]:
        doctest_namespace["sim"] = kepler_simulation()
    yield
    doctest_namespace.pop("sim", None)

"""The names the package's docstring examples assume: ``u`` (astropy.units),
``np`` (numpy) and ``orbits``, as the documentation's pages do
(``doctest_global_setup`` in ``docs/conf.py``), and two runs that the
examples of :class:`orbits.Result` show being made: ``two_body``
(:func:`orbits.scenes.kepler` with ``leapfrog``, a step of a day, ten years,
11 outputs) and ``planets`` (the outer solar system with ``leapfrog``, a step
of ten days, a century, 11 outputs).

``pytest --doctest-modules`` gives each example a namespace with them, so that
an example starts with what it shows rather than with its imports.  The runs
are made once a test process, when a doctest first asks for them; the
examples only read them.
"""

import functools

import astropy.units as u
import numpy as np
import pytest
from _pytest.doctest import DoctestItem

import orbits


@pytest.fixture(autouse=True, scope="session")
def _doctest_names(doctest_namespace):
    doctest_namespace.update(u=u, np=np, orbits=orbits)


@functools.cache
def _runs():
    def run(bodies, dt, until):
        return orbits.Simulation(bodies, "leapfrog", dt=dt).run(until=until, outputs=11,
                                                                progress=False)

    return {"two_body": run(orbits.scenes.kepler(), 1 * u.day, 10 * u.yr),
            "planets": run(orbits.scenes.outer_solar_system(), 10 * u.day, 100 * u.yr)}


@pytest.fixture(autouse=True)
def _doctest_runs(request, doctest_namespace):
    # doctests only: the other tests make the runs they use
    if isinstance(request.node, DoctestItem):
        doctest_namespace.update(_runs())

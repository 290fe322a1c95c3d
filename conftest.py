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

The examples of the output file's functions and of its writer start from a
file: one that names ``run_file`` gets the path of a new file in a temporary
folder that ``sim`` has run into (ten days in 3 outputs), the ``sim`` of the
example; one that uses ``rec`` before making it gets a
:class:`~orbits.io.h5md.FileRecorder` of ``sim`` writing a new file
(``rec.path``), planned to ten days in 2 outputs, that has written its first
output and a checkpoint: the set-up the example of that class shows.

``pytest --doctest-modules`` gives each example a namespace with them, so that
an example starts with what it shows rather than with its imports.
"""

import functools
import re

import astropy.units as u
import numpy as np
import pytest

import orbits


def kepler_simulation():
    """``sim`` of the examples: a fresh one for each."""
    return orbits.Simulation(orbits.scenes.kepler(), integrator="leapfrog", dt=1 * u.day)


def run_file(folder, sim):
    """``run_file`` of the examples: ``sim`` run ten days into a new file in ``folder``."""
    path = str(folder / "run.h5")
    sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    return path


def file_recorder(folder, sim):
    """``rec`` of the examples: a writer of ``sim`` into a new file in ``folder``,
    planned to ten days in 2 outputs (its first output and a checkpoint written)."""
    from orbits.io.h5md import FileRecorder
    from orbits.records import RunPlan
    plan = RunPlan(until=10.0, outputs=2, ratio=10.0, n_full=10, has_partial=False,
                   start_step=0)
    return FileRecorder(str(folder / "run.h5"), sim, plan)


def _uses(text, name):
    """Whether an example uses ``name`` (``name.``, a word of its own) before
    making it, or without."""
    found = re.search(rf"(?<![\w.]){name}\.", text)
    return found is not None and f">>> {name} = " not in text[:found.start()]


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
    names = {}
    if _uses(text, "sim") or "run_file" in text or _uses(text, "rec"):
        names["sim"] = kepler_simulation()
    if "run_file" in text:
        names["run_file"] = run_file(request.getfixturevalue("tmp_path"), names["sim"])
    if _uses(text, "rec"):
        names["rec"] = file_recorder(request.getfixturevalue("tmp_path"), names["sim"])
    doctest_namespace.update(names)
    yield
    if "rec" in names:
        names["rec"].close()
    for name in names:
        doctest_namespace.pop(name, None)

"""The names the package's docstring examples assume: ``u`` (astropy.units),
``np`` (numpy) and ``orbits``, as the documentation's pages do
(``doctest_global_setup`` in ``docs/conf.py``).

``pytest --doctest-modules`` gives each example a namespace with them, so that
an example starts with what it shows rather than with its imports.
"""

import astropy.units as u
import numpy as np
import pytest

import orbits


@pytest.fixture(autouse=True, scope="session")
def _doctest_names(doctest_namespace):
    doctest_namespace.update(u=u, np=np, orbits=orbits)

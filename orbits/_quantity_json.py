"""Quantities as plain JSON values, ``[value, unit]``, and back: how force
terms' dictionaries (:mod:`orbits.forces`) and a simulation's configuration
(:class:`orbits.records.SimulationConfig`) hold them.

Examples
--------
>>> from orbits._quantity_json import to_plain, from_plain
>>> to_plain(3e5 * u.km / u.s), to_plain([0, 0, 2] * u.rad / u.day), to_plain(None)
([300000.0, 'km / s'], [[0.0, 0.0, 2.0], 'rad / d'], None)
>>> from_plain([300000.0, 'km / s'])
<Quantity 300000. km / s>

astropy is imported only to make a Quantity: a value is none before it is.
"""

import sys

import numpy as np

__all__ = ["to_plain", "from_plain", "is_quantity"]


def is_quantity(value):
    """Whether ``value`` is an astropy Quantity (never before astropy's units
    are imported, which this does not do)."""
    u = sys.modules.get("astropy.units")
    return u is not None and isinstance(value, u.Quantity)


def to_plain(value):
    """A Quantity as ``[value, unit]`` (its value a list where it is an array);
    None as it is; a plain number as a float, a plain array as a list of floats."""
    if value is None:
        return None
    if is_quantity(value):
        return [np.asarray(value.value).tolist(), value.unit.to_string()]
    if np.ndim(value):
        return [float(c) for c in np.asarray(value, dtype=float).ravel()]
    return float(value)


def from_plain(value):
    """The Quantity that ``[value, unit]`` writes; anything else as it is."""
    if isinstance(value, list) and len(value) == 2 and isinstance(value[1], str):
        import astropy.units as u
        return u.Quantity(value[0], value[1])
    return value

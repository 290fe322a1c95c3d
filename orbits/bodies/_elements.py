"""A body's orbit about its primary: the state from orbital elements, and the
elements from the state.

:meth:`~orbits.BodySet.add` and :mod:`orbits.systemfile` make a body given by
elements with :func:`relative_state`, the same arithmetic for both, so that
the same elements give the same state bit for bit.  A primary is a body, the
barycentre of the set, or by default the centre of mass of the bodies before
(:func:`primary_state`).
"""

import math

import numpy as np

from .. import geometry as _geometry
from .. import orbit_fields as _orbit_fields
from .._kernels import anomalies as _anomalies
from .._kernels import elements as _elements
from .._kernels.status import describe_status
from ..body import unknown_body
from ..errors import BodyError, ElementsError
from ._input import require_mass

__all__ = ["ELEMENT_NAMES", "FIELD_KINDS", "relative_state", "state_from_elements",
           "primary_state", "relative_to_primary", "element_values", "bound_elements"]

#: the classical elements, in the order of the kernels' arrays
ELEMENT_NAMES = ("a", "e", "inc", "Omega", "omega", "f", "M")

#: what each field of :meth:`BodySet.add`'s orbit is
FIELD_KINDS = {"a": "length", "e": "dimensionless", "inc": "angle", "Omega": "angle",
               "omega": "angle", "f": "angle", "M": "angle",
               **_orbit_fields.ALTERNATIVE_FIELDS}


def relative_state(name, units, mp, m, a, e, inc, Omega, omega, f, M):
    """Position and velocity, shape (3,) each, of body ``name`` (mass ``m``)
    relative to its primary (mass ``mp``), from its elements as plain floats in
    ``units`` (angles in rad; ``None`` for an angle not given).

    Raises
    ------
    ElementsError
        The elements are not finite, not an orbit, or both masses are zero.

    Examples
    --------
    >>> from orbits import UnitSystem
    >>> from orbits.bodies._elements import relative_state
    >>> pos, vel = relative_state("Earth", UnitSystem(), 1.0, 0.0, 1.0, 0.0, None,
    ...                           None, None, None, None)
    >>> pos.tolist()
    [1.0, 0.0, 0.0]
    """
    ang = dict(inc=inc, Omega=Omega, omega=omega, f=f, M=M)
    for key, val in (("a", a), ("e", e), *ang.items()):
        if val is not None and not math.isfinite(val):
            raise ElementsError(f"must be finite, got {val}", body=name, field=key)
    if e < 0:
        raise ElementsError(f"eccentricity must be >= 0, got {e}", body=name, field="e")
    if a == 0:
        raise ElementsError("semi-major axis must be non-zero", body=name, field="a")
    if a > 0 and e >= 1:
        raise ElementsError(f"e = {e} >= 1 needs a < 0 (a hyperbolic orbit); "
                            f"got a = {a} {units.length}. Parabolic orbits "
                            f"(e = 1) must be given as a state", body=name, field="e")
    if a < 0 and e <= 1:
        raise ElementsError(f"a < 0 means a hyperbolic orbit and needs e > 1; "
                            f"got e = {e}", body=name, field="e")
    if f is not None and M is not None:
        raise ElementsError("give the true anomaly f or the mean anomaly M, not both",
                            body=name, field="f")
    anomaly = f if f is not None else (
        _anomalies.true_from_mean(M, e) if M is not None else 0.0)
    mu = units.G * (mp + m)
    if mu <= 0:
        raise ElementsError("the primary and the body are both massless; an orbit "
                            "needs mass", body=name, field="primary")
    pos, vel = np.empty(3), np.empty(3)
    status = _elements.elements_to_state(mu, a, e, inc or 0.0, Omega or 0.0, omega or 0.0,
                                         anomaly, pos, vel)
    if status != 0:
        raise ElementsError(describe_status(status), body=name,
                            field="f" if f is not None else "elements")
    return pos, vel


def state_from_elements(bodies, name, m, primary, fields):
    """Position and velocity in the set's frame of a body ``name`` of mass ``m``
    (internal units) to be added to ``bodies``, from the orbit fields of
    :meth:`BodySet.add` (Quantities, or None where not given)."""
    mp, xp, vp = primary_state(bodies, name, primary, before=len(bodies))
    values = {key: None if val is None else bodies._scalar(val, FIELD_KINDS[key], name, key)
              for key, val in fields.items()}
    el = _orbit_fields.classical(name, bodies.units.G * (mp + m), values)
    pos, vel = relative_state(name, bodies.units, mp, m, el["a"],
                              0.0 if el["e"] is None else el["e"], el["inc"], el["Omega"],
                              el["omega"], el["f"], el["M"])
    return xp + pos, vp + vel


def _centre_of_mass(m, x, v):
    """Total mass, position and velocity of the centre of mass of ``m`` (> 0 in all)."""
    mt = m.sum()
    return mt, (m @ x) / mt, (m @ v) / mt


def primary_state(bodies, name, primary, before):
    """Mass, position and velocity (internal units) of the primary of ``name``.

    ``primary`` is a body's name, or None for the centre of mass of the first
    ``before`` bodies of the set.

    Raises
    ------
    BodyError
        No primary named where no body before has mass, or a primary that is
        not a name.
    UnknownBodyError
        No body of that name.
    """
    if primary is None:
        if before == 0 or not np.any(bodies._m[:before] > 0):
            raise BodyError("orbital elements need a primary: name one with "
                            "primary=, or add a massive body first",
                            body=name, field="primary")
        return _centre_of_mass(bodies._m[:before], bodies._x[:before], bodies._v[:before])
    if not isinstance(primary, str):
        raise BodyError(f"primary must be a body's name, got {primary!r}",
                        body=name, field="primary")
    if primary not in bodies._names:
        raise unknown_body(primary, bodies._names, field="primary", body=name,
                           what=f"unknown primary {primary!r}", label="known bodies")
    j = bodies._names.index(primary)
    return bodies._m[j], bodies._x[j], bodies._v[j]


def relative_to_primary(bodies, name, primary):
    """``mu = G (m_primary + m_body)`` and the state of ``name`` relative to its
    primary (internal units): a named body, the bodies before ``name`` (None), or
    the barycentre of all bodies, ``name`` included."""
    i = bodies.index(name)
    if _geometry.is_barycentre(primary):
        require_mass(bodies._m)
        mp = bodies._m.sum()
        xp, vp = bodies._com()
    else:
        if primary == name:
            raise BodyError("a body has no orbit about itself; name another primary",
                            body=name, field="primary")
        mp, xp, vp = primary_state(bodies, name, primary, before=i)
    mu = bodies.units.G * (mp + bodies._m[i])
    return mu, bodies._x[i] - xp, bodies._v[i] - vp


def element_values(bodies, name, primary):
    """``(a, e, inc, Omega, omega, f, M)`` of ``name`` about ``primary`` in internal
    units and rad, shape (7,), and the kernel's status."""
    mu, r, v = relative_to_primary(bodies, name, primary)
    out = np.empty(7)
    status = _elements.state_to_elements(mu, r, v, out)
    return out, status


def bound_elements(bodies, i):
    """``(a, e, inc)`` of body ``i`` about the centre of mass of the bodies before it
    (internal units, inc in rad), or None where that orbit is not a bound ellipse."""
    if i == 0 or not bodies._m[:i].sum() > 0:
        return None
    mt, xp, vp = _centre_of_mass(bodies._m[:i], bodies._x[:i], bodies._v[:i])
    mu = bodies.units.G * (mt + bodies._m[i])
    out = np.empty(7)
    status = _elements.state_to_elements(mu, bodies._x[i] - xp, bodies._v[i] - vp, out)
    if status != 0 or not (0 <= out[1] < 1 and out[0] > 0):
        return None
    return float(out[0]), float(out[1]), float(out[2])

"""Orbital elements of a result's bodies over its outputs: the osculating
elements about a chosen primary, the mutual inclination of two orbits, and
the elements as a plain table (:class:`~orbits.Result`'s methods
``elements``, ``mutual_inclination`` and ``elements_table``).
"""

import math

import astropy.units as u
import numpy as np

from ._kernels import elements as _elements
from ._kernels.status import describe_status
from ._result_exports import _label
from .body import unknown_body
from .errors import BodyError, ElementsError, NoMassiveBodyError
from .geometry import angle_between, barycentre, is_barycentre

__all__ = []

#: the osculating elements, in the columns of the compiled kernel's output
_ELEMENT_KEYS = ("a", "e", "inc", "Omega", "omega", "f", "M")


def elements(result, body, primary=None):
    """Osculating orbital elements of a body at every output.

    The elements, angle conventions and default primary of
    :meth:`orbits.BodySet.elements`, from the same compiled kernel, run on
    all outputs at once; and the orbital period.

    Parameters
    ----------
    body : str
        The body's name.
    primary : str, optional
        The body the orbit is about, by name; or ``"barycentre"`` (or
        ``"barycenter"``): the centre of mass of all bodies at each output,
        ``body`` included, with ``mu = G (M + m)`` (REBOUND's
        ``particle.orbit(primary=sim.com())``; bodies merged away by a
        collision left out).  Default: the centre of mass of the bodies
        before ``body`` in the set (Jacobi-like, as in
        :meth:`~orbits.BodySet.elements` and REBOUND's ``Particle.orbit()``).

    Returns
    -------
    dict of Quantity, each of shape (n,) for n outputs
        ``a`` (length; negative for a hyperbolic orbit), ``e``
        (dimensionless), ``inc``, ``Omega``, ``omega``, ``f``, ``M`` (angles
        in rad), and ``P`` (time; NaN for a hyperbolic orbit, which has no
        period), in the run's unit system.

    Raises
    ------
    UnknownBodyError
        ``body`` or ``primary`` is not one of the bodies.
    BodyError
        ``primary`` is ``body`` itself, or no massive body comes before
        ``body`` in the set and no primary is named.
    ElementsError
        At some output the state describes no orbit: the body is on its
        primary, or the orbit is radial or parabolic to within rounding.  The
        message gives the first such output.

    Notes
    -----
    With ``mu = G (m_primary + m_body)`` and the relative state ``r, v``:
    ``1/a = 2/|r| - |v|^2/mu``, the eccentricity vector is
    ``(v x h)/mu - r/|r|`` with ``h = r x v``, and ``P = 2 pi sqrt(a^3/mu)``.
    ``inc`` lies in [0, pi], ``Omega`` and ``omega`` in [0, 2 pi), ``f`` and
    ``M`` in [-pi, pi]; ``M`` of a hyperbola is ``e sinh F - F``.  REBOUND
    reduces some angles to other ranges (compare them modulo 2 pi) and gives
    a hyperbola the negative period ``-2 pi sqrt(|a|^3/mu)``.

    Examples
    --------
    >>> el = planets.elements("Jupiter", primary="Sun")
    >>> el["a"].shape
    (11,)
    >>> print(el["a"][0].round(2), el["P"][0].to(u.yr).round(1))
    5.2 AU 11.9 yr
    """
    U = result.units
    mu, dx, dv, here = _relative_states(result, body, primary)
    n = len(mu)
    out = np.full((n, 7), np.nan)
    status = np.zeros(n, dtype=np.int64)
    if here.all():
        _elements.state_to_elements_many(mu, dx, dv, out, status)
    elif here.any():
        part = np.empty((int(here.sum()), 7))
        st = np.zeros(len(part), dtype=np.int64)
        _elements.state_to_elements_many(np.ascontiguousarray(mu[here]),
                                         np.ascontiguousarray(dx[here]),
                                         np.ascontiguousarray(dv[here]), part, st)
        out[here], status[here] = part, st
    bad = np.flatnonzero(status)
    if bad.size:
        k = int(bad[0])
        more = f" (and at {bad.size - 1} later outputs)" if bad.size > 1 else ""
        raise ElementsError(f"at output {k} (t = {result.times[k]:.10g}){more}: "
                            f"{describe_status(status[k])}", body=body,
                            field="elements")
    a = out[:, 0]
    period = np.full(n, np.nan)
    bound = a > 0
    period[bound] = 2.0 * math.pi * np.sqrt(a[bound] ** 3 / mu[bound])
    q = U.quantity
    elements = {"a": q(a, "length"), "e": out[:, 1] << u.dimensionless_unscaled}
    for k, key in enumerate(_ELEMENT_KEYS[2:], start=2):
        elements[key] = out[:, k] << u.rad
    elements["P"] = q(period, "time")
    return elements


def _relative_states(result, body, primary):
    """``mu`` (n,), the body's position and velocity relative to its
    primary (n, 3) each, in the run's internal units, and where both are
    present (n,) (False once a collision merged either away)."""
    i = result._index(body)
    U, x, v, m = result._internal()
    n = x.shape[0]
    # masses at each output where collisions changed them (NaN: merged
    # away), else the masses at the start for every output
    mh = (np.nan_to_num(result.masses_at_outputs.to_value(U.unit("mass")))
          if result.masses_at_outputs is not None else np.broadcast_to(m, (n, len(m))))
    if is_barycentre(primary):
        if not np.any(m > 0):
            raise NoMassiveBodyError("the barycentre needs a body with positive mass")
        mp, xp, vp = barycentre(mh, x, v)
    elif primary is None:
        interior = m[:i]
        if i == 0 or not np.any(interior > 0):
            raise BodyError("orbital elements need a primary: no massive body comes "
                            "before this one in the set; name one with primary=",
                            body=body, field="primary")
        w = mh[:, :i]
        mp = w.sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            xp = np.einsum("kj,kjd->kd", w, np.nan_to_num(x[:, :i])) / mp[:, None]
            vp = np.einsum("kj,kjd->kd", w, np.nan_to_num(v[:, :i])) / mp[:, None]
    else:
        if not isinstance(primary, str) or primary not in result.names:
            raise unknown_body(primary, result.names, field="primary", body=body,
                               what=f"unknown primary {primary!r}",
                               label="known bodies")
        j = result.names.index(primary)
        if j == i:
            raise BodyError("a body has no orbit about itself; name another primary",
                            body=body, field="primary")
        mp, xp, vp = mh[:, j], x[:, j], v[:, j]
    mu = np.ascontiguousarray(U.G * (mp + mh[:, i]), dtype=float)
    if not np.any(mu > 0):
        raise ElementsError("the primary and the body are both massless; an orbit "
                            "needs mass", body=body, field="primary")
    # outputs after a collision merged the body (or its primary) away: NaN
    here = np.isfinite(x[:, i, 0]) & np.isfinite(xp[:, 0])
    return (mu, np.ascontiguousarray(x[:, i] - xp), np.ascontiguousarray(v[:, i] - vp),
            here)


def mutual_inclination(result, a, b, primary=None):
    """The angle between the orbital planes of two bodies at every output.

    Parameters
    ----------
    a, b, primary
        As for :meth:`orbits.BodySet.mutual_inclination`.

    Returns
    -------
    Quantity, shape (n,), rad
        The angle :meth:`orbits.BodySet.mutual_inclination` gives, at each
        output; NaN at outputs after a collision merged either body (or its
        primary) away.

    Raises
    ------
    UnknownBodyError, BodyError
        A name is not one of the bodies', or an orbit has no primary, as for
        :meth:`elements`.

    Examples
    --------
    >>> planets.mutual_inclination("Jupiter", "Saturn", primary="Sun")[[0, -1]].to(u.deg).round(3)
    <Quantity [1.251, 1.253] deg>
    """
    normals = []
    for name in (a, b):
        _, dx, dv, here = _relative_states(result, name, primary)
        h = np.cross(dx, dv)
        h[~here] = np.nan
        normals.append(h)
    return angle_between(*normals) << u.rad


def elements_table(result, body, primary=None):
    """:meth:`elements` at every output as a plain table for people and files.

    Parameters
    ----------
    body : str
        The body's name.
    primary : str, optional
        As for :meth:`elements`.

    Returns
    -------
    columns : list of str
        ``"time [d]"``, ``"a [AU]"``, ``"e"``, ``"inc [deg]"``,
        ``"Omega [deg]"``, ``"omega [deg]"``, ``"f [deg]"``, ``"M [deg]"``,
        ``"P [d]"``: the run's units of time and length, angles in degrees.
    table : ndarray, shape (n, 9)
        One row per output.

    Raises
    ------
    UnknownBodyError, BodyError, ElementsError
        As :meth:`elements` raises them.

    Examples
    --------
    >>> columns, table = planets.elements_table("Saturn", primary="Sun")
    >>> columns[:4], table.shape
    (['time [d]', 'a [AU]', 'e', 'inc [deg]'], (11, 9))
    """
    el = result.elements(body, primary=primary)
    values = [result.times.value]
    columns = [_label("time", result.times.unit)]
    for key in (*_ELEMENT_KEYS, "P"):
        q = el[key].to(u.deg) if el[key].unit == u.rad else el[key]
        values.append(q.value)
        columns.append(_label(key, q.unit))
    return columns, np.column_stack(values)

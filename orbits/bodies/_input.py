"""What enters a body set, checked where it enters and written down as given.

Names, masses, radii, positions and velocities are refused with a
:class:`~orbits.errors.BodyError` that names the body and the field: one set
of checks for a body added alone (:meth:`~orbits.BodySet.add`) and for arrays
of them (:meth:`~orbits.BodySet.from_arrays`).  :func:`describe` writes a
value given as the set's ``history`` records it.
"""

import functools

import astropy.units as u
import numpy as np

from ..errors import BodyError, CoincidentBodiesError, DuplicateBodyError, NoMassiveBodyError

__all__ = ["check_name", "check_names", "internal", "check_masses", "check_radii",
           "check_states", "require_mass", "check_distinct_positions", "describe",
           "unit_string"]

#: what a value of each shape is called in a message
_SHAPE_WORDS = {(): "a scalar", (3,): "3 components (x, y, z)"}

#: bodies up to which :func:`check_distinct_positions` compares every pair at
#: once, an (N, N, 3) array; above, it sorts the positions (np.unique over rows)
_PAIRWISE_UP_TO = 64


def check_name(name):
    """Refuse a name that is not a non-empty string, or that an HDF5 file cannot
    hold: a NUL character, or a lone surrogate (text that UTF-8 cannot encode).

    Examples
    --------
    >>> from orbits.bodies._input import check_name
    >>> check_name("Jupiter")
    >>> try:
    ...     check_name("")
    ... except ValueError as exc:
    ...     print(exc)
    body '', field 'name': name must be a non-empty string, got ''
    """
    if not isinstance(name, str) or not name:
        raise BodyError(f"name must be a non-empty string, got {name!r}",
                        body=name, field="name")
    if "\0" in name:
        raise BodyError("name must not contain a NUL character ('\\x00'), which an output "
                        "file cannot hold", body=name, field="name")
    try:
        name.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise BodyError(f"name must be text that UTF-8 can encode; character "
                        f"{exc.object[exc.start]!r} at {exc.start} is a lone surrogate",
                        body=name, field="name") from None


def check_names(names, existing=()):
    """Each of ``names`` a valid name (:func:`check_name`), none of them twice and
    none in ``existing``; a :class:`~orbits.errors.DuplicateBodyError` names the first
    repeated one."""
    seen = set(existing)
    for name in names:
        check_name(name)
        if name in seen:
            raise DuplicateBodyError("a body of this name is already in the set",
                                     body=name, field="name")
        seen.add(name)


def internal(units, value, kind, shape, *, bare_ok, body=None, field):
    """``value`` as float64 in the internal unit of ``kind``, of ``shape``.

    Parameters
    ----------
    units : UnitSystem
    value : Quantity or array_like
        Plain numbers are read in ``units`` where ``bare_ok``.
    kind : str
        A kind of :meth:`UnitSystem.unit`: ``"mass"``, ``"length"``, ...
    shape : tuple
        The shape wanted; ``None`` for a length of any size.
    bare_ok : bool
    body, field : str
        Named in the error.

    Returns
    -------
    ndarray
        C-contiguous float64; it may share memory with ``value``.

    Raises
    ------
    BodyUnitsError
        The wrong physical type, or a plain number where a Quantity is needed.
    BodyError
        The wrong shape.
    """
    val = units.to_internal(value, kind, bare_ok=bare_ok, body=body, field=field)
    if val.ndim != len(shape) or any(s is not None and s != d
                                     for s, d in zip(shape, val.shape)):
        want = _SHAPE_WORDS.get(shape) or (
            "shape (" + ", ".join("N" if s is None else str(s) for s in shape) + ")")
        raise BodyError(f"expected {want}, got shape {val.shape}", body=body, field=field)
    return val if val.flags.c_contiguous else np.ascontiguousarray(val)


def _first_bad(ok, values, names, field, message):
    """A BodyError for the first body where ``ok`` is False: ``message`` with its
    value in place of ``{}``."""
    if not np.all(ok):
        i = int(np.argmin(ok))
        raise BodyError(message.format(values[i]), body=names[i], field=field)


def check_masses(m, names, unit):
    """Each mass of ``m`` (shape (N,), in ``unit``) finite and >= 0."""
    _first_bad(np.isfinite(m), m, names, "mass", "mass must be finite, got {}")
    _first_bad(m >= 0, m, names, "mass", f"mass must be >= 0, got {{}} {unit}")


def check_radii(r, names, unit):
    """Each radius of ``r`` (shape (N,), in ``unit``) finite and >= 0."""
    _first_bad(np.isfinite(r) & (r >= 0), r, names, "radius",
               f"radius must be finite and >= 0, got {{}} {unit}")


def check_states(x, v, names):
    """Each position and velocity (shape (N, 3)) finite."""
    for field, arr in (("position", x), ("velocity", v)):
        _first_bad(np.all(np.isfinite(arr), axis=1), arr, names, field,
                   f"{field} must be finite, got {{}}")


def require_mass(m):
    """Refuse a set with no body of positive mass (``m``, shape (N,))."""
    if len(m) == 0 or not np.any(m > 0):
        raise NoMassiveBodyError(
            f"the body set has no body with positive mass ({len(m)} bodies); "
            "at least one is needed")


def check_distinct_positions(names, x, unit):
    """Refuse two bodies at one position (``x``, shape (N, 3), in ``unit``): their
    mutual force is infinite.  The error names the first such body and the others
    at its place."""
    n = len(names)
    if n < 2:
        return
    if n <= _PAIRWISE_UP_TO:
        same = (x[:, None, :] == x[None, :, :]).all(axis=2)
        np.fill_diagonal(same, False)
        repeated = same.any(axis=1)
        found, j = bool(repeated.any()), int(np.argmax(repeated))
    else:
        _, first, counts = np.unique(x, axis=0, return_index=True, return_counts=True)
        found, j = bool(np.any(counts > 1)), first[np.argmax(counts > 1)]
    if found:
        same = [names[k] for k in range(n) if np.array_equal(x[k], x[j])]
        raise CoincidentBodiesError(
            f"is at the same position as {', '.join(map(repr, same[1:]))} "
            f"({x[j]} {unit}); bodies must be at distinct positions",
            body=same[0], field="position")


def describe(value):
    """``str(value)``, with a Quantity's unit formatted once per unit (astropy
    formats it anew at every ``str()``): how the set's ``history`` and a system
    file's cells write a value given.

    Examples
    --------
    >>> from orbits.bodies._input import describe
    >>> describe(5.2 * u.au), describe(0.048)
    ('5.2 AU', '0.048')
    """
    if isinstance(value, u.Quantity):
        unit = unit_string(value.unit)
        return f"{value.value} {unit}" if unit else str(value.value)
    return str(value)


@functools.lru_cache(maxsize=64)
def unit_string(unit):
    """``unit.to_string()``, kept for each unit seen."""
    return unit.to_string()

"""A force term's parameters checked where they enter: body names, finite
numbers, lengths, time scales and spins, and each converted once, when the
term is bound, through the body set's :class:`~orbits.units.UnitSystem`.

Every failure is a :class:`~orbits.errors.ForceTermError` (or, for a value
in the wrong unit, a :class:`~orbits.errors.BodyUnitsError`) that names the
term, the parameter and the body concerned.
"""

import math

import astropy.constants as const
import astropy.units as u
import numpy as np

from ..errors import BodyUnitsError, ForceTermError

__all__ = ["body_name", "number", "positive_length", "internal", "speed_of_light",
           "angular_velocity", "check_spin"]


def body_name(value, term, field, *, optional=False, body=None):
    """``value``, which must be a body's name (or None, where ``optional``)."""
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise ForceTermError(f"{field} must be a body's name{' or None' if optional else ''}, "
                             f"got {value!r}", term=term, field=field, body=body)
    return value


def number(value, term, field, body=None):
    """``value`` as a finite float, or a named error."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        out = math.nan
    if not math.isfinite(out):
        raise ForceTermError(f"expected a finite number, got {value!r}", term=term,
                             field=field, body=body)
    return out


def positive_length(value, term, body=None, field="radius"):
    """Check that ``value`` (a plain number: a length's value) is a positive
    finite scalar."""
    value = np.asarray(value, dtype=float)
    if value.shape != () or not (value > 0 and math.isfinite(value)):
        raise ForceTermError(f"expected a positive finite {field}, got {value}", term=term,
                             field=field, body=body)


def internal(value, kind, ctx, field):
    """A Quantity of ``kind`` (or, where the body set allows, a plain number)
    as a float in the internal units."""
    return float(ctx.units.to_internal(value, kind, bare_ok=ctx.bare_ok, field=field))


def speed_of_light(term, ctx):
    """The term's ``c`` (astropy's when None) in internal units: positive and finite."""
    cv = internal(const.c if term.c is None else term.c, "velocity", ctx, "c")
    if not (cv > 0 and math.isfinite(cv)):
        raise ForceTermError(f"the speed of light must be a positive finite speed, got "
                             f"{term.c}", term=repr(term), field="c")
    return cv


def angular_velocity(value, ctx, term):
    """An angular velocity 3-vector in rad per internal time unit (zero for
    None); astropy's ``dimensionless_angles`` lets it be given as ``rad / s``
    or as ``1 / s`` alike."""
    per_time = u.rad / ctx.units.unit("time")
    if value is None:
        return np.zeros(3)
    if isinstance(value, u.Quantity):
        try:
            out = np.asarray(value.to_value(per_time, equivalencies=u.dimensionless_angles()),
                             dtype=np.float64)
        except u.UnitConversionError:
            raise BodyUnitsError(f"expected an angular velocity (e.g. in {per_time}), got "
                                 f"{value.unit.physical_type} ({value.unit})",
                                 field="spin") from None
    else:
        try:  # plain numbers where the body set's own units are implied, as for lengths
            out = ctx.units.to_internal(value, "velocity", bare_ok=ctx.bare_ok, field="spin")
        except BodyUnitsError:
            raise BodyUnitsError(f"expected a Quantity with a unit of angular velocity (e.g. "
                                 f"{per_time}), got the bare value {value!r}",
                                 field="spin") from None
    check_spin(out, term)
    return np.ascontiguousarray(out, dtype=np.float64)


def check_spin(value, term):
    """Check that ``value`` is a finite 3-vector."""
    value = np.asarray(value, dtype=float)
    if value.shape != (3,) or not np.all(np.isfinite(value)):
        raise ForceTermError(f"spin must be a finite angular-velocity 3-vector, got {value}",
                             term=term, field="spin")

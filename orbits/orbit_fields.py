"""REBOUND's other ways to give an orbit, resolved to the classical elements.

Besides the semi-major axis ``a`` and the angles ``omega`` (argument of
pericentre) and ``f`` or ``M`` (true or mean anomaly), an orbit may be given
as REBOUND's ``Particle`` takes it (Murray & Dermott 1999, ch. 2):

==========  ====================================  ==================================
field       meaning                               in place of
==========  ====================================  ==================================
``P``       orbital period                        ``a = (mu P^2 / 4 pi^2)^(1/3)``
``pomega``  longitude of pericentre               ``omega = pomega - Omega``
``l``       mean longitude                        ``M = l - pomega``
``theta``   true longitude                        ``f = theta - pomega``
``E``       eccentric anomaly                     ``f``, from ``tan(f/2) =
                                                  sqrt((1+e)/(1-e)) tan(E/2)``
``T``       time of pericentre passage            ``M = n (t - T)``, ``t = 0``
==========  ====================================  ==================================

with ``mu = G (m_primary + m_body)``, the two-body ``GM`` that
:meth:`~orbits.BodySet.add` uses for every orbit, ``n = sqrt(mu / |a|^3)`` the
mean motion, and ``pomega = Omega + omega`` however the pericentre was given.
For a retrograde orbit (``inc`` above 90 degrees) the longitudes are measured
the other way round, ``pomega = Omega - omega``, ``l = pomega - M``,
``theta = pomega - f``, so that ``pomega`` stays the direction of pericentre
for an orbit near the reference plane whichever way it goes round; REBOUND
measures them so too.  ``t = 0`` is the instant of the body set's states: a
simulation made from the set starts its clock there, so ``T`` is a time on
that clock (negative for a pericentre passed before the start).

One field of each group places the orbit: ``a`` or ``P``; ``omega`` or
``pomega`` (both only if they agree with ``Omega``); one of ``f``, ``M``,
``E``, ``l``, ``theta``, ``T``.  A conflict or an orbit that the fields cannot
describe (``P`` or ``E`` of an unbound orbit) is an
:class:`~orbits.errors.ElementsError` naming the body and the fields.

References
----------
Murray, C. D. & Dermott, S. F. 1999, *Solar System Dynamics*, Cambridge
University Press, ch. 2 (eqs. 2.39, 2.46, 2.52, 2.71 and the longitudes of
sec. 2.9).
"""

import math

from .errors import ElementsError

__all__ = ["PHASE_FIELDS", "ALTERNATIVE_FIELDS", "classical"]

#: The fields that place the body along its orbit; at most one is given
#: (default ``f = 0``, the body at pericentre).
PHASE_FIELDS = ("f", "M", "E", "l", "theta", "T")

#: The fields besides the classical ones, with the kind of quantity each is.
ALTERNATIVE_FIELDS = {"P": "time", "pomega": "angle", "l": "angle", "T": "time",
                      "E": "angle", "theta": "angle"}

#: Rounding allowed between ``pomega`` and ``Omega + omega`` when all three are
#: given, in units of float64's epsilon times the angles' sizes: each angle
#: is rounded once when converted to radians and once in the sum.
AGREEMENT_ULPS = 8

_TWO_PI = 2.0 * math.pi


def classical(name, mu, fields):
    """The classical elements of an orbit given by any of REBOUND's fields.

    Parameters
    ----------
    name : str
        The body's name, for the errors.
    mu : float
        ``G (m_primary + m_body)`` in the body set's units.
    fields : dict of str to float or None
        ``a, P, e, inc, Omega, omega, pomega, f, M, E, l, theta, T`` as plain
        numbers in the body set's units (angles in rad); ``None`` where not
        given.

    Returns
    -------
    dict of str to float or None
        ``a, e, inc, Omega, omega, f, M``, ready for the conversion to a state
        (at most one of ``f`` and ``M`` not None).

    Raises
    ------
    ElementsError
        Conflicting or missing fields, a field that is not finite, a period
        that is not positive or belongs to an unbound orbit, an eccentric
        anomaly of an unbound orbit.

    Examples
    --------
    >>> import math
    >>> from orbits.orbit_fields import classical
    >>> fields = dict.fromkeys(["a", "e", "inc", "Omega", "omega", "pomega", "f", "M",
    ...                         "E", "l", "theta", "T"])
    >>> out = classical("Earth", 4 * math.pi ** 2, {**fields, "P": 1.0, "pomega": 1.0,
    ...                                              "l": 1.5})
    >>> round(out["a"], 12), out["omega"], out["M"]
    (1.0, 1.0, 0.5)
    """
    given = {k: v for k, v in fields.items() if v is not None}
    for key, val in given.items():
        if not math.isfinite(val):
            raise ElementsError(f"must be finite, got {val}", body=name, field=key)
    out = {k: given.get(k) for k in ("e", "inc", "Omega")}
    e = given.get("e", 0.0)
    if e < 0:
        raise ElementsError(f"eccentricity must be >= 0, got {e}", body=name, field="e")

    if "a" in given and "P" in given:
        raise ElementsError("give the semi-major axis a or the period P, not both",
                            body=name, field="P")
    if "P" in given:
        out["a"] = _axis_from_period(name, mu, given["P"], e)
    elif "a" in given:
        out["a"] = given["a"]
    else:
        raise ElementsError("orbital elements need the semi-major axis a or the period P",
                            body=name, field="a")

    # +1 prograde, -1 retrograde: the sense in which the longitudes are measured
    sense = -1.0 if given.get("inc", 0.0) > 0.5 * math.pi else 1.0
    Omega = given.get("Omega", 0.0)
    if "pomega" in given:
        if "omega" in given:
            _check_agreement(name, given["pomega"], Omega, sense * given["omega"],
                             "Omega" in given, sense)
            out["omega"] = given["omega"]
        else:
            out["omega"] = sense * (given["pomega"] - Omega)
    else:
        out["omega"] = given.get("omega")
    pomega = (given["pomega"] if "pomega" in given
              else Omega + sense * given.get("omega", 0.0))

    phase = [k for k in PHASE_FIELDS if k in given]
    if len(phase) > 1:
        raise ElementsError(f"give one of {', '.join(PHASE_FIELDS)} to place the body on its "
                            f"orbit, not several (got {', '.join(phase)})",
                            body=name, field=phase[0])
    out["f"] = out["M"] = None
    which = phase[0] if phase else None
    if which in ("f", "M"):
        out[which] = given[which]
    elif which == "theta":
        out["f"] = sense * (given["theta"] - pomega)
    elif which == "l":
        out["M"] = sense * (given["l"] - pomega)
    elif which == "E":
        out["f"] = _true_from_eccentric(name, given["E"], e)
    elif which == "T":
        out["M"] = _mean_from_pericentre_time(name, mu, out["a"], given["T"])
    return out


def _axis_from_period(name, mu, P, e):
    """Kepler's third law, ``a^3 = mu P^2 / (4 pi^2)`` (M&D eq. 2.22)."""
    if not P > 0:
        raise ElementsError(f"the period must be positive, got {P}", body=name, field="P")
    if e >= 1:
        raise ElementsError(f"a period belongs to a bound orbit (0 <= e < 1), got e = {e}; "
                            "give the semi-major axis a (negative) for an unbound one",
                            body=name, field="P")
    if not mu > 0:
        raise ElementsError("the primary and the body are both massless; a period "
                            "needs mass", body=name, field="P")
    return (mu * (P / _TWO_PI) ** 2) ** (1.0 / 3.0)


def _check_agreement(name, pomega, Omega, omega, Omega_given, sense):
    """``pomega = Omega + omega`` to rounding, modulo a whole turn (``omega``
    signed by the sense of the orbit)."""
    off = math.remainder(pomega - (Omega + omega), _TWO_PI)
    scale = abs(pomega) + abs(Omega) + abs(omega) + _TWO_PI
    if abs(off) > AGREEMENT_ULPS * 2.220446049250313e-16 * scale:
        which = "Omega, omega and pomega" if Omega_given else "omega and pomega (Omega = 0)"
        rule = "Omega + omega" if sense > 0 else "Omega - omega (a retrograde orbit)"
        raise ElementsError(f"{which} disagree: pomega must be {rule}, and differs "
                            f"from it by {off:.3g} rad; give omega or pomega, not both",
                            body=name, field="pomega")


def _true_from_eccentric(name, E, e):
    """``tan(f/2) = sqrt((1+e)/(1-e)) tan(E/2)`` (M&D eq. 2.46), in the same
    revolution as ``E``."""
    if e >= 1:
        raise ElementsError(f"the eccentric anomaly belongs to a bound orbit (0 <= e < 1), "
                            f"got e = {e}; give f or M for an unbound one",
                            body=name, field="E")
    turns = round(E / _TWO_PI)
    half = 0.5 * (E - turns * _TWO_PI)
    f = 2.0 * math.atan2(math.sqrt(1.0 + e) * math.sin(half),
                         math.sqrt(1.0 - e) * math.cos(half))
    return f + turns * _TWO_PI


def _mean_from_pericentre_time(name, mu, a, T):
    """``M = n (t - T)`` at ``t = 0``, ``n = sqrt(mu / |a|^3)`` (M&D eq. 2.52;
    for a hyperbola the hyperbolic mean anomaly)."""
    if not mu > 0:
        raise ElementsError("the primary and the body are both massless; a time of "
                            "pericentre needs mass", body=name, field="T")
    return -math.sqrt(mu / abs(a) ** 3) * T

"""Epochs: the date of a body set's state, as an ``astropy.time.Time`` in TDB.

A :class:`~orbits.BodySet` may carry an epoch, the instant its positions and
velocities hold at; a :class:`~orbits.Simulation` made from it keeps it as
the date of its time 0, and a :class:`~orbits.Result` gives the dates of its
outputs, ``result.epochs = epoch + result.times``.  Everything here is in
Barycentric Dynamical Time (TDB), the time argument of the JPL ephemerides
and of the equations of motion in the solar system's barycentric frame: a
Time of another scale is carried to TDB (without the network: astropy's
built-in leap-second table), anything else is an
:class:`~orbits.errors.EpochError`.

In text (system files) an epoch is written as its Julian date in two parts,
``"2451545.0 + 0.0 TDB"``, which reads back bit for bit; a person may also
write any date astropy reads, with its scale (``"2000-01-01T12:00:00 TDB"``,
``"2024-03-01 UTC"``; TDB when none is given).  Output files keep the two
parts as a ``(2,)`` float64 attribute (:mod:`orbits.io.h5md`).

``astropy.time`` is imported only when a date is made or read (it costs
about 50 ms, which a run without an epoch does not pay).

Examples
--------
>>> from astropy.time import Time
>>> from orbits import epochs
>>> e = epochs.as_epoch(Time("2000-01-01T12:00:00", scale="tt"))
>>> e.scale, epochs.to_text(e)
('tdb', '2451545.0 - 1.1493888766642878e-09 TDB')
>>> epochs.from_text("2451545.0 + 0.0 TDB").isot
'2000-01-01T12:00:00.000'
"""

import math
import re
import sys

import numpy as np

from .errors import EpochError

__all__ = ["as_epoch", "parse", "from_text", "to_text", "from_pair", "to_pair", "describe",
           "at_times", "is_time", "to_tdb"]

# "2451545.0", "2451545.0 + 0.25", "2451545 - 0.5": a Julian date in one or two parts
_NUMBER = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_JD = re.compile(rf"\s*(?:JD\s*)?({_NUMBER})(?:\s*([-+])\s*({_NUMBER}))?\s*", re.IGNORECASE)


def _Time():
    # astropy.time (and erfa) load when a date is first read: a body set
    # without an epoch never needs them
    from astropy.time import Time
    return Time


def is_time(value):
    """Whether ``value`` is an ``astropy.time.Time`` (without importing astropy.time).

    Examples
    --------
    >>> from astropy.time import Time
    >>> from orbits import epochs
    >>> epochs.is_time(Time(2451545.0, format="jd")), epochs.is_time(2451545.0)
    (True, False)
    """
    module = sys.modules.get("astropy.time")
    return module is not None and isinstance(value, module.Time)


def as_epoch(value, field="epoch"):
    """``value``, one ``astropy.time.Time``, in TDB.

    Parameters
    ----------
    value : astropy.time.Time
        A single date of any scale (UTC, TT, TAI, TCB, ... are converted;
        UT1 needs the IERS tables astropy has on disk).
    field : str
        The name used in messages.

    Returns
    -------
    astropy.time.Time
        Scalar, scale ``"tdb"``, format ``"jd"``.

    Raises
    ------
    EpochError
        Not a Time, not a single date, not finite, or not convertible to TDB
        without the network.

    Examples
    --------
    >>> from astropy.time import Time
    >>> from orbits import epochs
    >>> epochs.as_epoch(Time("2000-01-01T11:58:55.816", scale="utc")).isot
    '2000-01-01T12:00:00.000'
    """
    if not is_time(value):
        raise EpochError(f"{field} must be an astropy.time.Time, got {type(value).__name__}; "
                         f"write Time('2000-01-01T12:00:00', scale='tdb'), or "
                         f"Time(2451545.0, format='jd', scale='tdb')")
    if not value.isscalar:
        raise EpochError(f"{field} must be a single date, got a Time of shape {value.shape}")
    if value.scale != "tdb":
        try:
            value = to_tdb(value)
        except Exception as exc:
            raise EpochError(f"{field}: cannot carry the date from {value.scale.upper()} to "
                             f"TDB without the network ({exc})") from None
    jd1, jd2 = float(value.jd1), float(value.jd2)
    if not (math.isfinite(jd1) and math.isfinite(jd2)):
        raise EpochError(f"{field} must be a finite date, got {value}")
    return from_pair(jd1, jd2)


def to_tdb(time):
    """``time``, an ``astropy.time.Time`` of any shape and scale, in TDB, converted
    without the network.

    UTC needs the leap-second table and UT1 the IERS tables: astropy's copies on
    disk are used, never fresher ones from the network.

    Examples
    --------
    >>> from astropy.time import Time
    >>> from orbits import epochs
    >>> epochs.to_tdb(Time(["2000-01-01T12:00:00"], scale="tt")).scale
    'tdb'
    """
    if time.scale == "tdb":
        return time
    # the IERS tables' settings load with the one conversion that reads them
    from astropy.utils import iers
    with iers.conf.set_temp("auto_download", False):
        return time.tdb


def from_pair(jd1, jd2, field="epoch"):
    """The TDB date whose Julian date is ``jd1 + jd2`` (floats, kept as they are).

    Examples
    --------
    >>> from orbits import epochs
    >>> e = epochs.from_pair(2451545.0, 0.25)
    >>> epochs.to_pair(e), e.scale
    ((2451545.0, 0.25), 'tdb')
    """
    jd1, jd2 = float(jd1), float(jd2)
    if not (math.isfinite(jd1) and math.isfinite(jd2)):
        raise EpochError(f"{field} must be a finite Julian date, got {jd1!r} + {jd2!r}")
    return _Time()(jd1, jd2, format="jd", scale="tdb")


def to_pair(epoch):
    """The two parts ``(jd1, jd2)`` of a TDB epoch's Julian date (floats).

    Examples
    --------
    >>> from astropy.time import Time
    >>> from orbits import epochs
    >>> epochs.to_pair(Time(2451545.0, format="jd", scale="tdb"))
    (2451545.0, 0.0)
    """
    return float(epoch.jd1), float(epoch.jd2)


def to_text(epoch):
    """The text a system file holds for ``epoch``: its two-part Julian date in
    TDB, ``"jd1 + jd2 TDB"``, read back bit for bit by :func:`from_text`.

    Examples
    --------
    >>> from orbits import epochs
    >>> epochs.to_text(epochs.from_pair(2451545.0, -0.125))
    '2451545.0 - 0.125 TDB'
    """
    jd1, jd2 = to_pair(epoch)
    sign = "-" if math.copysign(1.0, jd2) < 0 else "+"
    return f"{jd1!r} {sign} {abs(jd2)!r} TDB"


def from_text(text, field="epoch"):
    """A date from text: a Julian date in one or two parts (``"2451545.0 +
    0.25"``) or any date astropy reads (``"2000-01-01T12:00:00"``), then
    optionally a time scale (``TDB``, ``TT``, ``UTC``, ``TAI``, ``TCB``, ...;
    TDB when none); carried to TDB as :func:`as_epoch` does.

    Raises
    ------
    EpochError
        Text that is no date.

    Examples
    --------
    >>> from orbits import epochs
    >>> epochs.from_text("2000-01-01 11:58:55.816 UTC").isot
    '2000-01-01T12:00:00.000'
    >>> epochs.to_pair(epochs.from_text("JD 2451545.0"))
    (2451545.0, 0.0)
    """
    Time = _Time()
    if not isinstance(text, str):
        raise EpochError(f"{field} must be a date as text, got {type(text).__name__}")
    words = text.split()
    scale = "tdb"
    if len(words) > 1 and words[-1].lower() in Time.SCALES:
        scale = words[-1].lower()
        text = " ".join(words[:-1])
    m = _JD.fullmatch(text)
    try:
        if m:
            jd2 = 0.0 if m.group(3) is None else float(m.group(3))
            if m.group(2) == "-":
                jd2 = -jd2
            date = Time(float(m.group(1)), jd2, format="jd", scale=scale)
        else:
            date = Time(text.strip(), scale=scale)
    except (ValueError, TypeError) as exc:
        # astropy's one-line reasons say something (a bad month); its list of
        # every format it tried does not
        detail = "" if "\n" in str(exc) else f" ({exc})"
        raise EpochError(f"{field}: cannot read {text.strip()!r} as a date{detail}; write "
                         f"'2000-01-01T12:00:00 TDB' or a Julian date, '2451545.0 TDB'") \
            from None
    return as_epoch(date, field)


def parse(value, field="epoch"):
    """A scene's or a command's date: a Time (any scale), text as
    :func:`from_text` reads it, or a Julian date in TDB (a number); in TDB.

    Examples
    --------
    >>> from orbits import epochs
    >>> [epochs.to_pair(epochs.parse(d)) for d in (2451545.0, "2000-01-01T12:00:00")]
    [(2451545.0, 0.0), (2451545.0, 0.0)]
    """
    if is_time(value):
        return as_epoch(value, field)
    if isinstance(value, str):
        return from_text(value, field)
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        return from_pair(value, 0.0, field)
    raise EpochError(f"{field} must be an astropy.time.Time, a date as text or a Julian "
                     f"date (TDB), got {type(value).__name__}")


def describe(epoch):
    """One line for summaries: the calendar date and the Julian date, in TDB.

    Examples
    --------
    >>> from orbits import epochs
    >>> epochs.describe(epochs.from_pair(2451545.0, 0.0))
    '2000-01-01T12:00:00.000 TDB (JD 2451545.0)'
    """
    jd1, jd2 = to_pair(epoch)
    return f"{epoch.isot} TDB (JD {jd1 + jd2!r})"


def at_times(epoch, times):
    """The dates ``epoch + times`` (a Time array in TDB, two-part precision kept).

    Parameters
    ----------
    epoch : astropy.time.Time
        TDB, scalar.
    times : Quantity, shape (n,)
        Times since ``epoch``.

    Examples
    --------
    >>> from orbits import epochs
    >>> dates = epochs.at_times(epochs.from_pair(2451545.0, 0.0), [0, 1] * u.yr)
    >>> dates.jd.tolist(), dates.scale
    ([2451545.0, 2451910.25], 'tdb')
    """
    return epoch + times

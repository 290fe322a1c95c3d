"""Body sets in files: TOML for a person to write, CSV for a table.

``orbits run system.toml`` and :meth:`orbits.BodySet.read` read these files;
:func:`write` and :meth:`orbits.BodySet.write` write them.  Every value carries
its unit, so a file says what it means without a convention to remember.

TOML
----
One ``[[body]]`` table per body, in order; an optional ``[units]`` table; an
optional ``[run]`` table of defaults for ``orbits run``; an optional
``epoch``, before the tables::

    epoch = "2000-01-01T12:00:00 TDB"   # optional: the date of the states

    [units]                     # optional; as orbits.UnitSystem takes them
    length = "au"               # default au
    mass = "Msun"               # default Msun
    time = "day"                # default day
    # G = 2.95912208286e-4      # optional, in length^3 / (mass time^2), or
                                # a string with a unit; default: astropy's

    [[body]]
    name = "Sun"
    mass = "1 Msun"             # a string: a number and its unit
    radius = "1 Rsun"           # optional: the physical radius; default 0

    [[body]]                    # by orbital elements about a primary
    name = "Jupiter"
    mass = "9.547919e-4 Msun"
    primary = "Sun"             # default: the centre of mass of the bodies above
    a = "5.2026 au"
    e = 0.0484                  # a plain number: dimensionless
    inc = "1.30 deg"            # angles always with a unit (deg or rad)
    Omega = "100.5 deg"
    omega = "273.9 deg"
    M = "20 deg"                # or f = ..., the true anomaly; default f = 0

    [[body]]                    # by Cartesian state
    name = "probe"
    mass = 0
    position = ["1 au", "0 au", "0 au"]
    velocity = ["0 km/s", "30 km/s", "0 km/s"]

    [run]                       # optional: defaults for 'orbits run' (its
    integrator = "wh"           # options override them)
    dt = "50 day"
    until = "1000 yr"
    outputs = 500
    com = true                  # move to the centre-of-mass frame first
    # encounter_distance = "0.01 au", escape_distance = "1000 au"

    [run.options]               # the integrator's options
    corrector = 17

The ``epoch`` is the date the states hold at (:attr:`orbits.BodySet.epoch`):
text that :func:`orbits.epochs.from_text` reads, a date astropy reads
followed by its time scale (TDB when none is given: ``"2024-03-01 UTC"``,
``"2000-01-01T12:00:00 TDB"``) or a Julian date in one or two parts
(``"2451545.0 TDB"``, ``"2451545.0 + 0.25 TDB"``); :func:`write` writes the
two-part Julian date in TDB, which reads back bit for bit.

Body fields are those of :meth:`orbits.BodySet.add`: ``name``, ``mass``, an
optional ``radius``, and either ``position`` and ``velocity`` (three
components each) or ``a``, ``e``, ``inc``, ``Omega``, ``omega``, ``f`` or ``M``
with an optional ``primary``.
A value is a string with a unit (``"5.2 au"``, ``"30 km/s"``) or a plain
number.  A plain number is read in the ``[units]`` table's units; without a
``[units]`` table only dimensionless values (``e``) and zero take no unit.
Angles always need one.

CSV
---
A header row names the columns with their units in brackets; a row per body;
lines starting with ``#`` are comments, and a ``# units:`` comment before the
header gives the unit system (plain-number columns are then read in it), an
``# epoch:`` comment the date of the states (as the TOML ``epoch``)::

    # units: length = au; mass = Msun; time = day
    # epoch: 2451545.0 + 0.0 TDB
    name,mass [Msun],x [au],y [au],z [au],vx [km/s],vy [km/s],vz [km/s]
    Sun,1,0,0,0,0,0,0
    probe,0,1,0,0,0,30,0

The columns are ``name``, ``mass``, ``radius``, ``x``, ``y``, ``z``, ``vx``,
``vy``, ``vz``, ``primary``, ``a``, ``e``, ``inc``, ``Omega``, ``omega``, ``f``,
``M``; a row gives either the state or elements, and leaves the other cells
empty.  ``radius`` is optional (an empty cell or no column: 0).

A file saved by a spreadsheet reads as it is: a UTF-8 byte-order mark at its
start is skipped.  A name that a spreadsheet would take for a formula (one
beginning with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return) is
written with a single quote before it, as spreadsheets write such text, and a
name beginning with a quote gets one more; reading takes one such quote away
(``orbits._csvcells``).

Exactness
---------
:func:`write` writes the numbers the set holds, in its own units, with the
shortest text that reads back as the same float64 (Python's ``repr``), and
the unit system with its G.  Radii are written where any body has a non-zero
one.  A set written and read back is therefore the same bit for bit, and so
is any run of it.

Errors
------
Everything wrong in a file is a :class:`~orbits.errors.SystemFileError` whose
message starts with the file and the line, then names the body and the field:
``system.toml, line 12: body 'Jupiter', field 'inc': ...``.  That includes a
file that is not UTF-8 text, a whole number too large for a float or with
more digits than Python converts, and arrays nested too deeply to read.
"""

import os

from ..bodies import BodySet
from ..errors import SystemFileError
from . import _schema
from ._csv import _CsvReader
from ._reader import SystemFile
from ._schema import _format_of
from ._toml import _TomlReader
from ._writer import _dump_csv, _dump_toml

__all__ = ["SystemFile", "read", "write", "loads", "dumps", "BODY_FIELDS", "UNIT_FIELDS",
           "RUN_FIELDS", "CSV_COLUMNS"]

#: ``[[body]]`` keys and the physical kind each is read as
BODY_FIELDS = _schema.BODY_FIELDS

#: ``[units]`` keys (the arguments of :class:`~orbits.units.UnitSystem`)
UNIT_FIELDS = _schema.UNIT_FIELDS

#: ``[run]`` keys and what each holds
RUN_FIELDS = _schema.RUN_FIELDS

#: CSV columns: the body fields, with the vectors as one column per component
CSV_COLUMNS = _schema.CSV_COLUMNS

_BOM = "\ufeff"


def read(path):
    """Read a body set from a TOML or CSV file.

    Parameters
    ----------
    path : str or os.PathLike
        A file ending in ``.toml`` or ``.csv`` (the format is the module
        docstring's).

    Returns
    -------
    SystemFile
        ``bodies`` (a :class:`~orbits.BodySet` in the file's unit system),
        ``run`` (the ``[run]`` table's defaults) and ``path``.

    Raises
    ------
    SystemFileError
        The file is malformed; the message gives the file, the line, the body
        and the field.
    FileNotFoundError
        There is no such file.

    Examples
    --------
    >>> import os, tempfile
    >>> from orbits import systemfile
    >>> path = os.path.join(tempfile.mkdtemp(), "kepler.toml")
    >>> systemfile.write(orbits.scenes.kepler(), path)
    >>> systemfile.read(path).bodies.names
    ['Star', 'Planet']
    """
    path = os.fspath(path)
    kind = _format_of(path)
    with open(path, "rb") as fh:
        data = fh.read()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        start = data.rfind(b"\n", 0, exc.start) + 1
        raise SystemFileError(f"not UTF-8 text: the byte {data[exc.start]:#04x} at column "
                              f"{exc.start - start + 1} is not UTF-8; save the file as "
                              f"UTF-8", path=path, line=data.count(b"\n", 0, exc.start) + 1) \
            from None
    return loads(text, kind, source=path)


def loads(text, kind="toml", source="<string>"):
    """Read a body set from text.

    Parameters
    ----------
    text : str
        The file's contents.
    kind : {"toml", "csv"}
    source : str
        The name used in error messages.

    Returns
    -------
    SystemFile

    Examples
    --------
    >>> from orbits import systemfile
    >>> text = "name,mass [Msun],primary,a [au],e\\nSun,1,,,\\nEarth,3e-6,Sun,1,0.0167\\n"
    >>> bodies = systemfile.loads(text, "csv").bodies
    >>> round(float(bodies.elements("Earth", primary="Sun")["a"].to_value("au")), 12)
    1.0
    """
    if text.startswith(_BOM):   # a spreadsheet's UTF-8 mark
        text = text[len(_BOM):]
    if kind == "toml":
        return _TomlReader(text, source).read()
    if kind == "csv":
        return _CsvReader(text, source).read()
    raise ValueError(f"unknown body-set file format {kind!r}; expected 'toml' or 'csv'")


def write(bodies, path, run=None):
    """Write a body set to a TOML or CSV file, exactly.

    Parameters
    ----------
    bodies : BodySet
    path : str or os.PathLike
        Ending in ``.toml`` or ``.csv``; an existing file is replaced.
    run : dict, optional
        TOML only: a ``[run]`` table of defaults for ``orbits run`` (keys as in
        :data:`RUN_FIELDS`; times and lengths as Quantities).

    Notes
    -----
    States are written in the set's own units as the shortest decimal text that
    reads back as the same float64, with the unit system and its G, so
    :func:`read` gives the set back bit for bit.

    Examples
    --------
    >>> import os, tempfile
    >>> from orbits import systemfile
    >>> bodies = orbits.scenes.outer_solar_system()
    >>> path = os.path.join(tempfile.mkdtemp(), "outer.csv")
    >>> systemfile.write(bodies, path)
    >>> back = orbits.BodySet.read(path)
    >>> bool(np.array_equal(back.positions, bodies.positions))
    True
    """
    path = os.fspath(path)
    kind = _format_of(path)
    text = dumps(bodies, kind, run=run)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(text)


def dumps(bodies, kind="toml", run=None):
    """The text :func:`write` writes.

    Parameters
    ----------
    bodies : BodySet
    kind : {"toml", "csv"}
    run : dict, optional
        TOML only; see :func:`write`.

    Returns
    -------
    str

    Examples
    --------
    >>> from orbits import systemfile
    >>> print(systemfile.dumps(orbits.scenes.kepler()))  # doctest: +ELLIPSIS
    # A body set for orbits...
    [[body]]
    name = "Star"
    mass = 1.0
    ...
    """
    if not isinstance(bodies, BodySet):
        raise TypeError(f"bodies must be a BodySet, got {type(bodies).__name__}")
    if kind == "toml":
        return _dump_toml(bodies, run)
    if kind == "csv":
        if run:
            raise ValueError("a CSV file holds no [run] table; write TOML for run defaults")
        return _dump_csv(bodies)
    raise ValueError(f"unknown body-set file format {kind!r}; expected 'toml' or 'csv'")

"""The declaration of each monitor: one :class:`MonitorSpec` a series, from
which every table that lists monitors is made.

A spec says what a monitor is everywhere it appears: its name (what
``Simulation(monitors=...)`` takes, the output file's ``observables/<name>``
series and the :class:`~orbits.Result` attribute), its columns in a monitor
row (the compiled kernels' layout,
:data:`orbits._kernels.invariants.MONITOR_COLUMNS`), the bit of the kernels'
mask that turns it on, its unit, the relative error kept beside it, and what
it puts in an ensemble's table.  :mod:`orbits.monitors`, the file layout
(:mod:`orbits.io.h5md.layout`), the result's exports and the ensemble's
table read these specs; none of them names a monitor.

A new monitor is a column (and a bit) of the kernels' monitor row, one spec
here, and a test; the specs are checked against the kernels' layout when
this module is imported.
"""

import dataclasses
import functools

from ._kernels import invariants as _inv

__all__ = ["MonitorSpec", "MONITOR_SPECS"]


@dataclasses.dataclass(frozen=True)
class MonitorSpec:
    """What one monitor's series is, in the kernels, the files, results and ensembles.

    Parameters
    ----------
    name : str
        The monitor's name: what ``Simulation(monitors=...)`` takes, the output
        file's series ``observables/<name>`` (and ``observables/in_loop/<name>``)
        and the :class:`~orbits.Result` attribute that holds the series.
    columns : tuple of str
        Its columns in a monitor row, in order (names of
        :data:`orbits._kernels.invariants.MONITOR_COLUMNS`): one for a scalar
        series, three for a vector.
    kind : str
        Its unit: a kind of :class:`~orbits.UnitSystem` (``"energy"``,
        ``"length"``, ...), ``"dimensionless"`` (a plain array in a result,
        unit ``"1"`` in a file) or ``"1 / time"``.
    bit : int
        The bit of the kernels' monitor mask that records it; 0 for a series
        that is not chosen but kept with the monitor it ``adds_to``.
    adds_to : str or None
        The monitor whose conserved quantity this series is added to (the
        work ``W`` of non-conservative forces: ``E + W`` is conserved).  Rows
        written before the series was kept count it as 0.
    error : str or None
        The relative error kept beside the series, as
        :func:`orbits.monitors.error_series` computes it: ``"scalar"``
        (:func:`~orbits.monitors.relative_error` of the series plus those
        added to it) or ``"vector"``
        (:func:`~orbits.monitors.vector_relative_error`); the result's
        attribute ``<name>_error``.
    scale : int or None
        With ``error``: the index in the simulation's error scales (the file's
        ``parameters/scales``) of the denominator used where the reference is 0.
    chaos : bool
        A chaos indicator: it needs a tangent vector.
    default : bool
        Among the monitors a simulation records unless told otherwise.
    ensemble : str or None
        Its column in an ensemble's table: the largest relative error over the
        run (``"<name>_error_max"``, with ``error``), or the last value, with
        ``_<unit>`` appended for a series with a unit (``"lyapunov_per"``
        becomes ``"lyapunov_per_day"``).  None: not in the table.
    derived : tuple of str
        Result attributes computed from the outputs when this monitor is on
        (``test_particle_energy_error``), exported after its own series.
    """

    name: str
    columns: tuple
    kind: str
    bit: int = 0
    adds_to: str = None
    error: str = None
    scale: int = None
    chaos: bool = False
    default: bool = False
    ensemble: str = None
    derived: tuple = ()

    @property
    def chosen(self):
        """Whether it is a monitor one chooses (``monitors=``), not kept with another."""
        return self.bit != 0

    @property
    def scalar(self):
        """Whether the series holds one value a row (else a vector of its columns)."""
        return len(self.columns) == 1

    @property
    def shape(self):
        """The shape of one row of the series: ``()`` or ``(3,)``."""
        return () if self.scalar else (len(self.columns),)

    @property
    def error_field(self):
        """The result's attribute of its relative error, or None."""
        return None if self.error is None else f"{self.name}_error"

    @functools.cached_property
    def row_slice(self):
        """Its columns in a monitor row, as a slice."""
        start = _inv.MONITOR_COLUMNS.index(self.columns[0])
        return slice(start, start + len(self.columns))

    def unit(self, units):
        """Its unit in the unit system ``units`` (an astropy unit)."""
        if self.kind == "1 / time":
            return units.unit("time") ** -1
        return units.unit(self.kind)

    def file_unit(self, units):
        """Its unit in a file of the unit system ``units``, as the ``unit``
        attribute writes it (``"1"`` for dimensionless)."""
        return "1" if self.kind == "dimensionless" else self.unit(units).to_string()


#: Every monitor series, in the order results and files list them.
MONITOR_SPECS = (
    MonitorSpec("energy", ("energy",), "energy", bit=_inv.ENERGY, error="scalar", scale=0,
                default=True, ensemble="energy_error_max",
                derived=("test_particle_energy_error",)),
    MonitorSpec("work", ("work",), "energy", adds_to="energy"),
    MonitorSpec("angular_momentum", ("Lx", "Ly", "Lz"), "angular_momentum",
                bit=_inv.ANGULAR_MOMENTUM, error="vector", scale=1, default=True,
                ensemble="angular_momentum_error_max"),
    MonitorSpec("momentum", ("px", "py", "pz"), "momentum", bit=_inv.MOMENTUM),
    MonitorSpec("center_of_mass", ("comx", "comy", "comz"), "length",
                bit=_inv.CENTER_OF_MASS),
    MonitorSpec("megno", ("megno",), "dimensionless", bit=_inv.MEGNO, chaos=True,
                ensemble="megno"),
    MonitorSpec("lyapunov", ("lyapunov",), "1 / time", bit=_inv.LYAPUNOV, chaos=True,
                ensemble="lyapunov_per"),
    MonitorSpec("fli", ("fli",), "dimensionless", bit=_inv.FLI, chaos=True, ensemble="fli"),
)


def _check(specs, columns):
    """Raise ImportError unless ``specs`` cover the monitor row ``columns``
    (the kernels' layout) once each, every spec's columns side by side, with
    distinct names and mask bits and ``adds_to`` naming a chosen monitor."""
    problems = []
    names = [s.name for s in specs]
    if len(set(names)) != len(names):
        problems.append(f"a name is declared twice: {names}")
    bits = [s.bit for s in specs if s.chosen]
    if len(set(bits)) != len(bits) or any(b & (b - 1) for b in bits):
        problems.append(f"the mask bits are not distinct powers of two: {bits}")
    declared = [c for s in specs for c in s.columns]
    if sorted(declared) != sorted(columns):
        problems.append(f"the specs' columns {declared} are not the kernels' "
                        f"monitor row {list(columns)}")
    for s in specs:
        at = [columns.index(c) if c in columns else -1 for c in s.columns]
        if -1 not in at and at != list(range(at[0], at[0] + len(at))):
            problems.append(f"{s.name}: its columns {s.columns} are not side by side "
                            f"in the monitor row")
        if s.adds_to is not None and s.adds_to not in [t.name for t in specs if t.chosen]:
            problems.append(f"{s.name}: adds to {s.adds_to!r}, which is not a monitor")
        if (s.error is None) != (s.scale is None):
            problems.append(f"{s.name}: an error needs a scale, and a scale an error")
    if problems:
        raise ImportError("the monitor specs (orbits._monitor_specs) do not match the "
                          "kernels' monitor row (orbits._kernels.invariants): "
                          + "; ".join(problems))


_check(MONITOR_SPECS, _inv.MONITOR_COLUMNS)

#: name -> spec
BY_NAME = {s.name: s for s in MONITOR_SPECS}
#: the monitors one chooses (``Simulation(monitors=...)``), in order
CHOSEN = tuple(s for s in MONITOR_SPECS if s.chosen)
#: the chosen monitors with a relative error, in order
WITH_ERROR = tuple(s for s in CHOSEN if s.error is not None)


def added_to(name):
    """The specs of the series added to monitor ``name``'s (the work, to the energy)."""
    return tuple(s for s in MONITOR_SPECS if s.adds_to == name)


def result_fields(spec):
    """The result's attributes that monitor ``spec`` fills, in export order: its
    series, the series added to it, its error, and what is derived from it."""
    names = [spec.name] + [s.name for s in added_to(spec.name)]
    if spec.error is not None:
        names.append(spec.error_field)
    return tuple(names) + spec.derived


#: every monitor attribute of a result, in the order tables export them
RESULT_FIELDS = tuple(name for s in CHOSEN for name in result_fields(s))
#: the attributes of :data:`RESULT_FIELDS` that hold a recorded series or its
#: error (those derived from the outputs left out)
RECORDED_FIELDS = tuple(name for name in RESULT_FIELDS
                        if not any(name in s.derived for s in CHOSEN))

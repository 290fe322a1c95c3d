"""The stress suite's sweeps: their columns (:data:`SWEEPS`), one run a cell,
a map's row of cells for an integrator (:func:`measure`), the REBOUND
reference runs of the sweeps without an analytic oracle (:func:`reference`),
and the tasks that run them all (:func:`tasks`).
"""

import math
from typing import Callable, NamedTuple

import astropy.units as u
import numpy as np

from ... import scenes as _scenes
from ...errors import WallTimeExceeded
from .. import _measure, cases
from .._runner import Task
from .problems import (ENCOUNTER_DT, ENCOUNTER_TIME, adaptive, encounter_bodies, kepler_error,
                       pass_distance, spring)

__all__ = ["Sweep", "SWEEPS", "VARIANTS", "measure", "reference", "tasks", "map_rows", "sci",
           "wall_limit", "WALL_LIMIT_QUICK", "WALL_LIMIT_FULL", "KEPLER_STEPS_PER_ORBIT",
           "KEPLER_ORBITS", "MASS_RATIO_STEPS_PER_ORBIT", "MASS_RATIO_ECCENTRICITY",
           "STEP_ORBITS", "P_JUPITER", "PYTHAGOREAN_UNTIL", "PYTHAGOREAN_OUTPUTS",
           "SLOW_IN_QUICK", "SLOW_QUICK_SWEEPS"]

#: Seconds a cell may run (quick, full) before it is stopped as
#: WallTimeExceeded.  The quick limit keeps a crawling cell from holding up
#: the five-minute quick report (its cells take 0.01-1 s); the full one is half of
#: :data:`_measure.WALL_LIMIT`, enough for scipy's Radau on the k = 1e5 spring
#: (about 25 s); a cell whose step collapses without underflowing stops there.
WALL_LIMIT_QUICK = 3.0
WALL_LIMIT_FULL = 0.5 * _measure.WALL_LIMIT


def wall_limit(quick):
    """Seconds a cell may run: :data:`WALL_LIMIT_QUICK` or :data:`WALL_LIMIT_FULL`."""
    return WALL_LIMIT_QUICK if quick else WALL_LIMIT_FULL


class Sweep(NamedTuple):
    """One sweep: its columns in quick and full mode (``quick``, ``full``;
    ``*_adaptive`` where adaptive methods sweep their tolerance instead), the
    error measure and how a column is written."""

    key: str
    title: str
    quick: tuple
    full: tuple
    metric: str
    label: Callable
    quick_adaptive: tuple = ()
    full_adaptive: tuple = ()
    adaptive_label: Callable = None

    @property
    def split(self):
        """True if adaptive methods sweep their tolerance (a second panel)."""
        return bool(self.quick_adaptive)

    def values(self, quick, adaptive=False):
        if adaptive and self.split:
            return self.quick_adaptive if quick else self.full_adaptive
        return self.quick if quick else self.full


def sci(v):
    """``v`` as a column label writes it (``1e-8``, ``3e-3``, ``1``)."""
    if v == 0:
        return "0"
    if v == 1:
        return "1"
    exp = math.floor(math.log10(abs(v)) + 1e-9)
    mant = v / 10 ** exp
    return f"1e{exp}" if abs(mant - 1) < 1e-9 else f"{mant:g}e{exp}"


def _tol(v):
    return f"tol {sci(v)}"


SWEEPS = {s.key: s for s in (
    Sweep("eccentricity", "Eccentricity (Kepler orbit)",
          (0.0, 0.5, 0.9, 0.99, 0.999, 0.9999),
          (0.0, 0.3, 0.5, 0.7, 0.9, 0.95, 0.99, 0.995, 0.999, 0.9995, 0.9999),
          "position", lambda v: f"e = {v:g}"),
    Sweep("step", "Step size and tolerance (outer solar system)",
          (10, 30, 100, 300, 1000), (10, 20, 50, 100, 200, 500, 1000, 3000),
          "position", lambda v: f"P_J/{v:g}",
          (1e-3, 1e-6, 1e-9, 1e-12), (1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13), _tol),
    Sweep("mass-ratio", "Mass ratio (two-body orbit, e = 0.5)",
          (1e-12, 1e-9, 1e-6, 1e-3, 1.0),
          (1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 1.0),
          "position", lambda v: f"q = {sci(v)}"),
    Sweep("encounter", "Close encounters (two Earth-mass planets about a star)",
          (1e-3, 1e-5, 1e-8), (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8),
          "position", lambda v: f"{sci(v)} au"),
    Sweep("pythagorean", "Pythagorean three-body problem",
          (1e-2, 1e-3, 1e-4), (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5),
          "energy", lambda v: f"dt {sci(v)}",
          (1e-6, 1e-9, 1e-12), (1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14), _tol),
    Sweep("spring", "Stiff spring (k = 1 to 1e6, dt = 0.01)",
          (1.0, 1e2, 1e4, 1e6), (1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6),
          "position", lambda v: f"k = {sci(v)}"),
)}

# Kepler runs: fixed step P/1000, the finest of the report's Kepler problems
# (cases: e = 0.9); whole orbits plus a half, so that the run ends far from
# the pericentre of the eccentric orbits, where a position error measures the
# orbit and not the sensitivity of a fast pass.
KEPLER_STEPS_PER_ORBIT = 1000
MASS_RATIO_STEPS_PER_ORBIT = 200     # cases' e = 0.5 step
MASS_RATIO_ECCENTRICITY = 0.5
KEPLER_ORBITS = {True: 2.5, False: 10.5}

# outer solar system: run length in Jupiter periods (quick, full: about 95
# and 950 years), a whole number so that every step P_J/N of the sweep ends
# the run exactly on the reference's end time
STEP_ORBITS = {True: 8, False: 80}
P_JUPITER = 4332.59                  # days

PYTHAGOREAN_UNTIL = {True: 20.0, False: 70.0}
PYTHAGOREAN_OUTPUTS = 201


# -- one row of a map ----------------------------------------------------------------

def _from_row(row, error=None, keep_x=False):
    cell = {"outcome": row["outcome"], "message": row["message"][:300],
            "warning": row["warning"][:300], "steps": int(row["steps"]),
            "wall_time": float(row["wall_time"]),
            "energy_error": float(row["energy_error_max"]),
            "error": None if error is None else float(error)}
    if keep_x:
        cell["x"] = None if row["x"] is None else np.asarray(row["x"], dtype=float).tolist()
    return cell


def _kepler_cell(bodies, name, options, steps_per_orbit, quick):
    """A two-body run of ``KEPLER_ORBITS`` orbits (a = 1 au) against the
    analytic orbit."""
    mu = bodies.units.G * float(bodies._m.sum())
    period = 2 * math.pi / math.sqrt(mu)                       # a = 1 au
    dt = None if adaptive(name) else period / steps_per_orbit
    row = _measure.run_orbits(bodies, name, options, dt=dt,
                              until=KEPLER_ORBITS[quick] * period, outputs=2,
                              wall_limit=wall_limit(quick))
    err = kepler_error(bodies, row, 1.0) if row["outcome"] == "completed" else None
    return _from_row(row, err)


def _eccentricity_cell(name, options, e, quick):
    return _kepler_cell(_scenes.kepler(e=e), name, options, KEPLER_STEPS_PER_ORBIT, quick)


def _mass_ratio_cell(name, options, q, quick):
    bodies = _scenes.kepler(e=MASS_RATIO_ECCENTRICITY, m_orbiter=q * u.Msun)
    return _kepler_cell(bodies, name, options, MASS_RATIO_STEPS_PER_ORBIT, quick)


def _swept_run(bodies, name, options, value, dt, until, outputs, quick):
    """A run at a column of a sweep that sets the step of fixed-step methods
    (``dt``) and the tolerance of adaptive ones (``value``)."""
    if adaptive(name):
        options, dt = {**options, **cases.tolerance_options(name, value)}, None
    return _measure.run_orbits(bodies, name, options, dt=dt, until=until, outputs=outputs,
                               wall_limit=wall_limit(quick))


def _step_cell(name, options, value, quick):
    row = _swept_run(_scenes.outer_solar_system(com=True), name, options, value,
                     P_JUPITER / value, STEP_ORBITS[quick] * P_JUPITER, 2, quick)
    return _from_row(row, keep_x=True)


def _encounter_cell(name, options, d, quick):
    bodies = encounter_bodies(d)
    dt = None if adaptive(name) else ENCOUNTER_DT
    row = _measure.run_orbits(bodies, name, options, dt=dt, until=2 * ENCOUNTER_TIME, outputs=2,
                              wall_limit=wall_limit(quick))
    return _from_row(row, keep_x=True)


def _pythagorean_cell(name, options, value, quick):
    row = _swept_run(_scenes.pythagorean(), name, options, value, value,
                     PYTHAGOREAN_UNTIL[quick], PYTHAGOREAN_OUTPUTS, quick)
    return _from_row(row, row["energy_error_max"])


def _spring_cell(name, options, k, quick):
    return spring(name, k, wall_limit(quick))      # default options: no variant here


_CELLS = {"eccentricity": _eccentricity_cell, "step": _step_cell,
          "mass-ratio": _mass_ratio_cell, "encounter": _encounter_cell,
          "pythagorean": _pythagorean_cell, "spring": _spring_cell}


#: Extra rows: an integrator with other options where a sweep tells something
#: about them (label, registry name, options).  Democratic heliocentric
#: coordinates treat the star's reflex motion as a separate term, whose
#: error grows with the planet's mass: the mass-ratio sweep shows how.
VARIANTS = {"mass-ratio": (("wh (democratic-heliocentric)", "wh",
                            {"coordinates": "democratic-heliocentric"}),)}

#: Integrators left out of the quick report's long sweeps: scipy's Radau
#: calls the force and takes each step from Python (about 0.5 ms a step,
#: seconds a cell); it runs in the quick sweeps of :data:`SLOW_QUICK_SWEEPS`
#: and everywhere in the full report.
SLOW_IN_QUICK = ("radau",)
SLOW_QUICK_SWEEPS = ("encounter", "spring")


def map_rows(sweep):
    """(label, registry name, options) of every row of a sweep's map."""
    return [(n, n, {}) for n in cases.integrator_names()] + list(VARIANTS.get(sweep, ()))


def _left_out(sweep, name, quick):
    """Why integrator ``name`` is left out of ``sweep`` (None if it runs)."""
    if sweep == "pythagorean":
        reason = cases.applies(cases.problem("pythagorean"), name, quick)
        if reason is not None:
            return reason
    if quick and name in SLOW_IN_QUICK and sweep not in SLOW_QUICK_SWEEPS:
        return ("quick mode: scipy's Radau calls the force and takes each step from Python "
                "(about 0.5 ms a step, seconds a cell here); the full report runs it")
    return None


def measure(sweep, integrator, quick, options=None, label=None):
    """One row of a map: integrator ``integrator`` at every column of ``sweep``.

    Columns run in order of difficulty; after a cell passes the wall-time
    limit, the harder ones are not run (outcome ``"Skipped"``, drawn grey).

    Returns a small dict (``kind="row"``, ``sweep``, ``integrator``,
    ``label``, ``left_out``, ``cells``: one dict per column with
    ``outcome``, ``message``, ``error``, ``energy_error``, ``steps``,
    ``wall_time`` and, where a reference run decides the error, the final
    positions ``x``).
    """
    spec = SWEEPS[sweep]
    options = dict(options or {})
    values = spec.values(quick, adaptive(integrator))
    row = {"kind": "row", "sweep": sweep, "integrator": integrator,
           "label": label or integrator, "left_out": _left_out(sweep, integrator, quick),
           "cells": []}
    if row["left_out"] is not None:
        return row
    stopped = False
    for value in values:
        if stopped:
            cell = {"outcome": "Skipped", "message": "not run: an easier column passed "
                    "the wall-time limit", "warning": "", "steps": 0, "wall_time": 0.0,
                    "error": None, "energy_error": math.nan}
        else:
            cell = _CELLS[sweep](integrator, options, value, quick)
            stopped = cell["outcome"] == WallTimeExceeded.__name__
        cell["value"] = value
        row["cells"].append(cell)
    return row


def reference(sweep, quick):
    """The reference runs of a sweep that has no analytic oracle (REBOUND IAS15)."""
    spec = SWEEPS[sweep]
    if sweep == "step":
        bodies = _scenes.outer_solar_system(com=True)
        row = _measure.run_rebound(bodies, "ias15", until=STEP_ORBITS[quick] * P_JUPITER,
                                   outputs=2, wall_limit=_measure.WALL_LIMIT)
        return {"kind": "reference", "sweep": sweep, "outcome": row["outcome"],
                "x": np.asarray(row["x"]).tolist()}
    if sweep == "encounter":
        cols = []
        for d in spec.values(quick):
            s, q, x = pass_distance(encounter_bodies(d))
            cols.append({"value": d, "separation": s, "pericentre": q, "x": x.tolist()})
        return {"kind": "reference", "sweep": sweep, "outcome": "completed",
                "columns": cols}
    raise ValueError(f"sweep {sweep!r} has an analytic reference")


# -- tasks ---------------------------------------------------------------------------

# rough seconds of one row (quick mode) by sweep, and factors by integrator,
# from a serial run on this machine: they only order the tasks
_SWEEP_COST = {"eccentricity": 0.5, "step": 1.0, "mass-ratio": 0.5, "encounter": 1.0,
               "pythagorean": 2.0, "spring": 1.5}
_INTEGRATOR_COST = {"radau": 8.0, "lsoda": 2.0, "ias15": 3.0, "implicit-euler": 2.0,
                    "implicit-midpoint": 2.0, "yoshida8": 1.5, "rk4-doubling": 1.5}


def tasks(quick):
    """Every measurement of the stress suite: one task per (sweep, row) and the
    REBOUND reference runs."""
    out = []
    scale = 1.0 if quick else 6.0
    for sweep in SWEEPS:
        for label, name, options in map_rows(sweep):
            cost = _SWEEP_COST[sweep] * _INTEGRATOR_COST.get(name, 1.0) * scale
            out.append(Task(f"{__name__}:measure",
                            {"sweep": sweep, "integrator": name, "quick": quick,
                             "options": options, "label": label}, cost))
        if sweep in ("step", "encounter"):
            out.append(Task(f"{__name__}:reference", {"sweep": sweep, "quick": quick},
                            0.5 * scale))
    return out

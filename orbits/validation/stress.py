"""The stress suite: where each integrator is accurate, where it degrades, where it fails.

Six sweeps push every integrator of the registry towards the edge of what it
can do, one parameter at a time:

* **eccentricity** of a Kepler orbit, 0 to 0.9999, against the analytic orbit
  (Kepler's equation, :mod:`orbits._kernels.anomalies`: an oracle that shares no
  code with any integrator);
* **step size** on the outer solar system, against REBOUND's IAS15: the step
  for fixed-step methods, the tolerance for adaptive ones (they have no step
  to set);
* **mass ratio** of a two-body orbit, 1e-12 to 1, against the analytic orbit;
* **close encounters** of two Earth-mass planets about a star, passing at
  1e-3 to 1e-8 au, against REBOUND's IAS15.  The initial state is made by
  integrating the moment of closest approach backwards (REBOUND IAS15), so
  the pass distance is what the column says; the reference run measures it
  again;
* the **Pythagorean problem**: step and tolerance against the largest energy
  error (the motion is chaotic, so final positions would measure the
  reference as much as the method);
* the **stiff spring** ``x'' = -k x`` (m = 1, x0 = 1, v0 = 0) for k = 1 to 1e6
  at a fixed step dt = 0.01 (the integrator-choice guide's step), through
  :func:`orbits.integrate`, against ``cos(sqrt(k) t)``.

Each cell of a map is one run, classified by the thresholds below as
accurate, degraded or failed; a run that raised one of the named run errors
(``NonFiniteState``, ``StepSizeUnderflow``, ``ConvergenceFailure``,
``WallTimeExceeded``) is failed and shows the error's abbreviation.  Nothing
is left to hang: every run has a wall-time limit.  An integrator that does
not apply to a sweep is drawn grey and listed with the reason.

This module follows the report's part protocol: :data:`TITLE`,
:func:`tasks` (the measurements, run in parallel by
:func:`orbits.validation._runner.run_tasks`) and :func:`section` (maps and
Markdown from their rows).
"""

import functools
import math
import time
from typing import Callable, NamedTuple

import numba
import numpy as np

from .. import integrators as _integrators
from .. import scenes as _scenes
from ..bodies import BodySet
from ..custom import integrate
from ..errors import IntegratorOptionError, RunError, WallTimeExceeded
from ..units import UnitSystem
from .._kernels import anomalies as _anomalies
from .._kernels import elements as _elements
from .._kernels.status import Status, describe_status
from . import _measure, cases
from ._runner import Task

__all__ = ["TITLE", "tasks", "section", "classify", "abbreviation", "encounter_bodies",
           "pass_distance", "kepler_reference", "measure", "reference", "Sweep", "SWEEPS",
           "VARIANTS", "ACCURATE", "DEGRADED", "FAILED", "LEFT_OUT", "ACCURATE_POSITION",
           "FAILED_POSITION", "ACCURATE_ENERGY", "FAILED_ENERGY", "WALL_LIMIT_QUICK",
           "WALL_LIMIT_FULL"]

TITLE = "Stress suite"

# -- classification -----------------------------------------------------------------

ACCURATE, DEGRADED, FAILED, LEFT_OUT = "accurate", "degraded", "failed", "left out"
_CLASSES = (ACCURATE, DEGRADED, FAILED, LEFT_OUT)

#: Relative position error below which a run is accurate: six digits of the
#: orbit, what an ephemeris comparison or a figure at any zoom would need.
ACCURATE_POSITION = 1e-6
#: Relative position error from which a run has failed: a tenth of the orbit
#: (or of the separation, or of the amplitude) off is a different trajectory,
#: no longer a less precise one.
FAILED_POSITION = 1e-1
#: Relative energy error below which a run is accurate (the same six digits).
ACCURATE_ENERGY = 1e-6
#: Relative energy error from which a run has failed: one per cent of the
#: energy changes which pair of the Pythagorean problem ends as the binary,
#: and a position error grows about 2 pi (3/2) dE/E per orbit, so 1e-2 in
#: energy is already a tenth of an orbit in phase within one orbit.
FAILED_ENERGY = 1e-2

_THRESHOLDS = {"position": (ACCURATE_POSITION, FAILED_POSITION),
               "energy": (ACCURATE_ENERGY, FAILED_ENERGY)}

#: Seconds a cell may run (quick, full) before it is stopped as
#: WallTimeExceeded.  The quick limit keeps a crawling cell from holding up
#: the five-minute quick report (its cells take 0.01-1 s); the full one is half of
#: :data:`_measure.WALL_LIMIT`, enough for scipy's Radau on the k = 1e5 spring
#: (about 25 s); a cell whose step collapses without underflowing stops there.
WALL_LIMIT_QUICK = 3.0
WALL_LIMIT_FULL = 0.5 * _measure.WALL_LIMIT

_ABBREVIATIONS = {"NonFiniteState": "NFS", "StepSizeUnderflow": "SSU",
                  "ConvergenceFailure": "CF", "WallTimeExceeded": "WTE",
                  "IntegratorOptionError": "IOE"}


def abbreviation(outcome):
    """The short name of a run error for a map cell (``"NonFiniteState"`` -> ``"NFS"``)."""
    return _ABBREVIATIONS.get(outcome) or "".join(c for c in outcome if c.isupper()) or outcome


def classify(error, outcome="completed", metric="position"):
    """The class of one cell.

    Parameters
    ----------
    error : float
        The sweep's error measure (relative position or energy error).
    outcome : str
        ``"completed"``, or the class name of the run error.
    metric : {"position", "energy"}
        Which pair of thresholds applies.

    Returns
    -------
    str
        :data:`ACCURATE`, :data:`DEGRADED`, :data:`FAILED`, or :data:`LEFT_OUT`
        for an integrator that refused the problem (``IntegratorOptionError``)
        and for a cell not run (``"Skipped"``).
    """
    if outcome in ("IntegratorOptionError", "Skipped"):
        return LEFT_OUT
    if outcome != "completed":
        return FAILED
    good, bad = _THRESHOLDS[metric]
    if error is None or not math.isfinite(error) or error >= bad:
        return FAILED
    return ACCURATE if error < good else DEGRADED


def _cell_text(cls, outcome, error):
    if cls == LEFT_OUT:
        return "skip" if outcome == "Skipped" else "n/a"
    if outcome != "completed":
        return abbreviation(outcome)
    if error is None or not math.isfinite(error):
        return "inf"
    if error <= 0:
        return "0"
    text = f"{math.log10(error):.1f}"
    return "0.0" if text == "-0.0" else text


# -- the sweeps ---------------------------------------------------------------------

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


def _sci(v):
    if v == 0:
        return "0"
    if v == 1:
        return "1"
    exp = math.floor(math.log10(abs(v)) + 1e-9)
    mant = v / 10 ** exp
    return f"1e{exp}" if abs(mant - 1) < 1e-9 else f"{mant:g}e{exp}"


def _tol(v):
    return f"tol {_sci(v)}"


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
          "position", lambda v: f"q = {_sci(v)}"),
    Sweep("encounter", "Close encounters (two Earth-mass planets about a star)",
          (1e-3, 1e-5, 1e-8), (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8),
          "position", lambda v: f"{_sci(v)} au"),
    Sweep("pythagorean", "Pythagorean three-body problem",
          (1e-2, 1e-3, 1e-4), (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5),
          "energy", lambda v: f"dt {_sci(v)}",
          (1e-6, 1e-9, 1e-12), (1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14), _tol),
    Sweep("spring", "Stiff spring (k = 1 to 1e6, dt = 0.01)",
          (1.0, 1e2, 1e4, 1e6), (1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6),
          "position", lambda v: f"k = {_sci(v)}"),
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
_P_JUPITER = 4332.59                  # days

# close encounters: planets of an Earth mass each on a 1 au orbit, meeting at
# 5 km/s relative speed (faster than the mutual escape speed at the Hill
# radius, so the pass is a clean hyperbola); the pass is at ENCOUNTER_TIME,
# the run ends at twice that; the fixed step of 1e-3 day puts about 300 steps
# into the 1e-3 au pass (d / v_p = 0.3 day) and less than one into the
# 1e-5 au pass (5e-4 day).
ENCOUNTER_MASS = 3.0e-6               # Msun
ENCOUNTER_SPEED = 2.9e-3              # au/day at infinity, relative
ENCOUNTER_TIME = 5.0                  # days
ENCOUNTER_DT = 1e-3                   # days

PYTHAGOREAN_UNTIL = {True: 20.0, False: 70.0}
PYTHAGOREAN_OUTPUTS = 201

SPRING_DT = 0.01
SPRING_STEPS = 1000
SPRING_SEGMENTS = 10                  # wall-time checks per run
SPRING_OUTPUTS = 100                  # adaptive samples over the run

def _adaptive(name):
    return _integrators.get(name).adaptive


def _wall(quick):
    return WALL_LIMIT_QUICK if quick else WALL_LIMIT_FULL


# -- references ---------------------------------------------------------------------

def kepler_reference(mu, r0, v0, t):
    """The relative position of a two-body orbit at time ``t``, from Kepler's equation.

    ``r0, v0``: relative position and velocity at t = 0 (shape (3,)), ``mu =
    G (m1 + m2)``.  The mean anomaly advances by ``n t`` and Kepler's equation
    gives the true anomaly; no integrator is involved.
    """
    el = np.zeros(7)
    status = _elements.state_to_elements(mu, np.ascontiguousarray(r0, dtype=float),
                                       np.ascontiguousarray(v0, dtype=float), el)
    if status not in (Status.OK, Status.PARABOLIC_ORBIT):
        raise ValueError(describe_status(status))
    a, e, inc, node, peri, _, mean0 = el
    n = math.sqrt(mu / abs(a) ** 3)
    f = _anomalies.true_from_mean(mean0 + n * t, e)
    pos, vel = np.zeros(3), np.zeros(3)
    _elements.elements_to_state(mu, a, e, inc, node, peri, f, pos, vel)
    return pos


def _kepler_error(bodies, row, scale):
    """Final error of the relative position (body 1 - body 0), over ``scale``."""
    m = bodies._m
    mu = bodies.units.G * float(m[0] + m[1])
    r0 = bodies._x[1] - bodies._x[0]
    v0 = bodies._v[1] - bodies._v[0]
    ref = kepler_reference(mu, r0, v0, row["t_end"])
    return float(np.linalg.norm((row["x"][1] - row["x"][0]) - ref) / scale)


def _pair_state(distance):
    """Star and two planets at the moment the planets pass at ``distance``:
    the pair's centre of mass on a circular 1 au orbit, their separation
    radial, their relative velocity perpendicular to it (so the separation is
    at a minimum) and inclined to the orbital plane, its size from the
    hyperbola's energy: ``v_p^2 = v_inf^2 + 2 G (m1 + m2) / d``."""
    units = UnitSystem.default()
    G = units.G
    m = ENCOUNTER_MASS
    m_star = 1.0
    x_pair = np.array([1.0, 0.0, 0.0])
    v_pair = np.array([0.0, math.sqrt(G * (m_star + 2 * m)), 0.0])
    v_p = math.sqrt(ENCOUNTER_SPEED ** 2 + 2 * G * (2 * m) / distance)
    r_rel = distance * np.array([1.0, 0.0, 0.0])
    v_rel = v_p * np.array([0.0, 0.6, 0.8])
    x = np.array([np.zeros(3), x_pair - 0.5 * r_rel, x_pair + 0.5 * r_rel])
    v = np.array([np.zeros(3), v_pair - 0.5 * v_rel, v_pair + 0.5 * v_rel])
    masses = np.array([m_star, m, m])
    com_x = masses @ x / masses.sum()
    com_v = masses @ v / masses.sum()
    return units, masses, x - com_x, v - com_v


def _rebound_sim(units, masses, x, v):
    import rebound
    sim = rebound.Simulation()
    sim.G = units.G
    for mi, xi, vi in zip(masses, x, v):
        sim.add(m=float(mi), x=xi[0], y=xi[1], z=xi[2], vx=vi[0], vy=vi[1], vz=vi[2])
    sim.gravity = "basic"
    sim.integrator = "ias15"
    return sim


def _state(sim):
    return (np.array([p.xyz for p in sim.particles]),
            np.array([p.vxyz for p in sim.particles]))


@functools.lru_cache(maxsize=16)
def _encounter_arrays(distance):
    units, masses, x, v = _pair_state(distance)
    sim = _rebound_sim(units, masses, x, v)
    sim.dt = -1e-3
    sim.integrate(-ENCOUNTER_TIME, exact_finish_time=1)
    x0, v0 = _state(sim)
    return units, masses, x0, v0


def encounter_bodies(distance):
    """Star and two Earth-mass planets that pass at ``distance`` au at
    t = :data:`ENCOUNTER_TIME` days.

    The state at closest approach (:func:`_pair_state`) is integrated back by
    ENCOUNTER_TIME with REBOUND's IAS15; integrated forward again, the
    planets meet at that distance (time reversibility, to IAS15's error:
    :func:`pass_distance` measures it).
    """
    units, masses, x0, v0 = _encounter_arrays(float(distance))
    return BodySet.from_arrays(masses, x0, v0, names=["Star", "Planet 1", "Planet 2"],
                               units=units)


def pass_distance(bodies):
    """The pass distance of planets 1 and 2 of an encounter body set, measured
    with REBOUND's IAS15: the separation at ENCOUNTER_TIME and the pericentre
    distance of the pair's osculating two-body orbit there (equal when the
    closest approach is at that time), and the final state at twice that.

    Returns ``(separation, pericentre, x_final)``.
    """
    sim = _rebound_sim(bodies.units, bodies._m, bodies._x, bodies._v)
    sim.integrate(ENCOUNTER_TIME, exact_finish_time=1)
    x, v = _state(sim)
    r, w = x[2] - x[1], v[2] - v[1]
    mu = bodies.units.G * float(bodies._m[1] + bodies._m[2])
    s = float(np.linalg.norm(r))
    h = float(np.linalg.norm(np.cross(r, w)))
    inv_a = 2 / s - float(w @ w) / mu
    e = math.sqrt(max(0.0, 1 - h * h / mu * inv_a))
    q = h * h / mu / (1 + e)
    sim.integrate(2 * ENCOUNTER_TIME, exact_finish_time=1)
    return s, q, _state(sim)[0]


# -- the stiff spring ----------------------------------------------------------------

@numba.njit(cache=True)
def _spring_force(x, v, t):
    # k travels in the state as component 1, with zero velocity and zero
    # acceleration, so it stays exactly k: one compiled force for every k,
    # where a closure over k would compile the stepping loop again for each.
    # Component 2 (always 0) fills the state's row of three, so that no
    # padding the force does not write enters a solver
    a = np.zeros_like(x)
    a[0] = -x[1] * x[0]
    return a


def _spring(name, k, wall_limit):
    """x'' = -k x from x = 1 at rest, dt = SPRING_DT for SPRING_STEPS steps (or
    the same span adaptively at the default tolerance), in SPRING_SEGMENTS
    pieces with a wall-time check between them.

    Fixed-step methods call the force as Python (``py_func``: the same
    arithmetic; 1000 steps take a tenth of a second, less than compiling a
    stepping loop for a user force); adaptive ones, which take up to 1e5
    steps at k = 1e6, call it compiled, after a short untimed run that
    compiles their loop.
    """
    adaptive = _adaptive(name)
    force = _spring_force if adaptive else _spring_force.py_func
    until = SPRING_DT * SPRING_STEPS
    x, v = np.array([1.0, k, 0.0]), np.zeros(3)
    ts, xs, vs = [0.0], [1.0], [0.0]
    cell = {"outcome": "completed", "message": "", "warning": "", "steps": 0}
    per = SPRING_STEPS // SPRING_SEGMENTS
    try:
        if adaptive:
            integrate(force, np.array([1.0, 1.0, 0.0]), np.zeros(3), method=name,
                      until=1e-3, outputs=2)
    except (RunError, IntegratorOptionError):
        pass
    t_start = time.perf_counter()
    for seg in range(SPRING_SEGMENTS):
        t0 = seg * per * SPRING_DT
        try:
            with np.errstate(all="ignore"):
                if adaptive:
                    tr = integrate(force, x, v, method=name, t0=t0, until=t0 + per * SPRING_DT,
                                   outputs=SPRING_OUTPUTS // SPRING_SEGMENTS + 1)
                else:
                    tr = integrate(force, x, v, method=name, t0=t0, dt=SPRING_DT, steps=per)
        except (RunError, IntegratorOptionError) as exc:
            cell.update(outcome=type(exc).__name__, message=str(exc))
            break
        cell["steps"] += tr.steps
        x, v = tr.x[-1].copy(), tr.v[-1].copy()
        ts.extend(tr.t[1:])
        xs.extend(tr.x[1:, 0])
        vs.extend(tr.v[1:, 0])
        if time.perf_counter() - t_start > wall_limit and seg + 1 < SPRING_SEGMENTS:
            cell.update(outcome=WallTimeExceeded.__name__,
                        message=f"passed {wall_limit:g} s at t = {ts[-1]:.6g} of {until:g}")
            break
    ts, xs, vs = np.array(ts), np.array(xs), np.array(vs)
    with np.errstate(all="ignore"):
        cell["error"] = float(np.max(np.abs(xs - np.cos(math.sqrt(k) * ts))))
        energy = 0.5 * vs ** 2 + 0.5 * k * xs ** 2
        cell["energy_error"] = float(np.max(np.abs(energy / (0.5 * k) - 1)))
    cell["wall_time"] = time.perf_counter() - t_start
    return cell


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
    dt = None if _adaptive(name) else period / steps_per_orbit
    row = _measure.run_orbits(bodies, name, options, dt=dt,
                              until=KEPLER_ORBITS[quick] * period, outputs=2,
                              wall_limit=_wall(quick))
    err = _kepler_error(bodies, row, 1.0) if row["outcome"] == "completed" else None
    return _from_row(row, err)


def _eccentricity_cell(name, options, e, quick):
    return _kepler_cell(_scenes.kepler(e=e), name, options, KEPLER_STEPS_PER_ORBIT, quick)


def _mass_ratio_cell(name, options, q, quick):
    import astropy.units as u
    bodies = _scenes.kepler(e=MASS_RATIO_ECCENTRICITY, m_orbiter=q * u.Msun)
    return _kepler_cell(bodies, name, options, MASS_RATIO_STEPS_PER_ORBIT, quick)


def _step_cell(name, options, value, quick):
    bodies = _scenes.outer_solar_system(com=True)
    until = STEP_ORBITS[quick] * _P_JUPITER
    if _adaptive(name):
        row = _measure.run_orbits(bodies, name, {**options, **cases.tolerance_options(name, value)},
                                  until=until,
                                  outputs=2, wall_limit=_wall(quick))
    else:
        row = _measure.run_orbits(bodies, name, options, dt=_P_JUPITER / value, until=until,
                                  outputs=2, wall_limit=_wall(quick))
    return _from_row(row, keep_x=True)


def _encounter_cell(name, options, d, quick):
    bodies = encounter_bodies(d)
    dt = None if _adaptive(name) else ENCOUNTER_DT
    row = _measure.run_orbits(bodies, name, options, dt=dt, until=2 * ENCOUNTER_TIME, outputs=2,
                              wall_limit=_wall(quick))
    return _from_row(row, keep_x=True)


def _pythagorean_cell(name, options, value, quick):
    bodies = _scenes.pythagorean()
    until = PYTHAGOREAN_UNTIL[quick]
    if _adaptive(name):
        row = _measure.run_orbits(bodies, name, {**options, **cases.tolerance_options(name, value)},
                                  until=until,
                                  outputs=PYTHAGOREAN_OUTPUTS, wall_limit=_wall(quick))
    else:
        row = _measure.run_orbits(bodies, name, options, dt=value, until=until,
                                  outputs=PYTHAGOREAN_OUTPUTS, wall_limit=_wall(quick))
    return _from_row(row, row["energy_error_max"])


def _spring_cell(name, options, k, quick):
    return _spring(name, k, _wall(quick))      # default options: no variant here


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


def _rows(sweep):
    """(label, registry name, options) of every row of a sweep's map."""
    return ([(n, n, {}) for n in cases.integrator_names()] + list(VARIANTS.get(sweep, ())))


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
    values = spec.values(quick, _adaptive(integrator))
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
        row = _measure.run_rebound(bodies, "ias15", until=STEP_ORBITS[quick] * _P_JUPITER,
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
        for label, name, options in _rows(sweep):
            cost = _SWEEP_COST[sweep] * _INTEGRATOR_COST.get(name, 1.0) * scale
            out.append(Task(f"{__name__}:measure",
                            {"sweep": sweep, "integrator": name, "quick": quick,
                             "options": options, "label": label}, cost))
        if sweep in ("step", "encounter"):
            out.append(Task(f"{__name__}:reference", {"sweep": sweep, "quick": quick},
                            0.5 * scale))
    return out


# -- the section ---------------------------------------------------------------------

def _error_against(sweep, cell, ref, col):
    """Fill the cell's error from the sweep's REBOUND reference."""
    if cell["outcome"] != "completed" or cell.get("x") is None:
        return None
    x = np.asarray(cell["x"])
    if sweep == "step":
        xr = np.asarray(ref["x"])
        h, hr = x[1:] - x[0], xr[1:] - xr[0]
        # worst planet: heliocentric position error over heliocentric distance
        return float(np.max(np.linalg.norm(h - hr, axis=1) / np.linalg.norm(hr, axis=1)))
    if sweep == "encounter":
        xr = np.asarray(ref["columns"][col]["x"])
        # the pair's separation vector after the pass, relative: the outcome of
        # the encounter (the deflection), not the pair's smooth orbit
        s, sr = x[2] - x[1], xr[2] - xr[1]
        return float(np.linalg.norm(s - sr) / np.linalg.norm(sr))
    raise ValueError(sweep)


def _ranges(labels, idx):
    """Consecutive column indices as "a to b" runs."""
    parts, start = [], None
    for i, j in enumerate(idx):
        if start is None:
            start = j
        if i + 1 == len(idx) or idx[i + 1] != j + 1:
            parts.append(labels[start] if start == j else f"{labels[start]} to {labels[j]}")
            start = None
    return ", ".join(parts)


def _describe(labels, classes, outcomes):
    """For the summary table: where a row is accurate, degraded, failed.  Failed
    columns are grouped by how they failed, each named error after its
    columns ("e = 0.5 to e = 0.99, e = 0.9999 (NonFiniteState)")."""
    out = {}
    for cls in (ACCURATE, DEGRADED, FAILED):
        idx = [i for i, c in enumerate(classes) if c == cls]
        if not idx:
            out[cls] = "-"
        elif cls != FAILED:
            out[cls] = _ranges(labels, idx)
        else:
            parts = []
            for outcome in dict.fromkeys(outcomes[i] for i in idx):
                sub = [i for i in idx if outcomes[i] == outcome]
                text = _ranges(labels, sub)
                parts.append(text if outcome == "completed" else f"{text} ({outcome})")
            out[cls] = ", ".join(parts)
    return out


def _verdict(labels, classes, outcomes):
    """One sentence: accurate up to ..., degraded ..., fails at ... (Error)."""
    d = _describe(labels, classes, outcomes)
    parts = []
    if d[ACCURATE] != "-":
        parts.append(f"accurate at {d[ACCURATE]}")
    if d[DEGRADED] != "-":
        parts.append(f"degraded at {d[DEGRADED]}")
    if d[FAILED] != "-":
        parts.append(f"fails at {d[FAILED]}")
    return "; ".join(parts) or "left out"


_COLOURS = {ACCURATE: "#4caf50", DEGRADED: "#ffc107", FAILED: "#e53935",
            LEFT_OUT: "#d9d9d9"}


def _draw(path, title, panels):
    """One map: panels of (subtitle, row names, column labels, class grid,
    text grid)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    heights = [max(len(p[1]), 1) for p in panels]
    width = max(len(p[2]) for p in panels)
    fig, axes = plt.subplots(len(panels), 1, squeeze=False,
                             figsize=(2.4 + 0.95 * width, 1.2 + 0.3 * sum(heights)
                                      + 0.6 * len(panels)),
                             gridspec_kw={"height_ratios": heights})
    cmap = ListedColormap([_COLOURS[c] for c in _CLASSES])
    for ax, (subtitle, rows, cols, grid, text) in zip(axes[:, 0], panels):
        codes = np.array([[_CLASSES.index(c) for c in r] for r in grid], dtype=float)
        codes = codes.reshape(len(rows), len(cols))
        ax.imshow(codes, cmap=cmap, vmin=-0.5, vmax=len(_CLASSES) - 0.5, aspect="auto")
        for i in range(len(rows)):
            for j in range(len(cols)):
                ax.text(j, i, text[i][j], ha="center", va="center", fontsize=7)
        ax.set_xticks(range(len(cols)), cols, fontsize=8)
        ax.set_yticks(range(len(rows)), rows, fontsize=8)
        ax.xaxis.tick_top()
        ax.set_xticks(np.arange(-0.5, len(cols)), minor=True)
        ax.set_yticks(np.arange(-0.5, len(rows)), minor=True)
        ax.grid(which="minor", color="white", linewidth=1)
        ax.tick_params(which="minor", length=0)
        if subtitle:
            ax.set_title(subtitle, fontsize=9, loc="left")
    fig.suptitle(title, fontsize=11)
    fig.legend(handles=[Patch(color=_COLOURS[c], label=c) for c in _CLASSES],
               loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _grid(spec, rows_by_name, names, refs, quick, adaptive):
    """Classes, texts and sentences of one panel."""
    values = spec.values(quick, adaptive)
    fmt = spec.adaptive_label if (adaptive and spec.split) else spec.label
    labels = [fmt(v) for v in values]
    classes, texts, table, notes = [], [], [], []
    for name in names:
        row = rows_by_name.get(name)
        if row is None or row["left_out"] is not None:
            classes.append([LEFT_OUT] * len(values))
            texts.append(["n/a"] * len(values))
            table.append((name, None, row["left_out"] if row else "not measured"))
            continue
        cls_row, txt_row, outs, reason = [], [], [], ""
        for j, cell in enumerate(row["cells"]):
            err = cell["error"]
            if spec.key in refs:
                err = cell["error"] = _error_against(spec.key, cell, refs[spec.key], j)
            cls = classify(err, cell["outcome"], spec.metric)
            cls_row.append(cls)
            txt_row.append(_cell_text(cls, cell["outcome"], err))
            outs.append(cell["outcome"])
            if cls == LEFT_OUT and cell["outcome"] != "Skipped":
                reason = cell["message"].split(";")[0]
            if cell["warning"]:
                notes.append(f"{name} at {labels[j]}: {cell['warning'][:160]}")
        classes.append(cls_row)
        texts.append(txt_row)
        if all(c == LEFT_OUT for c in cls_row):
            table.append((name, None, reason))
        else:
            verdict = _verdict(labels, cls_row, outs)
            skipped = [labels[j] for j, o in enumerate(outs) if o == "Skipped"]
            if skipped:
                verdict += (f"; not run at {', '.join(skipped)} (an easier column passed "
                            f"the wall-time limit)")
            table.append((name, _describe(labels, cls_row, outs), verdict))
    return labels, classes, texts, table, notes


_INTRO = """\
Each map shows one sweep: integrators as rows, the swept value as columns.  A
cell is **accurate** (green) when its error is below {ap:g} (position, relative)
or {ae:g} (energy), **failed** (red) from {fp:g} (position) or {fe:g}
(energy), or when the run stopped with a named error, and **degraded** (amber)
in between; grey cells are integrators that do not apply ("n/a"), listed
below each map with the reason, or harder columns not run after an easier one
passed the wall-time limit ("skip").  The number in a cell is log10 of the error; a failed run
shows its error's abbreviation: NFS = NonFiniteState, SSU = StepSizeUnderflow,
CF = ConvergenceFailure, WTE = WallTimeExceeded (the run passed {wall:g} s of
wall time; a limit, not a wrong result).  A position error of a tenth of the
orbit is a different trajectory, hence the failure threshold; an energy error
of one per cent is already a tenth of an orbit in phase within an orbit.
Adaptive methods run at their default tolerance (rtol 1e-9, atol 1e-12;
IAS15 epsilon 1e-9) except where a sweep varies it.
"""

_SWEEP_TEXT = {
    "eccentricity": """\
A Sun-mass star and a Jupiter-mass planet (1e-3 Msun), a = 1 au, from true
anomaly 1 rad, for {orbits:g} orbits, so that the run ends away from
pericentre.  Fixed-step methods take dt = P/{kn}.  Error: the final planet-star
vector against the analytic orbit (Kepler's equation solved by
`orbits._kernels.anomalies`, no integrator involved), in units of a.""",
    "step": """\
The outer solar system (Hairer, Lubich & Wanner: Sun, four giant planets,
Pluto) for {jorb} periods of Jupiter (P_J = {pj:g} days; {years:.0f} years).
Fixed-step methods sweep the step; adaptive methods have no step to set and sweep their
tolerance instead (rtol = tol, atol = 1e-3 tol; IAS15 epsilon = tol).  Error:
the worst planet's final heliocentric position against REBOUND's IAS15
(default epsilon), over its heliocentric distance.""",
    "mass-ratio": """\
Two bodies, m2/m1 = q with m1 = 1 Msun, e = {me:g}, a = 1 au, for {orbits:g} orbits
at dt = P/{mn} (fixed-step methods).  Error: the final relative vector
against the analytic orbit, in units of a.  With two bodies the Jacobi split
of the Wisdom-Holman family is exact at any q (one Kepler orbit, no
interaction term); democratic heliocentric coordinates, added as a row, keep
the star's reflex motion as a separate term whose error grows with q.""",
    "encounter": """\
A Sun-mass star and two planets of {em:g} Msun each on a 1 au orbit, meeting
at {vinf:g} km/s at infinity, passing at the column's distance at t = {te:g} days;
the run ends at {te2:g} days.  The initial state is the closest approach
integrated backwards by REBOUND's IAS15, so the pass distance is set, not
hoped for; the table below measures it again in the forward reference run.
Fixed-step methods take dt = {edt:g} day.  Reference: REBOUND's IAS15 from the
same initial state.  Error: the planets' final separation vector against the
reference, over its length (the outcome of the encounter).  Point masses: at
1e-8 au the planets would have merged long before.""",
    "pythagorean": """\
Burrau's three bodies (masses 3, 4, 5 at rest, G = 1) from t = 0 to {pu:g},
through their close encounters.  Fixed-step methods sweep dt, adaptive ones
their tolerance.  The motion is chaotic, so the error is the largest relative
energy error over {po} outputs, not a final position.""",
    "spring": """\
x'' = -k x with m = 1, x0 = 1, v0 = 0, through `orbits.integrate`; fixed-step
methods take dt = {sdt:g} for {sn} steps (the integrator-choice guide's step;
sqrt(k) dt runs from 0.01 to 10), adaptive ones cover the same t = 0 to {su:g} at
their default tolerance.  One compiled force serves every k: k travels in
the state as a second component with zero velocity and acceleration (it
stays exactly k), and a third, zero, fills the state's row of three.  Runs are made of {seg} pieces with a wall-time check
between them (adaptive ones restart their step control at each).  Error: the
largest |x(t) - cos(sqrt(k) t)| over the run (amplitude 1).""",
}


def _sweep_text(key, quick):
    return _SWEEP_TEXT[key].format(
        orbits=KEPLER_ORBITS[quick], kn=KEPLER_STEPS_PER_ORBIT, jorb=STEP_ORBITS[quick],
        years=STEP_ORBITS[quick] * _P_JUPITER / 365.25,
        pj=_P_JUPITER, me=MASS_RATIO_ECCENTRICITY, mn=MASS_RATIO_STEPS_PER_ORBIT,
        em=ENCOUNTER_MASS, vinf=round(ENCOUNTER_SPEED * 1.495978707e8 / 86400, 1),
        te=ENCOUNTER_TIME, te2=2 * ENCOUNTER_TIME, edt=ENCOUNTER_DT,
        pu=PYTHAGOREAN_UNTIL[quick], po=PYTHAGOREAN_OUTPUTS, sdt=SPRING_DT, sn=SPRING_STEPS,
        su=SPRING_DT * SPRING_STEPS, seg=SPRING_SEGMENTS)


def section(rows, out_dir, quick):
    """The stress suite's Markdown, with its maps written into ``out_dir``."""
    import pathlib
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    refs = {r["sweep"]: r for r in rows if r.get("kind") == "reference"}
    by_sweep = {}
    for r in rows:
        if r.get("kind") == "row":
            by_sweep.setdefault(r["sweep"], {})[r["label"]] = r
    md = [f"## {TITLE}", "",
          _INTRO.format(ap=ACCURATE_POSITION, ae=ACCURATE_ENERGY, fp=FAILED_POSITION,
                        fe=FAILED_ENERGY, wall=_wall(quick)).strip(), ""]
    if quick:
        md += ["*Quick mode: fewer columns and shorter runs than the full report.*", ""]
    for key, spec in SWEEPS.items():
        if key not in by_sweep:
            continue
        rows_by_name = by_sweep[key]
        md += [f"### {spec.title}", "", _sweep_text(key, quick), ""]
        panels, tables, notes = [], [], []
        labels = [lab for lab, _, _ in _rows(key)]
        adaptive = {lab: _adaptive(name) for lab, name, _ in _rows(key)}
        groups = ([("fixed-step methods: step", [n for n in labels if not adaptive[n]], False),
                   ("adaptive methods: tolerance", [n for n in labels if adaptive[n]], True)]
                  if spec.split else [("", labels, False)])
        for subtitle, group, adaptive in groups:
            labels, classes, texts, table, nts = _grid(spec, rows_by_name, group, refs,
                                                       quick, adaptive)
            panels.append((subtitle, group, labels, classes, texts))
            tables.append((subtitle, table))
            notes += nts
        png = f"stress_{key.replace('-', '_')}.png"
        _draw(out_dir / png, spec.title, panels)
        md += [f"![{spec.title}]({png})", ""]
        if key == "encounter" and key in refs:
            md += _encounter_table(refs[key])
        left = []
        for subtitle, table in tables:
            if subtitle:
                md += [f"*{subtitle[0].upper()}{subtitle[1:]}*", ""]
            md += ["| integrator | accurate | degraded | failed | in a sentence |",
                   "|---|---|---|---|---|"]
            for name, desc, verdict in table:
                if desc is None:
                    md.append(f"| {name} | - | - | - | left out |")
                    left.append(f"- **{name}**: {verdict}")
                else:
                    md.append(f"| {name} | {desc[ACCURATE]} | {desc[DEGRADED]} | "
                              f"{desc[FAILED]} | {verdict} |")
            md.append("")
        if left:
            md += ["Left out:", ""] + left + [""]
        if notes:
            md += ["Warnings:", ""] + [f"- {n}" for n in sorted(set(notes))] + [""]
    return "\n".join(md).rstrip() + "\n"


def _encounter_table(ref):
    md = ["Pass distance measured in the reference run (REBOUND IAS15): the separation at",
          f"t = {ENCOUNTER_TIME:g} days and the pericentre of the pair's osculating "
          "two-body orbit there.", "",
          "| asked (au) | separation (au) | pericentre (au) | relative difference |",
          "|---|---|---|---|"]
    for c in ref["columns"]:
        diff = max(abs(c["separation"] / c["value"] - 1), abs(c["pericentre"] / c["value"] - 1))
        md.append(f"| {_sci(c['value'])} | {c['separation']:.6e} | {c['pericentre']:.6e} | "
                  f"{diff:.1e} |")
    return md + [""]

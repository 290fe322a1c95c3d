"""The stress suite's problems that need more than a scene, with their oracles:
the analytic Kepler orbit, the close encounter whose initial state REBOUND's
IAS15 makes by integrating the pass backwards (and whose pass distance it
measures), and the stiff spring run through :func:`orbits.integrate`.
"""

import functools
import math
import time

import numba
import numpy as np

from ... import integrators as _integrators
from ...bodies import BodySet
from ...custom import integrate
from ...errors import IntegratorOptionError, RunError, WallTimeExceeded
from ...units import UnitSystem
from ..._kernels import anomalies as _anomalies
from ..._kernels import elements as _elements
from ..._kernels.status import Status, describe_status

__all__ = ["kepler_reference", "kepler_error", "encounter_bodies", "pass_distance", "spring",
           "adaptive", "ENCOUNTER_MASS", "ENCOUNTER_SPEED", "ENCOUNTER_TIME", "ENCOUNTER_DT",
           "SPRING_DT", "SPRING_STEPS", "SPRING_SEGMENTS", "SPRING_OUTPUTS"]

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

SPRING_DT = 0.01
SPRING_STEPS = 1000
SPRING_SEGMENTS = 10                  # wall-time checks per run
SPRING_OUTPUTS = 100                  # adaptive samples over the run


def adaptive(name):
    """Whether the integrator ``name`` is adaptive (it sweeps its tolerance, not a step)."""
    return _integrators.get(name).adaptive


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


def kepler_error(bodies, row, scale):
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


def spring(name, k, wall_limit):
    """x'' = -k x from x = 1 at rest, dt = SPRING_DT for SPRING_STEPS steps (or
    the same span adaptively at the default tolerance), in SPRING_SEGMENTS
    pieces with a wall-time check between them.

    Fixed-step methods call the force as Python (``py_func``: the same
    arithmetic; 1000 steps take a tenth of a second, less than compiling a
    stepping loop for a user force); adaptive ones, which take up to 1e5
    steps at k = 1e6, call it compiled, after a short untimed run that
    compiles their loop.
    """
    is_adaptive = adaptive(name)
    force = _spring_force if is_adaptive else _spring_force.py_func
    until = SPRING_DT * SPRING_STEPS
    x, v = np.array([1.0, k, 0.0]), np.zeros(3)
    ts, xs, vs = [0.0], [1.0], [0.0]
    cell = {"outcome": "completed", "message": "", "warning": "", "steps": 0}
    per = SPRING_STEPS // SPRING_SEGMENTS
    try:
        if is_adaptive:
            integrate(force, np.array([1.0, 1.0, 0.0]), np.zeros(3), method=name,
                      until=1e-3, outputs=2)
    except (RunError, IntegratorOptionError):
        pass
    t_start = time.perf_counter()
    for seg in range(SPRING_SEGMENTS):
        t0 = seg * per * SPRING_DT
        try:
            with np.errstate(all="ignore"):
                if is_adaptive:
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

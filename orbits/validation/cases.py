"""The problems of the validation report, and which integrators apply to each.

Every problem is a built-in scene with a run length, a fixed step for the
fixed-step methods, and the facts that decide what applies to it.  An
integrator that does not apply is left out with a reason, and the report
lists those reasons, so that a missing row is never a mystery:

* the Wisdom-Holman family (``wh``, ``saba2/3/4`` and REBOUND's WHFast) needs
  one body that dominates the mass (:data:`orbits.integrators.wisdom_holman.MASS_RATIO_LIMIT`);
* scipy's ``radau`` and ``lsoda`` call the force from Python at every
  evaluation, about a thousand times slower per step than the compiled loops;
  they run only where a run has few steps (they are references for stiff user
  problems, and the stress suite's spring sweep has them);
* explicit Euler (first order, energy growing every orbit) is left out of
  long runs, where it only measures how fast it diverges.

Times and lengths are in each scene's own units (:attr:`Problem.time_unit`,
:attr:`Problem.length_unit`).
"""

import math
from typing import NamedTuple

from .. import integrators as _integrators
from .. import scenes as _scenes
from ..integrators.wisdom_holman import MASS_RATIO_LIMIT

__all__ = ["Problem", "PROBLEMS", "problem", "applies", "WISDOM_HOLMAN", "PYTHON_FORCE",
           "DIVERGENT", "mass_ratio", "bodies"]

#: Integrators that split the motion into Kepler orbits about one body.
WISDOM_HOLMAN = ("wh", "saba2", "saba3", "saba4", "trace")

#: Integrators whose force is called from Python (scipy's solve_ivp).
PYTHON_FORCE = ("radau", "lsoda")

#: First-order explicit methods, left out of long runs.
DIVERGENT = ("euler",)

#: Above this many orbits of the shortest period (full report, quick report)
#: a Python-force method takes longer than the rest of a problem's rows
#: together: scipy's Radau takes some 400 steps of about 0.5 ms an orbit at
#: its default tolerance.
PYTHON_FORCE_ORBITS = (150, 30)

_YEAR = 365.25


def _kepler_period(a_au=1.0, m_sum=1.001):
    # P = 2 pi sqrt(a^3 / (G M)) in days, G = GM_sun in au^3 / day^2
    gm_sun = 2.959122082855911e-4
    return 2 * math.pi * math.sqrt(a_au ** 3 / (gm_sun * m_sum))


_P_KEPLER = _kepler_period()
_P_MOON = 27.321661           # sidereal month, days
_P_JUPITER = 4332.59          # days


class Problem(NamedTuple):
    """One problem of the report.

    ``until`` and ``until_quick`` are the run lengths of the full and the
    quick report, ``dt`` the fixed methods' step, all in the scene's time
    unit; ``period`` is the shortest orbital period (for the Pythagorean
    problem the time its bodies take to fall together, about 1).
    """

    key: str
    title: str
    scene: str
    scene_kwargs: dict
    until: float
    until_quick: float
    dt: float
    period: float
    time_unit: str
    length_unit: str
    span: str              # the full run's length in words
    span_quick: str

    def length(self, quick):
        return self.until_quick if quick else self.until

    def steps(self, quick):
        return int(round(self.length(quick) / self.dt))


PROBLEMS = (
    Problem("kepler-e0.5", "Kepler orbit, e = 0.5", "kepler", {"e": 0.5},
            1000 * _P_KEPLER, 100 * _P_KEPLER, _P_KEPLER / 200, _P_KEPLER, "day", "au",
            "1000 orbits", "100 orbits"),
    Problem("kepler-e0.9", "Kepler orbit, e = 0.9", "kepler", {"e": 0.9},
            1000 * _P_KEPLER, 100 * _P_KEPLER, _P_KEPLER / 1000, _P_KEPLER, "day", "au",
            "1000 orbits", "100 orbits"),
    Problem("earth-moon", "Earth-Moon", "earth-moon", {},
            10 * _YEAR, 1 * _YEAR, 1.0 / 24, _P_MOON, "day", "km", "10 years", "1 year"),
    Problem("outer-solar-system", "outer solar system (HLW)", "outer-solar-system", {},
            1e4 * _YEAR, 1e3 * _YEAR, 10.0, _P_JUPITER, "day", "au",
            "10,000 years", "1000 years"),
    Problem("sun-8-planets", "Sun and eight planets (J2000)", "solar-system", {"moon": False},
            1e3 * _YEAR, 1e2 * _YEAR, 1.0, 87.969, "day", "au", "1000 years", "100 years"),
    Problem("pythagorean", "Pythagorean three-body problem", "pythagorean", {},
            70.0, 20.0, 1e-4, 1.0, "N-body", "N-body", "t = 0 to 70", "t = 0 to 20"),
    Problem("figure-eight", "figure-eight choreography", "figure-eight", {},
            100 * _scenes.FIGURE_EIGHT_PERIOD, 10 * _scenes.FIGURE_EIGHT_PERIOD,
            _scenes.FIGURE_EIGHT_PERIOD / 1000, _scenes.FIGURE_EIGHT_PERIOD, "N-body", "N-body",
            "100 periods", "10 periods"),
)

_BY_KEY = {p.key: p for p in PROBLEMS}


def problem(key):
    """The :class:`Problem` named ``key``."""
    try:
        return _BY_KEY[key]
    except KeyError:
        raise KeyError(f"unknown problem {key!r}; valid: {', '.join(_BY_KEY)}") from None


def bodies(prob):
    """A fresh body set of the problem."""
    return _scenes.get(prob.scene, **prob.scene_kwargs)


def mass_ratio(body_set):
    """Largest other mass over the first body's (the central one)."""
    m = body_set._m
    return float(m[1:].max() / m[0]) if len(m) > 1 and m[0] > 0 else math.inf


def applies(prob, name, quick=False, body_set=None, length=None):
    """None if integrator ``name`` (ours or ``"rebound-whfast"``, ...) applies to
    ``prob`` run for ``length`` (default: the problem's own), else the reason
    it is left out (a sentence)."""
    if name in WISDOM_HOLMAN or name == "rebound-whfast":
        ratio = mass_ratio(body_set if body_set is not None else bodies(prob))
        if ratio > MASS_RATIO_LIMIT:
            return (f"no dominant body (largest other mass {ratio:.2g} of the first, above "
                    f"{MASS_RATIO_LIMIT:g}): the Wisdom-Holman split assumes Kepler orbits "
                    f"about one body")
    if name in PYTHON_FORCE:
        n = (prob.length(quick) if length is None else length) / prob.period
        if n > PYTHON_FORCE_ORBITS[1 if quick else 0]:
            return (f"scipy's solver calls the force from Python: {n:,.0f} orbits of the "
                    f"shortest period would take minutes; it is a reference for stiff user "
                    f"problems, run in the stress suite's spring sweep")
    return None


def tolerance_options(name, tol):
    """Adaptive method ``name``'s options for tolerance ``tol``: rtol = tol and
    atol = 1e-3 tol (their default ratio), IAS15's epsilon = tol, the Taylor
    method's tol = tol (which sets its order)."""
    options = _integrators.get(name).options
    if "epsilon" in options:
        return {"epsilon": tol}
    if "tol" in options:
        return {"tol": tol}
    return {"rtol": tol, "atol": 1e-3 * tol}


def integrator_names():
    """Every registered integrator, in registry order."""
    return [info.name for info in _integrators.available()]

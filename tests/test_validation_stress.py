"""The stress suite (orbits.validation.stress): classification, the
close-encounter set-up, named failures and a tiny sweep end to end."""

import math
import re

import numpy as np
import pytest

pytest.importorskip("rebound")
pytest.importorskip("matplotlib")

from orbits import Simulation, integrators, scenes  # noqa: E402
from orbits.validation import _runner, cases, stress  # noqa: E402
from orbits.validation.stress import classes, maps, problems  # noqa: E402

EPS = np.finfo(float).eps


# -- classification --------------------------------------------------------------------

def test_classify_thresholds():
    a, f = stress.ACCURATE_POSITION, stress.FAILED_POSITION
    assert stress.classify(0.0) == stress.ACCURATE
    assert stress.classify(0.5 * a) == stress.ACCURATE
    assert stress.classify(a) == stress.DEGRADED          # the bound belongs to the worse class
    assert stress.classify(0.5 * f) == stress.DEGRADED
    assert stress.classify(f) == stress.FAILED
    ae, fe = stress.ACCURATE_ENERGY, stress.FAILED_ENERGY
    assert stress.classify(0.5 * ae, metric="energy") == stress.ACCURATE
    assert stress.classify(0.5 * fe, metric="energy") == stress.DEGRADED
    assert stress.classify(fe, metric="energy") == stress.FAILED
    assert stress.ACCURATE_POSITION < stress.FAILED_POSITION
    assert stress.ACCURATE_ENERGY < stress.FAILED_ENERGY


def test_classify_named_errors_and_non_finite():
    # a named run error fails the cell whatever its error; a non-finite or
    # missing error of a completed run is a failure, never a number shown
    assert stress.classify(1e-12, "NonFiniteState") == stress.FAILED
    assert stress.classify(1e-12, "WallTimeExceeded") == stress.FAILED
    assert stress.classify(math.nan) == stress.FAILED
    assert stress.classify(math.inf) == stress.FAILED
    assert stress.classify(None) == stress.FAILED
    # a refusal (the Wisdom-Holman family takes no user force) or a cell not
    # run is left out, not failed
    assert stress.classify(None, "IntegratorOptionError") == stress.LEFT_OUT
    assert stress.classify(None, "Skipped") == stress.LEFT_OUT


def test_abbreviations():
    assert stress.abbreviation("NonFiniteState") == "NFS"
    assert stress.abbreviation("StepSizeUnderflow") == "SSU"
    assert stress.abbreviation("ConvergenceFailure") == "CF"
    assert stress.abbreviation("WallTimeExceeded") == "WTE"
    assert stress.abbreviation("SomeNewError") == "SNE"


def test_verdict_ranges():
    labels = ["e = 0", "e = 0.5", "e = 0.9", "e = 0.99", "e = 0.9999"]
    classes = [stress.ACCURATE, stress.ACCURATE, stress.ACCURATE, stress.DEGRADED,
               stress.FAILED]
    outcomes = ["completed"] * 4 + ["NonFiniteState"]
    assert maps._verdict(labels, classes, outcomes) == (
        "accurate at e = 0 to e = 0.9; degraded at e = 0.99; "
        "fails at e = 0.9999 (NonFiniteState)")
    # failed columns grouped by how they failed, the named error after its own
    classes = [stress.DEGRADED, stress.FAILED, stress.FAILED, stress.FAILED, stress.FAILED]
    outcomes = ["completed", "completed", "completed", "StepSizeUnderflow", "NonFiniteState"]
    assert maps._describe(labels, classes, outcomes)[stress.FAILED] == (
        "e = 0.5 to e = 0.9, e = 0.99 (StepSizeUnderflow), e = 0.9999 (NonFiniteState)")


def test_every_integrator_in_every_sweep():
    # each map must show every registered integrator (run or left out)
    names = set(cases.integrator_names())
    rows = {}
    for t in stress.tasks(quick=True):
        if t.function.endswith(":measure"):
            rows.setdefault(t.kwargs["sweep"], set()).add(t.kwargs["integrator"])
        assert t.cost > 0
    assert set(rows) == set(stress.SWEEPS)
    for sweep, got in rows.items():
        assert got == names, sweep


# -- references ------------------------------------------------------------------------

@pytest.mark.parametrize("e", [0.0, 0.5, 0.9999])
def test_kepler_reference_returns_after_whole_orbits(e):
    bodies = scenes.kepler(e=e)
    mu = bodies.units.G * float(bodies._m.sum())
    period = 2 * math.pi / math.sqrt(mu)          # a = 1 au
    r0 = bodies._x[1] - bodies._x[0]
    v0 = bodies._v[1] - bodies._v[0]
    back = stress.kepler_reference(mu, r0, v0, 7 * period)
    # seven turns of the mean anomaly: only the rounding of n t (about
    # 7 * 2 pi * eps) times the speed's amplification near pericentre,
    # (1 + e) / (1 - e) ~ 2e4 at e = 0.9999, so 1e-10 au is loose and a
    # wrong period or anomaly would miss by order 1
    assert np.linalg.norm(back - r0) < 1e-10
    half = stress.kepler_reference(mu, r0, v0, 0.5 * period)
    assert np.linalg.norm(half - r0) > 1e-3 * np.linalg.norm(r0)


@pytest.mark.parametrize("distance", [1e-3, 1e-8])
def test_encounter_passes_at_the_requested_distance(distance):
    bodies = stress.encounter_bodies(distance)
    start = np.linalg.norm(bodies._x[2] - bodies._x[1])
    assert start > 10 * distance               # the planets start well apart
    separation, pericentre, _ = stress.pass_distance(bodies)
    # positions near 1 au carry eps au of rounding, that is eps / d of the
    # separation, and the state went back and forth through IAS15: allow
    # 100 such roundings (2e-11 at 1e-3 au, 2e-6 at 1e-8 au); a pass that
    # missed its time or its speed would be off by order one
    tol = 100 * EPS * 1.0 / distance
    assert abs(separation / distance - 1) < tol
    assert abs(pericentre / distance - 1) < tol


def test_encounter_distance_confirmed_by_our_integrator():
    # an integrator of ours, not REBOUND: dop853 at rtol 1e-12 to the moment
    # of closest approach.  Its error over 5 days is below 1e-9 au at each
    # planet (rtol 1e-12 on 1 au positions, a few hundred steps), far inside
    # the 1e-3 * 1e-3 au allowed here; a pass set up wrongly would miss by
    # more than the distance itself
    import astropy.units as u
    d = 1e-3
    sim = Simulation(stress.encounter_bodies(d),
                     integrator=integrators.get("dop853", rtol=1e-12, atol=1e-15))
    sim.run(until=stress.ENCOUNTER_TIME * u.day, outputs=2, progress=False, wall_limit=60)
    x = sim._x[np.argsort(sim._order)]
    assert abs(np.linalg.norm(x[2] - x[1]) / d - 1) < 1e-3


# -- named failures --------------------------------------------------------------------

def test_forced_failure_becomes_a_named_cell():
    # explicit Euler on k = 1e6 at dt = 0.01 (sqrt(k) dt = 10) grows by a
    # factor 10 a step: the state overflows within the 1000 steps
    cell = problems.spring("euler", 1e6, wall_limit=30)
    assert cell["outcome"] == "NonFiniteState"
    cls = stress.classify(cell["error"], cell["outcome"])
    assert cls == stress.FAILED
    assert classes.cell_text(cls, cell["outcome"], cell["error"]) == "NFS"


def test_refusal_is_left_out_with_the_reason():
    cell = problems.spring("wh", 1.0, wall_limit=30)
    assert cell["outcome"] == "IntegratorOptionError"
    assert stress.classify(cell["error"], cell["outcome"]) == stress.LEFT_OUT
    assert cell["message"]


def test_spring_accurate_where_resolved():
    # leapfrog at sqrt(k) dt = 0.01: phase error about (omega dt)^2 / 24 per
    # radian over 10 radians, 4e-5: degraded by our thresholds, not failed
    cell = problems.spring("leapfrog", 1.0, wall_limit=30)
    assert cell["outcome"] == "completed"
    assert 1e-6 < cell["error"] < 1e-4
    assert stress.classify(cell["error"]) == stress.DEGRADED


# -- a tiny sweep end to end -----------------------------------------------------------

def test_tiny_sweep_serial(tmp_path, monkeypatch):
    sweeps = {
        "eccentricity": stress.SWEEPS["eccentricity"]._replace(quick=(0.5, 0.9999)),
        "spring": stress.SWEEPS["spring"]._replace(quick=(1.0, 1e6)),
    }
    monkeypatch.setattr(stress.sweeps, "SWEEPS", sweeps)
    monkeypatch.setattr(cases, "integrator_names", lambda: ["euler", "leapfrog", "wh"])
    tasks = stress.tasks(quick=True)
    with _runner.Pool(n_workers=1) as pool:
        rows = _runner.run_tasks(tasks, pool, progress=False)
    assert len(rows) == len(tasks)
    md = stress.section(rows, tmp_path, quick=True)
    assert md.startswith("## Stress suite")
    for png in ("stress_eccentricity.png", "stress_spring.png"):
        data = (tmp_path / png).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 2000
        assert f"]({png})" in md
    assert not re.search(r"\bnan\b", md, re.IGNORECASE)
    # the failure is named in the table, the refusal listed with its reason
    euler = next(line for line in md.splitlines()
                 if line.startswith("| euler |") and "k = " in line)
    assert "NonFiniteState" in euler
    assert "- **wh**:" in md
    # wh integrates a two-body orbit exactly (Kepler drifts), at any eccentricity
    wh = next(line for line in md.splitlines()
              if line.startswith("| wh |") and "e = " in line)
    assert "accurate at e = 0.5 to e = 0.9999" in wh

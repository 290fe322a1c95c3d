"""The validation report's machinery: problems, measured runs, sections, command."""

import math
import re

import numpy as np
import pytest

import orbits
from orbits import cli
from orbits.validation import cases, drift, guide, work_precision
from orbits.validation._measure import on_steps, run_orbits, run_rebound

pytest.importorskip("rebound")


def test_wisdom_holman_left_out_without_a_dominant_body():
    prob = cases.problem("pythagorean")
    for name in cases.WISDOM_HOLMAN + ("rebound-whfast",):
        reason = cases.applies(prob, name)
        assert reason is not None and "dominant" in reason
    assert cases.applies(cases.problem("outer-solar-system"), "wh") is None


def test_python_force_methods_left_out_of_long_runs_only():
    # the Sun with eight planets over 1000 years is ~4000 Mercury orbits; the
    # quick figure-eight is 10 periods
    assert cases.applies(cases.problem("sun-8-planets"), "radau") is not None
    assert cases.applies(cases.problem("figure-eight"), "radau", quick=True) is None


def test_every_registered_integrator_is_run_or_left_out_with_a_reason():
    from orbits.validation import accuracy
    ran = {(t.kwargs["problem"], t.kwargs["integrator"]) for t in accuracy.tasks(True)
           if not t.kwargs.get("rebound")}
    skipped = {(p, n) for p, n, _ in accuracy.left_out(True)}
    for prob in cases.PROBLEMS:
        for name in cases.integrator_names():
            assert ((prob.key, name) in ran) != ((prob.key, name) in skipped), (prob.key, name)


def test_unknown_problem_lists_the_valid_ones():
    with pytest.raises(KeyError, match="outer-solar-system"):
        cases.problem("nope")


def test_output_times_on_whole_steps():
    assert np.array_equal(on_steps([0.4, 10.2, 10.4, 31.0], 10.0), [10.0, 30.0])
    assert np.array_equal(on_steps([0.4, 2.5], None), [0.4, 2.5])


def test_leapfrog_measured_alike_in_both_codes():
    # the same floats, G and step: the kernels differ only in rounding (an ulp or
    # so a step), so 3652 steps of 10 days leave the codes within ~1e-12 au,
    # while a step-count or output-time mismatch would show as > 1e-6 au
    bodies = orbits.scenes.outer_solar_system()
    ours = run_orbits(bodies, "leapfrog", dt=10.0, until=36525.0, outputs=11)
    theirs = run_rebound(bodies, "leapfrog", dt=10.0, until=36525.0, outputs=11)
    assert ours["steps"] == theirs["steps"] == 3652
    assert np.abs(ours["x"] - theirs["x"]).max() < 1e-10
    # energy errors are the same physics: equal to 1e-6 of their size
    assert math.isclose(ours["energy_error_max"], theirs["energy_error_max"], rel_tol=1e-6)
    assert np.allclose(ours["times"], theirs["times"])


def test_a_failure_is_a_named_outcome_with_the_errors_so_far():
    # backward Euler damps the figure-eight's bodies together: Newton fails
    # (measured: step ~1400 of 10000 at dt = P/1000)
    bodies = orbits.scenes.figure_eight()
    p = orbits.scenes.FIGURE_EIGHT_PERIOD
    row = run_orbits(bodies, "implicit-euler", dt=p / 1000, until=10 * p, outputs=11)
    assert row["outcome"] == "ConvergenceFailure"
    assert "did not converge" in row["message"]
    assert 0 < row["steps"] < 10_000
    assert np.all(np.isfinite(row["x"]))
    assert np.isfinite(row["energy_error_max"])


def test_wall_limit_is_a_named_outcome():
    bodies = orbits.scenes.outer_solar_system()
    row = run_orbits(bodies, "yoshida8", dt=1.0, until=1e9, outputs=2, wall_limit=0.3)
    assert row["outcome"] == "WallTimeExceeded"
    assert 0 < row["t_end"] < 1e9


def test_warning_recorded():
    row = run_orbits(orbits.scenes.figure_eight(), "wh", dt=0.01, until=0.1, outputs=2)
    assert row["warning"].startswith("NoDominantBodyWarning")


@pytest.mark.parametrize("exponent, law", [(0.02, "bounded"), (0.5, "random walk (t^0.5)"),
                                           (1.0, "linear"), (2.0, "quadratic or faster"),
                                           (math.nan, "–")])
def test_drift_law(exponent, law):
    assert drift.classify(exponent) == law


def test_every_integrator_in_the_drift_section_or_left_out():
    run = {r[2] for r in drift.RUNS if not r[1]}
    assert run.isdisjoint(drift.LEFT_OUT)
    assert run | set(drift.LEFT_OUT) == set(cases.integrator_names())


def test_cheapest_ignores_failures_and_the_reference():
    rows = [dict(series="a", outcome="completed", position_error=1e-9, wall_time=2.0),
            dict(series="a", outcome="completed", position_error=1e-3, wall_time=0.1),
            dict(series="b", outcome="completed", position_error=1e-9, wall_time=1.0),
            dict(series="c", outcome="NonFiniteState", position_error=1e-12, wall_time=0.01),
            dict(series="reference", outcome="completed", position_error=0.0,
                 wall_time=0.001)]
    assert work_precision.cheapest(rows, 1e-8) == [("b", 1.0), ("a", 2.0)]
    assert work_precision.cheapest(rows, 1e-2)[0] == ("a", 0.1)


@pytest.mark.slow  # ~20 s: the validate command end to end on its cheapest section
def test_guide_section_by_command(tmp_path):
    # the whole command on its cheapest section, in this process
    assert cli.main(["validate", "--only", "guide", "--workers", "1", "--out",
                     str(tmp_path), "--no-progress"]) == 0
    text = (tmp_path / "report.md").read_text()
    assert (tmp_path / "guide_spring.png").stat().st_size > 10_000
    # explicit Euler multiplies the energy by exactly 1 + k dt^2 a step: 1.01^100 - 1
    assert f"{100 * guide.euler_theory(100):.4g} %" in text
    row = re.search(r"\| euler \| 1 \| no \| ([0-9.e+-]+) \|", text)
    assert row and math.isclose(float(row.group(1)), 1.01 ** 100 - 1, rel_tol=1e-2)
    assert not re.search(r"\bnan\b", text, re.IGNORECASE)


def test_unknown_section(capsys):
    assert cli.main(["validate", "--only", "nope", "--workers", "1"]) == 2
    assert "valid: accuracy" in capsys.readouterr().err


@pytest.mark.slow
def test_quick_report(tmp_path):
    """The quick report, end to end, on the machine's cores."""
    assert cli.main(["validate", "--quick", "--out", str(tmp_path), "--no-progress"]) == 0
    text = (tmp_path / "report.md").read_text()
    assert not re.search(r"\bnan\b", text, re.IGNORECASE)
    for name in cases.integrator_names():
        assert f"| {name} |" in text or f"`{name}`" in text, name
    for image in re.findall(r"\]\(([^)]+\.png)\)", text):
        assert (tmp_path / image).stat().st_size > 10_000, image
    for title in ("Accuracy against REBOUND", "Dissipative forces", "Work against precision",
                  "Long-horizon drift", "Stress suite", "The integrator-choice guide, checked"):
        assert f"## {title}" in text

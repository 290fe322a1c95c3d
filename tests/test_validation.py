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


def test_rebound_best_fixed_step_methods_beside_its_defaults():
    # "cheapest at each accuracy" is against REBOUND's best: every fixed-step
    # method of REBOUND's is swept over the same steps as its WHFast
    rebound_tasks = [t.kwargs for t in work_precision.tasks(True) if t.kwargs.get("rebound")]
    for key in work_precision.SWEEP:
        steps = {name: sorted(t["dt"] for t in rebound_tasks
                              if t["problem"] == key and t["integrator"] == name)
                 for name in work_precision.REBOUND_FIXED_STEP}
        assert all(steps[name] == steps["whfast"] and steps[name]
                   for name in work_precision.REBOUND_FIXED_STEP), (key, steps)
        assert any(t["problem"] == key and t["integrator"] == "ias15" for t in rebound_tasks)
        # WHFast512 is swept exactly where it runs
        assert (any(t["problem"] == key and t["integrator"] == "whfast512"
                    for t in rebound_tasks) == work_precision.whfast512_status()[0])


def test_whfast512_tried_and_its_refusal_given():
    rebound = pytest.importorskip("rebound")
    ok, why = work_precision.whfast512_status()
    if not ok:
        assert "Error" in why          # REBOUND's exception, by name and message
        if not rebound.avx512_available:
            assert "no AVX-512" in why
        assert why.rstrip(".") in work_precision._whfast512_sentence()


@pytest.mark.parametrize("method", ["whfast, corrector 11", "whckl", "SABA(10,6,4)"])
def test_rebound_force_evaluations_are_counted_over_the_whole_run(method):
    # the row's count (extrapolated from 32- and 64-step tallies) must equal a
    # tally of the same whole run with its outputs; one a step would be wrong
    # for all three (WHCKL's kernel and SABA's stages, the correctors at outputs)
    from orbits.validation._measure import _set_options
    key = "outer-solar-system"
    dt = 8 * cases.problem(key).dt
    row = work_precision.measure(key, method, True, dt=dt, rebound=True)
    assert row["outcome"] == "completed" and row["series"] == f"REBOUND {method}"
    integrator, options = work_precision.rebound_method(method)
    options.setdefault("safe_mode", 0)
    sim = cases.bodies(cases.problem(key)).to_rebound()
    sim.gravity = "basic"
    sim.integrator = integrator
    _set_options(sim, integrator, options)
    sim.dt = dt
    count = [0]

    def tally(_sim):
        count[0] += 1

    sim.additional_forces = tally
    sim.force_is_velocity_dependent = 0
    until = work_precision.SWEEP[key][1]
    for t in on_steps(np.linspace(0.0, until, work_precision.OUTPUTS)[1:], dt):
        sim.integrate(t - 0.5 * dt, exact_finish_time=0)
    assert sim.steps_done == row["steps"]
    assert row["force_evaluations"] == count[0] > row["steps"]


def test_unit_g_runs_as_run_rebound_does():
    # WHFast512's runner scales time so that G = 1; with WHFast in it, the
    # run must be run_rebound's up to rounding: 3652 steps of 10 days leave
    # ~1e-12 au between them (measured 1.6e-12), while a wrong scale or step
    # count would show as > 1e-6 au
    bodies = orbits.scenes.outer_solar_system()
    ours = work_precision._run_unit_g(bodies, "whfast", {"safe_mode": 0}, dt=10.0,
                                      until=36525.0, outputs=11)
    theirs = run_rebound(bodies, "whfast", dt=10.0, until=36525.0, outputs=11)
    assert ours["outcome"] == "completed" and ours["steps"] == theirs["steps"] == 3652
    assert np.abs(ours["x"] - theirs["x"]).max() < 1e-10
    assert math.isclose(ours["t_end"], theirs["t_end"], rel_tol=1e-12)
    # relative energy errors do not depend on the time unit (measured: equal to 4e-7)
    assert math.isclose(ours["energy_error_max"], theirs["energy_error_max"], rel_tol=1e-4)


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
    assert cli.main(["validate", "--only", "nope", "--workers", "1"]) == 3
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

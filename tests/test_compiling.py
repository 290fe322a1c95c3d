"""Compile time: measured apart from stepping, announced once, and paid ahead
(``orbits._compiling``, ``orbits compile``)."""

import io
import json
import os
import pathlib
import platform
import subprocess
import sys
import threading

import astropy.units as u
import numba
import pytest

import orbits
from orbits import _compiling, cli
from orbits._compiling import CompileClock, loop_label, notice
from orbits.cli import main

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: a fresh process that runs ``euler`` on the Kepler problem twice, with the
#: default progress (no terminal: no bar), and prints each run's compile
#: seconds and the first run's summary.  Euler's loop is the cheapest to
#: compile (about 4 s on an empty cache on the reference machine).  Its six
#: outputs are recorded in the loop, so the first run also compiles their
#: monitors (:data:`orbits._compiling.OUTPUT_MONITORS`, about 1.3 s).
RUN_TWICE = """
import json
import astropy.units as u
import orbits
results = []
for _ in range(2):
    sim = orbits.Simulation(orbits.scenes.kepler(), "euler", dt=1 * u.day)
    results.append(sim.run(until=5 * u.day, outputs=6))
print(json.dumps([r.compile_time for r in results]))
print(results[0].summary())
"""


def _python(args, cache, settings=None):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(ROOT), **(settings or {}))
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=600)


def _notices(stderr):
    return [line for line in stderr.splitlines() if line.startswith("orbits: compiling")]


def test_a_first_compile_is_announced_once_and_measured(tmp_path):
    proc = _python(["-c", RUN_TWICE], tmp_path / "cache")
    assert proc.returncode == 0, proc.stderr
    first, second = json.loads(proc.stdout.splitlines()[0])
    # one line, on a stderr that is not a terminal, for each part the first
    # run compiled: its outputs' monitors, then its loop; the second run of
    # the process compiles nothing
    assert _notices(proc.stderr) == [notice(_compiling.OUTPUT_MONITORS),
                                     notice("euler")], proc.stderr
    assert notice(_compiling.OUTPUT_MONITORS).startswith(
        "orbits: compiling the monitors of the outputs for this CPU, once (about 1.3 s")
    assert first > 0 and second == 0
    assert "compiling" in proc.stdout and "stepping" in proc.stdout


def test_orbits_compile_fills_the_cache_that_the_next_process_loads(tmp_path):
    # two loops (euler's is the Runge-Kutta loop, leapfrog's the splitting
    # one), the second compiled in a process of its own (--jobs 2); gravity
    # alone (--plain; the loops for terms, variations and stopping
    # conditions are the next test's)
    cache = tmp_path / "cache"
    proc = _python(["-m", "orbits.cli", "compile", "euler", "leapfrog", "--jobs", "2",
                    "--plain"], cache)
    assert proc.returncode == cli.EXIT_COMPLETED, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("euler") and "s compiling" in lines[0]
    assert lines[1].startswith("leapfrog") and "s compiling" in lines[1]
    assert lines[-1].startswith("2 loops ready") and str(cache) in lines[-1]
    assert _notices(proc.stderr) == []          # orbits compile says it in its own lines
    # the second loop was compiled in the other process: here it loads
    proc = _python(["-c", RUN_TWICE.replace('"euler"', '"leapfrog"')], cache)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.splitlines()[0]) == [0, 0]
    # a new process, another scene and output spacing: loaded, so nothing said
    proc = _python(["-c", RUN_TWICE], cache)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.splitlines()[0]) == [0, 0]
    assert _notices(proc.stderr) == []
    assert "compiling" not in proc.stdout




def _has_x86_64_v3():
    # AVX2 and FMA, the level's vector instructions, on an x86-64 host
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return False
    from numba.core.codegen import get_host_cpu_features
    features = get_host_cpu_features()
    return "+avx2" in features and "+fma" in features


@pytest.mark.skipif(not _has_x86_64_v3(), reason="needs an x86-64 processor with AVX2 and FMA")
def test_a_cache_compiled_for_an_instruction_set_level_loads_in_a_new_process(tmp_path):
    # the installation page's cache for machines with different CPUs: compiled
    # ahead for x86-64-v3 with the level's own features (numba's
    # NUMBA_CPU_NAME and NUMBA_CPU_FEATURES), so that numba keys it by the
    # level and not by this processor; a new process with the same settings
    # loads it
    level = {"NUMBA_CPU_NAME": "x86-64-v3", "NUMBA_CPU_FEATURES": ""}
    cache = tmp_path / "cache"
    proc = _python(["-m", "orbits.cli", "compile", "euler", "--plain"], cache, level)
    assert proc.returncode == cli.EXIT_COMPLETED, proc.stderr
    assert " for x86-64-v3; " in proc.stdout.splitlines()[-1], proc.stdout
    proc = _python(["-c", RUN_TWICE], cache, level)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.splitlines()[0]) == [0, 0]


#: a fresh process that runs ``euler`` on the outer solar system with each
#: addition to gravity that orbits compile compiles ahead, and prints the
#: seconds each run spent compiling
RUN_ADDED = """
import json
import astropy.units as u
import orbits
from orbits import forces as F
b = orbits.scenes.outer_solar_system()
sized = orbits.BodySet.from_arrays(b.masses, b.positions, b.velocities, names=b.names,
                                   units=b.units, radii=[1e-3] * len(b) * u.au)
runs = {
    "GRPotential + J2": dict(forces=[F.GRPotential("Sun"),
                                     F.ZonalHarmonics("Sun", 0.00465 * u.au, J2=2e-7)]),
    "GR + tides": dict(forces=[F.GR("Sun"), F.TidesConstantTimeLag(
        "Jupiter", k2=0.5, time_lag=0.01 * u.day, radius=7e4 * u.km)]),
    "megno": dict(monitors=("energy", "megno")),
    "variations": dict(variations="all"),
    "GR + megno": dict(forces=[F.GR("Sun")], monitors=("energy", "megno")),
    "GRPotential + variations + escape": dict(forces=[F.GRPotential("Sun")],
                                              variations="state",
                                              escape_distance=1000 * u.au),
    "GR + collisions": dict(forces=[F.GR("Sun")], collisions="bounce"),
    "escape, encounters": dict(escape_distance=1000 * u.au, encounter_distance=0.01 * u.au),
    "collisions": dict(collisions="bounce"),
    "encounter log": dict(encounter_log=0.1 * u.au),
}
out = {}
for name, kw in runs.items():
    bodies = sized if "collisions" in kw else b
    sim = orbits.Simulation(bodies, "euler", dt=30 * u.day, **kw)
    out[name] = sim.run(until=300 * u.day, outputs=3, progress=False).compile_time
print(json.dumps(out))
"""


def test_orbits_compile_compiles_what_runs_add_to_gravity():
    # goal 2 of "Start in seconds": an integrator compiled ahead takes any
    # built-in terms, chaos monitors, variations, stopping conditions,
    # collisions or encounter log, and any combination of them, without
    # compiling again.  In the suite's own cache (what other tests compiled
    # loads), and a new process on it
    labels = [label for label, _ in orbits.compile_ahead(["euler"], progress=False)]
    assert labels == ["euler", "euler with force terms", "euler with variations",
                      "euler with force terms and variations",
                      "euler with stopping conditions"]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-c", RUN_ADDED], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.splitlines()[-1]) == {
        name: 0 for name in ("GRPotential + J2", "GR + tides", "megno", "variations",
                             "GR + megno", "GRPotential + variations + escape",
                             "GR + collisions", "escape, encounters", "collisions",
                             "encounter log")}
    assert _notices(proc.stderr) == []


#: a fresh process that runs implicit Euler with MEGNO on the suite's cache
#: and prints the run's compile seconds
RUN_IMPLICIT_MEGNO = """
import json
import astropy.units as u
import orbits
sim = orbits.Simulation(orbits.scenes.outer_solar_system(), "implicit-euler", dt=10 * u.day,
                        monitors=("energy", "megno"))
print(json.dumps(sim.run(until=50 * u.day, outputs=3, progress=False).compile_time))
"""


def test_an_implicit_loop_with_variations_is_loaded_in_a_new_process():
    # its Jacobian is the package's own (the force with variations'), named
    # the same in every process, so the loop is cached; named by its identity
    # it was compiled again (10-14 s) in every process
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    seconds = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", RUN_IMPLICIT_MEGNO], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        seconds.append(json.loads(proc.stdout.splitlines()[-1]))
    assert seconds[1] == 0, seconds


def test_the_loops_compiled_ahead_follow_what_the_integrator_takes():
    from orbits._ahead import _variants

    def adds(name, plain=False):
        return [loop.adds for loop in _variants(name, plain)]

    # Taylor's series take neither terms nor variations; wh takes the terms
    # that depend on positions alone, checks escapes, and its lanes' loops
    # are taken by runs of gravity alone
    assert adds("taylor") == ["", "checks"]
    wh = [(loop.options.get("coordinates"), loop.lanes, loop.adds) for loop in _variants("wh")]
    assert wh == [("jacobi", False, ""), ("jacobi", True, ""),
                  ("democratic-heliocentric", False, ""),
                  ("democratic-heliocentric", True, ""),
                  ("jacobi", False, "terms"), ("democratic-heliocentric", False, "terms"),
                  ("jacobi", False, "variations"),
                  ("democratic-heliocentric", False, "variations"),
                  ("jacobi", False, "terms+variations"),
                  ("democratic-heliocentric", False, "terms+variations"),
                  ("jacobi", False, "checks")]
    assert adds("ias15") == ["", "terms", "variations", "terms+variations", "checks"]
    assert adds("ias15", plain=True) == [""]
    # in processes, the first run with each addition goes first (it compiles
    # what all of them share), then gravity alone, then the other additions
    from orbits._ahead import _pool_order
    loops = _variants("leapfrog") + _variants("ias15")
    assert [(loops[i].name, loops[i].adds) for i in _pool_order(loops)] == [
        ("leapfrog", "terms"), ("leapfrog", "variations"), ("leapfrog", "terms+variations"),
        ("leapfrog", "checks"), ("ias15", ""), ("ias15", "terms"), ("ias15", "variations"),
        ("ias15", "terms+variations"), ("ias15", "checks")]


def test_processes_do_not_compile_one_loop_twice_at_once():
    # saba2 runs wh's loops, verlet leapfrog's: a process starts neither
    # beside the other's run of the same coordinates, lanes and addition;
    # and a run with an addition waits for the first such run (which
    # compiles the terms' table, the stopping conditions' check) to end
    from orbits._ahead import _startable, _variants

    loops = _variants("wh") + _variants("saba2") + _variants("verlet")
    index = {(lp.name, lp.options.get("coordinates"), lp.lanes, lp.adds): i
             for i, lp in enumerate(loops)}
    wh = index["wh", "jacobi", False, ""]
    saba2 = index["saba2", "jacobi", False, ""]
    saba2_dh = index["saba2", "democratic-heliocentric", False, ""]
    assert not _startable(saba2, loops, [wh], [saba2, saba2_dh])
    assert _startable(saba2_dh, loops, [wh], [saba2, saba2_dh])
    assert _startable(saba2, loops, [], [saba2])
    first, later = index["wh", "jacobi", False, "terms"], index["verlet", None, False, "terms"]
    assert not _startable(later, loops, [first], [later])
    assert not _startable(later, loops, [], [first, later])
    assert _startable(first, loops, [], [first, later])
    assert _startable(later, loops, [], [later])
    # with terms and without, with variations and with both, wh runs one loop
    # (terms as data): not beside each other either
    assert not _startable(first, loops, [wh], [first])
    both = index["wh", "jacobi", False, "terms+variations"]
    varied = index["wh", "jacobi", False, "variations"]
    assert not _startable(both, loops, [varied], [both])
    assert _startable(both, loops, [wh], [both])


def test_compiling_in_processes_from_an_unguarded_script_is_a_named_error(tmp_path):
    # each new process would import the script again and run its top level:
    # refused before anything compiles, naming the line and the guard
    script = tmp_path / "ahead.py"
    script.write_text("import orbits\n"
                      "orbits.compile_ahead(['euler', 'leapfrog'], progress=False, jobs=2)\n")
    proc = _python([str(script)], tmp_path / "cache")
    assert proc.returncode != 0
    assert "RuntimeError" in proc.stderr and "line 2 of" in proc.stderr, proc.stderr
    assert '__name__ == "__main__"' in proc.stderr
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").rglob("*.nbi"))

# -- the clock, in this process, on functions of its own ------------------------------------

def _fresh():
    """A function of two levels that no process has compiled yet."""
    inner = numba.njit(lambda a: a * 2.0)
    return numba.njit(lambda a: inner(a) + 1.0)


def test_the_clock_counts_nested_compiles_once_and_loads_not_at_all():
    outer = _fresh()
    with CompileClock() as clock:
        outer(1.0)
    assert clock.compiled == 1 and clock.seconds > 0
    with CompileClock() as again:
        outer(2.0)                          # compiled already: nothing to do
    assert again.compiled == 0 and again.seconds == 0


def test_the_notice_is_said_in_a_loop_window_only_and_once():
    out = io.StringIO()
    with CompileClock("wh", stream=out) as clock:
        _fresh()(1.0)                       # a kernel outside the loop's call
        assert out.getvalue() == ""
        with clock.loop():
            _fresh()(1.0)
            _fresh()(1.0)                   # the same call: one line for all it compiles
        with clock.loop():
            pass                            # nothing compiled: nothing said
    assert out.getvalue() == notice("wh") + "\n"
    assert clock.compiled == 3


def test_a_part_of_the_run_is_announced_by_its_own_name():
    out = io.StringIO()
    check = _compiling.CHECKS["all"]
    with CompileClock("leapfrog", stream=out) as clock:
        with clock.part(check):
            _fresh()(1.0)
        with clock.loop():
            _fresh()(1.0)
    assert out.getvalue() == notice(check) + "\n" + notice("leapfrog") + "\n"
    assert notice(check).startswith("orbits: compiling the check of the stopping "
                                    "conditions for this CPU, once (about 22 s")


@pytest.mark.parametrize("name, kw, kinds", [
    ("leapfrog", dict(escape_distance=100 * u.au), ["escapes"]),
    ("trace", dict(escape_distance=100 * u.au), ["escapes", "ahead"]),
    ("leapfrog", {}, []),
])
def test_the_stopping_conditions_check_is_compiled_and_announced_before_the_loop(
        monkeypatch, capsys, name, kw, kinds):
    # the check (and trace's look-ahead) compiled inside a window of its own,
    # before the loop: a first compile is announced as the check's, not as
    # the loop's (a collision run's check takes 20-25 s, its loop a few).
    # Each is made to compile something new here, as on an empty cache.
    from orbits._kernels import stopping
    real_check, real_ahead = stopping.check_pointer, stopping.ahead_pointer

    def check_pointer(conditions=True):
        _fresh()(1.0)
        return real_check(conditions)

    def ahead_pointer(conditions=True):
        _fresh()(1.0)
        return real_ahead(conditions)

    monkeypatch.setattr(stopping, "check_pointer", check_pointer)
    monkeypatch.setattr(stopping, "ahead_pointer", ahead_pointer)
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), name, dt=30 * u.day, **kw)
    result = sim.run(until=300 * u.day, outputs=2)
    said = _notices(capsys.readouterr().err)
    expected = [notice(_compiling.CHECKS[k]) for k in kinds]
    assert said[:len(kinds)] == expected            # first, before any loop's line
    assert [line for line in said if line in map(notice, _compiling.CHECKS.values())] == expected
    if kinds:
        assert result.compile_time > 0              # and counted as compiling


def test_the_notice_is_silenced_with_the_progress_bar():
    out = io.StringIO()
    with CompileClock("wh", quiet=True, stream=out) as clock:
        with clock.loop():
            _fresh()(1.0)
    assert out.getvalue() == "" and clock.compiled == 1


def test_compiles_in_another_thread_are_not_counted():
    out = io.StringIO()
    with CompileClock("wh", stream=out) as clock:
        with clock.loop():
            worker = threading.Thread(target=_fresh(), args=(1.0,))
            worker.start()
            worker.join()
    assert clock.compiled == 0 and out.getvalue() == ""


def test_the_notice_names_the_loop_and_its_expected_time(monkeypatch):
    wh = orbits.integrators.get("wh", coordinates="democratic-heliocentric")
    assert loop_label(wh) == "wh democratic-heliocentric"
    monkeypatch.setitem(_compiling.FIRST_COMPILE_SECONDS, "wh democratic-heliocentric", 30.0)
    assert "the wh democratic-heliocentric loop" in notice(loop_label(wh))
    assert "about 30 s" in notice(loop_label(wh))
    assert "a few seconds" in notice("no-such-loop")
    # the loops of runs with terms or variations are named so, with their estimate
    label = loop_label(orbits.integrators.get("leapfrog"), adds="variations")
    assert notice(label) == ("orbits: compiling the leapfrog with variations loop for this "
                             f"CPU, once (about {_compiling.ADDED_ESTIMATE}; `orbits compile` "
                             "does it ahead)")
    # a loop expected to compile in under NOTICE_FROM is not announced
    monkeypatch.setitem(_compiling.FIRST_COMPILE_SECONDS, "quick", 0.5 * _compiling.NOTICE_FROM)
    assert notice("quick") is None


# -- the summary ----------------------------------------------------------------------------

def test_the_summary_parts_compiling_from_stepping():
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    result = sim.run(until=30 * u.day, outputs=2, progress=False)
    assert result.compile_time >= 0
    result.wall_time, result.compile_time, result.steps = 4.0, 3.0, 1000
    line = next(ln for ln in result.summary().splitlines() if ln.startswith("steps"))
    # steps per second over the stepping time alone: 1000 / (4 - 3)
    assert line.endswith("wall time 4 s (compiling 3 s, stepping 1 s, 1e+03 steps/s)")
    result.compile_time = 0.0
    line = next(ln for ln in result.summary().splitlines() if ln.startswith("steps"))
    assert line.endswith("wall time 4 s (250 steps/s)")


def test_a_result_read_from_a_file_has_no_compile_time(tmp_path):
    path = tmp_path / "run.h5"
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    assert sim.run(until=3 * u.day, outputs=2, progress=False, output=path) \
        .compile_time is not None
    loaded = orbits.load(path)
    assert loaded.compile_time is None
    assert "compiling" not in loaded.summary()


# -- the command -----------------------------------------------------------------------------

def test_orbits_compile_checks_its_arguments(capsys):
    with pytest.raises(SystemExit) as info:
        main(["compile", "leapfrog", "--all"])
    assert info.value.code == cli.EXIT_USAGE
    with pytest.raises(SystemExit) as info:
        main(["compile", "leapfrog", "--jobs", "-1"])
    assert info.value.code == cli.EXIT_USAGE
    assert "--jobs must be >= 0" in capsys.readouterr().err
    for jobs in (-1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="jobs must be a whole number"):
            orbits.compile_ahead(["leapfrog"], progress=False, jobs=jobs)
    capsys.readouterr()
    assert main(["compile", "no-such-method"]) == cli.EXIT_INPUT
    assert "valid names" in capsys.readouterr().err
    # scipy's methods run in Python: said, and nothing compiled
    assert main(["compile", "radau", "--no-progress"]) == cli.EXIT_COMPLETED
    out = capsys.readouterr().out
    assert "radau: run in Python, nothing to compile" in out
    assert out.splitlines()[-1].startswith("0 loops ready")
    assert _compiling.cache_dir() in out


def test_the_default_loops_are_those_the_help_names(capsys):
    assert cli.COMPILE_DEFAULT == _compiling.COMMON
    with pytest.raises(SystemExit):
        main(["compile", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "default: " + ", ".join(_compiling.COMMON) in help_text


def test_wh_compiles_its_scalar_and_its_lanes_loops_ahead():
    # runs take the lanes' loop by the lanes option ("auto": by the run's
    # length, or once compiled), so both are compiled ahead, the scalar first
    from orbits._ahead import _variants

    def loops(name):
        out = []
        for loop in _variants(name, plain=True):
            integ = orbits.integrators.get(loop.name, **loop.options)
            out.append((loop_label(integ, loop.lanes), integ.config.get("lanes")))
        return out

    got = loops("wh")
    assert got == [("wh", "off"), ("wh lanes", "on"),
                   ("wh democratic-heliocentric", "off"),
                   ("wh democratic-heliocentric lanes", "on")]
    assert all(f"{label}" in _compiling.FIRST_COMPILE_SECONDS for label, _ in got)
    assert loops("ias15") == [("ias15", None)]
    assert loops("trace") == [("trace", "off"), ("trace lanes", "on")]


def test_every_compiled_integrator_has_a_loop_label():
    labels = [loop_label(orbits.integrators.get(i.name))
              for i in orbits.integrators.available()]
    assert labels == [i.name for i in orbits.integrators.available()]
    assert [i.name for i in orbits.integrators.available()
            if not orbits.integrators.get(i.name).compiled] == ["radau", "lsoda"]

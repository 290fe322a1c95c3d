"""Interrupts, user forces of the wrong shape, runaway tolerances and loose input."""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import warnings

import astropy.units as u
import numba
import numpy as np
import pytest

import orbits
from orbits import _driver
from orbits.errors import (ForceTermError, IntegratorOptionError, OrbitsWarning,
                           RunInterrupted, StepSizeUnderflow, WallTimeExceeded)
from orbits.cli import main

from helpers import kepler_bodies


def outer(integrator="leapfrog", **kw):
    return orbits.Simulation(orbits.scenes.outer_solar_system(), integrator, dt=10 * u.d, **kw)


# -- SIGINT and SIGTERM -------------------------------------------------------------------

def test_ctrl_c_during_the_compiled_loop_leaves_a_consistent_simulation():
    # the signal arrives while the loop runs (about 1e8 steps were asked for, some
    # 30 s); Ctrl-C's handler raising as the loop returned used to give SystemError
    # with the positions a chunk ahead of the clock (66 au off after continuing)
    outer().run(until=1 * u.yr, outputs=2, progress=False)       # compiled beforehand
    sim = outer()
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            sim.run(until=3e6 * u.yr, outputs=2, progress=False)
    finally:
        timer.cancel()
    exc = info.value
    assert isinstance(exc, RunInterrupted) and exc.signal == signal.SIGINT
    assert 0 < sim.steps < 10 ** 8 and exc.step == sim.steps
    assert sim.time.to_value(u.d) == sim.steps * 10.0           # clock and step count agree
    assert exc.result.times[-1] == sim.time                     # the result ends there
    np.testing.assert_array_equal(exc.result.positions[-1].value, sim.bodies.positions.value)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back
    # continuing gives bit for bit what one uninterrupted run gives
    until = sim.time + 100 * u.d
    sim.run(until=until, outputs=2, progress=False)
    ref = outer()
    ref.run(until=until, outputs=2, progress=False)
    np.testing.assert_array_equal(sim.bodies.positions.value, ref.bodies.positions.value)


def _signal_at_chunk(sim, k, signum, chunk=64):
    """Send ``signum`` to this process as the run reaches its ``k``-th chunk
    boundary, the chunks held at ``chunk`` steps (many boundaries, so that the
    signal comes mid-run)."""
    calls = [0]
    original = sim._between_chunks
    sim._chunk = chunk

    def between(rec, wall0):
        calls[0] += 1
        sim._chunk = chunk
        if calls[0] == k:
            os.kill(os.getpid(), signum)
        return original(rec, wall0)

    sim._between_chunks = between


@pytest.mark.parametrize("integrator", ["leapfrog", "ias15"])
def test_ctrl_c_with_a_file_writes_a_checkpoint_that_resumes_bit_identically(tmp_path,
                                                                              integrator):
    until, outputs = 2000 * u.yr, 40
    path = tmp_path / "run.h5"
    sim = outer(integrator)
    _signal_at_chunk(sim, 5, signal.SIGINT)
    with pytest.raises(RunInterrupted, match="checkpoint"):
        sim.run(until=until, outputs=outputs, progress=False, output=path)
    restored = orbits.Simulation.from_file(path)
    assert restored.steps == sim.steps and not restored.resume_point.finished
    restored.resume(progress=False)
    ref_path = tmp_path / "ref.h5"
    outer(integrator).run(until=until, outputs=outputs, progress=False, output=ref_path)
    a, b = orbits.load(path), orbits.load(ref_path)
    np.testing.assert_array_equal(a.times.value, b.times.value)
    np.testing.assert_array_equal(a.positions.value, b.positions.value)


def test_a_callers_own_signal_handler_is_called_at_a_consistent_state():
    seen = []

    def handler(signum, frame):
        seen.append(signum)     # and returns: the run goes on

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        sim = outer()
        _signal_at_chunk(sim, 3, signal.SIGTERM)
        sim.run(until=20 * u.yr, outputs=2, progress=False)
        assert seen == [signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is handler
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_sigterm_stops_the_command_line_run_with_a_checkpoint(tmp_path):
    # a batch scheduler's SIGTERM: exit status 128 + 15, a message, and a file
    # whose checkpoint is a consistent state the run can be finished from
    path = tmp_path / "term.h5"
    proc = subprocess.Popen(
        [sys.executable, "-m", "orbits.cli", "run", "outer-solar-system", "-i", "leapfrog",
         "--dt", "10d", "--until", "1.2e7yr", "--out", str(path), "--no-progress"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120    # imports and a cold kernel cache: ~10 s
        while not path.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)
        time.sleep(1.0)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "stopped by SIGTERM" in err and "orbits resume" in err
    sim = orbits.Simulation.from_file(path)
    assert sim.steps > 0 and not sim.resume_point.finished
    assert sim.time.to_value(u.d) == sim.steps * 10.0


# -- how soon a run of expensive steps reacts --------------------------------------------

class _Clock:
    """The run driver's wall clock, advanced only by what the steps cost."""

    def __init__(self):
        self.now = 0.0

    def perf_counter(self):
        return self.now


def _expensive_steps(monkeypatch, sim, cost, at=None, signum=None):
    """Make every step of ``sim`` cost ``cost`` seconds of the clock that the run
    driver reads, and send ``signum`` to this process from the call of the
    compiled loop during which that clock passes ``at``.  The steps themselves
    are the real ones, of a loop compiled for other tests too."""
    clock = _Clock()
    monkeypatch.setattr(_driver, "_time", clock)
    integ = sim.integrator
    name = "advance_to" if integ.adaptive else "advance"
    real = getattr(integ, name)

    def timed(*args, **kw):
        out = real(*args, **kw)
        before = clock.now
        clock.now += cost * int(out[2] if integ.adaptive else out[1])
        if signum is not None and before < at <= clock.now:
            os.kill(os.getpid(), signum)
        return out

    setattr(integ, name, timed)
    return clock


# 40 ms a step: 2000 bodies on ias15, whose first chunk of 1024 steps took 39 s
# to react to Ctrl-C and passed a wall_limit of 5 s by 54 s
_STEP = 0.04


@pytest.mark.parametrize("integrator", ["leapfrog", "ias15"])
@pytest.mark.parametrize("at", [0.5 * _STEP, 3.0])
def test_ctrl_c_is_acted_on_within_a_chunk_of_expensive_steps(monkeypatch, integrator, at):
    sim = outer(integrator)
    clock = _expensive_steps(monkeypatch, sim, _STEP, at=at, signum=signal.SIGINT)
    with pytest.raises(RunInterrupted) as info:
        sim.run(until=1e4 * u.yr, outputs=5, progress=False)
    assert info.value.step == sim.steps
    # a chunk is sized from its predecessor's time a step to last at most
    # CHUNK_SECONDS; the first is one step (a signal during it stops there)
    assert at <= clock.now <= at + _driver.CHUNK_SECONDS
    if at < _STEP:
        assert sim.steps == _driver.FIRST_CHUNK == 1


@pytest.mark.parametrize("integrator", ["leapfrog", "ias15"])
def test_wall_limit_is_acted_on_within_a_chunk_of_expensive_steps(monkeypatch, integrator):
    limit = 5.0
    sim = outer(integrator)
    clock = _expensive_steps(monkeypatch, sim, _STEP)
    with pytest.raises(WallTimeExceeded) as info:
        sim.run(until=1e4 * u.yr, outputs=2, progress=False, wall_limit=limit)
    assert info.value.step == sim.steps
    assert limit < clock.now <= limit + _driver.CHUNK_SECONDS


@pytest.mark.parametrize("cost", [1e-7, 2e-5, 0.04, 0.3, 10.0])
def test_a_chunk_is_sized_from_the_time_a_step_took(cost):
    # after a first step of `cost` seconds, and then after chunks that ran
    # to their end at that cost, a chunk lasts at most CHUNK_SECONDS (or is
    # one step); by the third, at least half of it where a step is cheaper
    target = _driver.CHUNK_SECONDS
    chunk = _driver.FIRST_CHUNK
    for _ in range(3):
        chunk = _driver.next_chunk(chunk, chunk, cost * chunk)
        assert chunk == 1 or chunk * cost <= target
    assert chunk * cost >= target / 2 or cost > target / 2
    # a call that ended early (at an output) shortens the chunk only if it
    # took longer than CHUNK_SECONDS
    assert _driver.next_chunk(1000, 10, 10 * cost) == (
        1000 if 10 * cost <= target else max(1, int(target / cost)))


# -- user forces of the wrong shape -------------------------------------------------------

@numba.njit
def _short(x, v, t):
    return -x[:10].copy()


@numba.njit
def _long(x, v, t):
    return -np.concatenate((x, x))


@pytest.mark.parametrize("accel, returned", [
    (_short, r"shape \(10,\)"), (_long, r"shape \(24,\)"),
    (lambda x, v, t: None, "None"), (lambda x, v, t: -float(x[0]), "a scalar")])
def test_a_user_force_of_the_wrong_shape_is_a_named_error(accel, returned):
    # before: too few values read past the array (1e196 in the state), a scalar
    # moved only the first component, extra values were dropped, None gave IndexError
    with pytest.raises(ForceTermError, match=returned + r".*expected an array of shape "
                                                       r"\(12,\)"):
        orbits.integrate(accel, np.ones(12), np.zeros(12), dt=0.01, steps=10)


def test_a_user_force_whose_shape_changes_during_the_run_is_caught_in_the_loop():
    calls = [0]

    def accel(x, v, t):
        calls[0] += 1
        return -x if calls[0] < 5 else -x[:2]

    with pytest.raises(ForceTermError, match="during the run"):
        orbits.integrate(accel, np.ones(3), np.zeros(3), dt=0.01, steps=10)
    calls[0] = 0
    with pytest.raises(ForceTermError, match="during the run"):
        orbits.integrate(accel, np.ones(3), np.zeros(3), method="dopri5", until=1.0)


@numba.njit
def _shrinking(x, v, t, m):
    if t > 100.0:
        return np.zeros((2, 3))
    return np.zeros_like(x)


@numba.njit
def _raising(x, v, t, m):
    if t > 100.0:
        raise ValueError("no force after 100 d")
    return np.zeros_like(x)


@numba.njit
def _nothing(x, v, t, m):
    return np.zeros_like(x)


@pytest.mark.parametrize("integrator", ["leapfrog", "dopri5"])
@pytest.mark.parametrize("func, said", [(_shrinking, "returned an array of another shape"),
                                        (_raising, "raised an exception")])
def test_a_user_force_term_that_fails_stops_at_the_last_good_state(integrator, func, said):
    # a function that raises inside the compiled loop once went on without
    # its term (numba printed "Exception ignored" at each call)
    sim = outer(integrator, forces=[orbits.forces.UserForce(func)])
    sim._chunk = 1024           # the step that fails (t > 100 d) falls in the first chunk
    with pytest.raises(ForceTermError, match=said + ".*last good state"):
        sim.run(until=1000 * u.d, outputs=2, progress=False)
    # the run stops before the first step that called the function after 100 d,
    # with a good state: leapfrog's that of the same steps taken with a function
    # that never fails, bit for bit; dopri5's (whose rejected trials shrank its
    # steps towards 100 d) that of such a run to the same time, to its
    # tolerance (rtol 1e-9 a step, some tens of steps)
    assert 0 < sim.steps and sim.time.value <= 100.0
    same = outer(integrator, forces=[orbits.forces.UserForce(_nothing)])
    same.run(until=sim.time, outputs=2, progress=False)
    if integrator == "leapfrog":
        assert same.steps == sim.steps
        np.testing.assert_array_equal(sim.bodies.positions.value,
                                      same.bodies.positions.value)
    else:
        np.testing.assert_allclose(sim.bodies.positions.value, same.bodies.positions.value,
                                   rtol=1e-7, atol=1e-9)


# -- tolerances and step-size collapse ------------------------------------------------------

@pytest.mark.parametrize("name", ["dopri5", "dop853", "rk4-doubling", "radau", "lsoda"])
def test_tolerances_must_be_numbers(name):
    with pytest.raises(IntegratorOptionError, match="rtol.*string"):
        orbits.integrators.get(name, rtol="1e-9")
    with pytest.raises(IntegratorOptionError, match="atol"):
        orbits.integrators.get(name, atol=True)


@pytest.mark.parametrize("name", ["dopri5", "dop853", "rk4-doubling"])
def test_a_tolerance_below_float64_is_raised_to_the_floor_with_a_warning(name):
    # rtol = atol = 1e-30 crept on with steps of 1e-12 d: 23 million steps to
    # t = 5e-5 d.  At the floor, 100 roundings, 1000 d of the outer solar system
    # takes ~2000 steps (measured 202 for dop853, 2256 for dopri5)
    with pytest.warns(OrbitsWarning, match="below what float64"):
        integ = orbits.integrators.get(name, rtol=1e-30, atol=1e-30)
    assert integ.config["rtol"] == orbits.integrators.base.RTOL_FLOOR
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integ)
    sim.run(until=1000 * u.d, outputs=2, progress=False, wall_limit=60)
    assert sim.steps < 20_000


def _head_on():
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1.0, position=[0.0, 0.0, 0.0], velocity=[0.0, 0.0, 0.0])
    b.add("b", mass=1e-3, position=[1.0, 0.0, 0.0], velocity=[0.0, 0.0, 0.0])
    return b


@pytest.mark.parametrize("name", ["dopri5", "dop853", "rk4-doubling", "ias15", "radau"])
def test_a_collapsing_step_raises_step_size_underflow(name):
    # a radial fall from rest meets the centre at t = pi / (2 sqrt(2 G M)) * r^1.5
    # = 1.1102 (free-fall time of two bodies, G (M + m) = 1.001)
    sim = orbits.Simulation(_head_on(), name)
    with pytest.raises(StepSizeUnderflow):
        sim.run(until=2.0, outputs=2, progress=False, wall_limit=60)
    assert sim.time.value < 1.1103


def test_lsoda_raises_step_size_underflow_instead_of_hanging():
    # before, scipy's LSODA crept towards the collision without end: run in a
    # child process so that a hang fails the test instead of stopping the suite
    code = textwrap.dedent("""
        import orbits
        b = orbits.BodySet(units=orbits.UnitSystem.nbody())
        b.add("a", mass=1.0, position=[0, 0, 0], velocity=[0, 0, 0])
        b.add("b", mass=1e-3, position=[1.0, 0, 0], velocity=[0, 0, 0])
        try:
            orbits.Simulation(b, "lsoda").run(until=2.0, outputs=2, progress=False)
        except orbits.StepSizeUnderflow:
            print("underflow")
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)  # ~3 s of imports; generous for a loaded machine
    assert out.stdout.strip() == "underflow", out.stderr


# -- loose input -------------------------------------------------------------------------

def test_loose_run_arguments_are_named_errors():
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=10 * u.d)
    with pytest.raises(ValueError, match="outputs must be a whole number"):
        sim.run(until=1 * u.yr, outputs=2.7, progress=False)
    with pytest.raises(ValueError, match="until must be a finite time"):
        sim.run(until=np.inf * u.yr, outputs=2, progress=False)
    with pytest.raises(ValueError, match="float64 can tell apart"):
        sim.run(until=1e30 * u.yr, outputs=2, progress=False)
    with pytest.raises(ValueError, match="monitors=\\['energy'\\]"):
        orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=10 * u.d, monitors="energy")
    assert sim.steps == 0


def test_the_default_outputs_fit_a_short_run_and_say_so():
    # 1 yr at 10 d is 36 steps and a partial one: 38 outputs at most
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=10 * u.d)
    with pytest.warns(OrbitsWarning, match="taking 38 outputs"):
        r = sim.run(until=1 * u.yr, progress=False)
    assert len(r.times) == 38
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.run(until=100 * u.yr, progress=False)              # long enough: no warning
    with pytest.raises(ValueError, match="needs more steps"):  # asked for explicitly
        sim.run(until=sim.time + 1 * u.yr, outputs=500, progress=False)


def test_an_adaptive_progress_bar_counts_outputs(capsys):
    sim = orbits.Simulation(kepler_bodies(), "ias15")
    sim.run(until=10.0, outputs=5, progress=True)
    err = capsys.readouterr().err
    assert "output" in err and "step" not in err


def test_command_line_time_options(capsys):
    # a negative step reaches the library's check instead of argparse's
    assert main(["run", "kepler", "--dt", "-10d", "--until", "1yr"]) == 3
    assert "dt must be a positive" in capsys.readouterr().err
    # plain numbers are read in the scene's units, as the help says
    assert main(["run", "kepler", "--dt", "10", "--until", "100", "--no-progress",
                 "-i", "leapfrog", "--outputs", "3"]) == 0
    assert "steps           10 " in capsys.readouterr().out
    # an adaptive integrator needs no --dt; a fixed-step one says it does
    assert main(["run", "kepler", "-i", "ias15", "--until", "1yr", "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["run", "kepler", "-i", "verlet", "--until", "1yr"]) == 3
    err = capsys.readouterr().err
    assert "--dt is needed" in err and "ias15" in err
    # beyond float64's range
    assert main(["run", "kepler", "--dt", "10d", "--until", "1e400yr"]) == 3
    assert "finite" in capsys.readouterr().err


def test_ctrl_c_in_integrate_stops_at_an_output_with_the_trajectory():
    calls = [0]

    def accel(x, v, t):
        calls[0] += 1
        if calls[0] == 25:
            os.kill(os.getpid(), signal.SIGINT)
        return -x

    with pytest.raises(RunInterrupted) as info:
        orbits.integrate(accel, np.ones(3), np.zeros(3), dt=0.01, steps=1000, every=10)
    tr = info.value.result
    # the signal came in step 24 (verlet: one force a step after the first);
    # the run stops at the next output, step 30
    assert tr.steps == info.value.step == 30 and tr.t[-1] == pytest.approx(0.3, rel=1e-14)
    assert len(tr.t) == 4 and tr.status == "stopped by SIGINT"

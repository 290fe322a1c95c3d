"""Outputs recorded inside the compiled loop (orbits._driver.Driven.execute).

A fixed-step run records its outputs inside the loop, whether they fall
every k steps or not (then each on the step nearest its time: the loop is
handed those steps); with ``monitor_every`` set, it takes each output between
two calls of the loop.  Both must give the same outputs, to the bit:
the same state at the same steps, times computed as the clock computes them,
and monitors from the same compiled functions.
"""

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits import forces


def _same(a, b):
    assert np.array_equal(a.times.value, b.times.value)
    assert np.array_equal(a.positions.value, b.positions.value)
    assert np.array_equal(a.velocities.value, b.velocities.value)
    for name in ("energy", "energy_error", "angular_momentum", "work", "megno", "fli"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert np.array_equal(np.asarray(getattr(x, "value", x)),
                                  np.asarray(getattr(y, "value", y))), name


FIXED = [("leapfrog", 10 * u.day), ("wh", 30 * u.day), ("rk4", 10 * u.day),
         ("saba2", 30 * u.day), ("implicit-midpoint", 10 * u.day), ("trace", 30 * u.day)]


def _counting_calls(sim):
    calls = []
    advance = sim.integrator.advance

    def counted(*args, **kwargs):
        calls.append(1)
        return advance(*args, **kwargs)
    sim.integrator.advance = counted
    return calls


@pytest.mark.parametrize("integrator, dt", FIXED)
@pytest.mark.parametrize("k", [7, 7.37])
def test_outputs_in_the_loop_equal_those_taken_between_calls(integrator, dt, k):
    # k = 7.37: outputs between steps, each on the step nearest its time,
    # 7 or 8 steps apart
    scene = orbits.scenes.outer_solar_system()
    until = 700 * k * dt    # 700 outputs every k steps, and the first
    make = lambda: orbits.Simulation(scene, integrator, dt=dt,  # noqa: E731
                                     monitors=["energy", "angular_momentum", "momentum"])
    sim = make()
    calls = _counting_calls(sim)
    inloop = sim.run(until=until, outputs=701, progress=False)
    # recorded in the loop: a few calls of it (chunks), not one an output
    assert 1 <= len(calls) < 20
    # the same outputs one call of the loop each: monitor_every switches the
    # recording in the loop off for outputs
    sim = make()
    sim.monitor_every = 10 ** 9
    calls = _counting_calls(sim)
    between = sim.run(until=until, outputs=701, progress=False)
    assert len(calls) >= 700
    assert len(inloop) == 701
    _same(inloop, between)
    steps = np.round(inloop.times.value / dt.to_value(inloop.times.unit))
    assert set(np.diff(steps)) == ({7} if k == 7 else {7, 8})


@pytest.mark.parametrize("options", [{"corrector": 11},
                                     {"coordinates": "democratic-heliocentric"}])
def test_wh_outputs_made_beside_the_next_drift_with_a_corrector_or_other_coordinates(
        options):
    # the lanes' loop (four bodies or more) makes an output's drift beside the
    # next step's first one, then the corrector and the transform: the outputs
    # must be those of the immediate synchronisation between calls
    from orbits.integrators import get
    make = lambda: orbits.Simulation(  # noqa: E731
        orbits.scenes.solar_system(moon=False), get("wh", lanes="on", **options),
        dt=1 * u.day, monitors=["energy", "angular_momentum"])
    inloop = make().run(until=3000 * u.day, outputs=377, progress=False)
    sim = make()
    sim.monitor_every = 10 ** 9
    between = sim.run(until=3000 * u.day, outputs=377, progress=False)
    _same(inloop, between)


def test_with_terms_work_and_chaos_monitors():
    b = orbits.BodySet()
    b.add("Star", 1 * u.Msun)
    b.add("Planet", 1 * u.Mjup, primary="Star", a=1 * u.au, e=0.1)
    b.add("Outer", 1 * u.Mjup, primary="Star", a=2.5 * u.au, e=0.05, f=2 * u.rad)

    def make():
        return orbits.Simulation(b, "leapfrog", dt=2 * u.day, seed=1,
                                 monitors=["energy", "megno", "fli"],
                                 forces=[forces.Migration("Planet", tau_a=1e4 * u.yr)])
    inloop = make().run(until=1000 * u.day, outputs=101, progress=False)
    sim = make()
    sim.monitor_every = 10 ** 9
    between = sim.run(until=1000 * u.day, outputs=101, progress=False)
    _same(inloop, between)
    assert inloop.work[-1].value != 0.0 and inloop.megno[-1] > 0


@pytest.mark.parametrize("integrator, dt", [("leapfrog", 10 * u.day), ("wh", 216.6 * u.day)])
def test_monitors_with_terms_that_carry_energy(integrator, dt):
    # an output recorded in the loop gets its monitors after the loop, from
    # the state in its row, the terms' energy (here GR's potential and the
    # Sun's J2) added to the bodies': the values of the monitors taken
    # between calls, to the bit, for every monitor computed from the state
    scene = orbits.scenes.outer_solar_system()

    def make():
        return orbits.Simulation(
            scene, integrator, dt=dt,
            monitors=["energy", "angular_momentum", "momentum", "center_of_mass"],
            forces=[forces.GRPotential("Sun"),
                    forces.ZonalHarmonics("Sun", 0.00465 * u.au, J2=2e-7)])
    until = 300 * 3 * dt
    inloop = make().run(until=until, outputs=301, progress=False)
    sim = make()
    sim.monitor_every = 10 ** 9
    between = sim.run(until=until, outputs=301, progress=False)
    _same(inloop, between)
    for name in ("momentum", "center_of_mass"):
        assert np.array_equal(getattr(inloop, name).value, getattr(between, name).value)


def test_uneven_outputs_and_a_shortened_last_step():
    # 10.55 steps an output: the outputs before the last on the steps nearest
    # their times (recorded in the loop), the last after a shortened step
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    r = sim.run(until=105.5 * u.day, outputs=11, progress=False)
    t = r.times.to_value(u.day)
    assert t[-1] == 105.5 and np.all(np.diff(t) > 0)
    assert np.array_equal(t[:-1], np.round(np.arange(10) * 105.5 / 10))


def test_a_failure_keeps_the_outputs_before_it():
    # two bodies of negligible mass flying at each other meet exactly at the
    # origin in the middle of the third step, where the force is 0/0 (as in
    # test_simulation): the outputs recorded in the loop before the failing
    # step are kept, and the run's last output is the last good state
    from orbits.errors import NonFiniteState
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("a", mass=1e-300, position=[5, 0, 0], velocity=[-2, 0, 0])
    b.add("b", mass=1e-300, position=[-5, 0, 0], velocity=[2, 0, 0])
    sim = orbits.Simulation(b, "leapfrog", dt=1.0)
    with pytest.raises(NonFiniteState) as info:
        sim.run(until=20.0, outputs=21, progress=False)
    r = info.value.result
    # the outputs at steps 0, 1, 2, then the final one at the last good step
    # (as between calls: the failure's output repeats an output at that step)
    assert np.array_equal(r.times.value, [0.0, 1.0, 2.0, 2.0])
    assert r.times.value[-1] == sim.time.value
    assert np.all(np.isfinite(r.positions.value))
    assert np.array_equal(r.positions.value[:, 0, 0], 5 - 2 * r.times.value)


def test_streamed_to_a_file_in_pieces(tmp_path, monkeypatch):
    # a file takes the outputs recorded in the loop in pieces of at most
    # max_rows (memory stays flat); made small here so that the run takes
    # many pieces, with checkpoints between them: the file holds what memory does
    from orbits.io import h5md
    monkeypatch.setattr(h5md.FileRecorder, "max_rows", 7)
    scene = orbits.scenes.outer_solar_system()

    def make():
        return orbits.Simulation(scene, "wh", dt=30 * u.day, monitors=["energy", "megno"],
                                 seed=2)
    mem = make().run(until=300 * 30 * u.day, outputs=101, progress=False)
    path = tmp_path / "run.h5"
    make().run(until=300 * 30 * u.day, outputs=101, output=path, progress=False,
               checkpoint_interval=0)
    back = orbits.load(path)
    _same(mem, back)


class _Crash(Exception):
    pass


@pytest.mark.parametrize("outputs", [41, 37])
def test_a_crash_while_streaming_resumes_to_the_same_file(tmp_path, monkeypatch, outputs):
    # outputs streamed in pieces of 5 with a checkpoint between pieces; the
    # process dies after writing the rows of the fourth piece, before its
    # checkpoint: resumed from the file, the run writes the same file, bit for
    # bit (41 outputs: every 10 steps; 37: 11 or 12 steps apart)
    from orbits.io import h5md
    monkeypatch.setattr(h5md.FileRecorder, "max_rows", 5)
    scene = orbits.scenes.outer_solar_system()

    def run(path):
        sim = orbits.Simulation(scene, "leapfrog", dt=10 * u.day)
        sim.run(until=400 * 10 * u.day, outputs=outputs, output=path, progress=False,
                checkpoint_interval=1e-9)
    whole, cut = tmp_path / "whole.h5", tmp_path / "cut.h5"
    run(whole)
    real = h5md.FileRecorder.output_rows
    calls = []

    def crashing(self, *args):
        real(self, *args)
        calls.append(1)
        if len(calls) == 4:
            raise _Crash()
    monkeypatch.setattr(h5md.FileRecorder, "output_rows", crashing)
    with pytest.raises(_Crash):
        run(cut)
    monkeypatch.setattr(h5md.FileRecorder, "output_rows", real)
    orbits.Simulation.from_file(cut).resume(progress=False)
    a, b = orbits.load(whole), orbits.load(cut)
    assert np.array_equal(a.times.value, b.times.value)
    assert np.array_equal(a.positions.value, b.positions.value)
    assert np.array_equal(a.energy_error, b.energy_error)
    assert b.status == "completed" and len(b) == outputs


# -- adaptive runs: ias15, the embedded methods and rk4-doubling land on the outputs in their loop

# dopri5 runs dop853's loop (its table without the third-order estimate)
ADAPTIVE = ["ias15", "dop853", "rk4-doubling"]

def _adaptive_pair(make, **run):
    # (outputs recorded in the loop, the same run taking each between calls)
    inloop = make().run(progress=False, **run)
    sim = make()
    sim.monitor_every = 10 ** 9       # switches the recording in the loop off
    between = sim.run(progress=False, **run)
    return inloop, between, sim


@pytest.mark.parametrize("integrator", ADAPTIVE)
def test_adaptive_outputs_in_the_loop_equal_those_taken_between_calls(integrator):
    # the loop lands on each output time as it lands on the end of a call:
    # same steps, same state, same monitors (with a force term and its work)
    scene = orbits.scenes.outer_solar_system()

    def make():
        return orbits.Simulation(scene, integrator, monitors=["energy", "angular_momentum"],
                                 forces=[forces.Migration("Saturn", tau_a=1e6 * u.yr)])
    a, b, sim = _adaptive_pair(make, until=2000 * u.yr, outputs=1001)
    assert len(a) == 1001 and a.steps == b.steps and a.work is not None
    assert sim.integrator.records_marks
    _same(a, b)


@pytest.mark.parametrize("integrator", ["ias15", "dop853", "taylor"])
def test_adaptive_outputs_in_the_loop_stop_where_the_run_stops(integrator):
    # a stopping condition between two outputs: the outputs before it, then
    # the state where it stopped, as between calls
    from orbits.errors import Collision
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=0.005 * u.au)
    b.add("Comet", mass=0 * u.kg, position=[1, 0, 0] * u.au,
          velocity=[-0.001, 0, 0] * u.au / u.day, radius=1 * u.km)

    def make():
        return orbits.Simulation(b, integrator, collisions="halt")
    results = []
    for off in (False, True):
        sim = make()
        if off:
            sim.monitor_every = 10 ** 9
        with pytest.raises(Collision) as info:
            sim.run(until=1 * u.yr, outputs=366, progress=False)
        results.append(info.value.result)
    assert 50 < len(results[0]) < 366
    _same(*results)


def test_ias15_outputs_streamed_to_a_file_in_pieces(tmp_path, monkeypatch):
    from orbits.io import h5md
    monkeypatch.setattr(h5md.FileRecorder, "max_rows", 7)
    scene = orbits.scenes.outer_solar_system()

    def make():
        return orbits.Simulation(scene, "ias15")
    mem = make().run(until=500 * u.yr, outputs=101, progress=False)
    path = tmp_path / "run.h5"
    make().run(until=500 * u.yr, outputs=101, output=path, progress=False)
    back = orbits.load(path)
    _same(mem, back)
    # the file's step counts are those of the outputs, as between calls
    path2 = tmp_path / "between.h5"
    make().run(until=500 * u.yr, outputs=101, output=path2, progress=False,
               checkpoint_interval=0)
    import h5py
    with h5py.File(path, "r") as f, h5py.File(path2, "r") as g:
        assert np.array_equal(f["particles/bodies/position/step"][()],
                              g["particles/bodies/position/step"][()])


def test_an_adaptive_runs_output_times_are_those_of_output_time_to_the_bit():
    # the loop's marks are made at once for every output a call may reach
    # (RunPlan.output_times); each must be the float output_time gives,
    # which the outputs taken between calls land on
    from orbits.records import RunPlan
    rng = np.random.default_rng(13)
    for _ in range(300):
        outputs = int(rng.integers(2, 10**5))
        start = float(rng.normal() * 10 ** rng.uniform(-3, 6))
        plan = RunPlan(start + float(10 ** rng.uniform(-3, 7)), outputs, 0.0, 0, False, 0, start)
        first = int(rng.integers(0, outputs))
        count = int(rng.integers(1, outputs - first + 2))
        expected = [plan.output_time(k) for k in range(first, first + count)]
        assert plan.output_times(first, count).tolist() == expected


@pytest.mark.parametrize("scene, dt", [("outer", 216.6 * u.day), ("sun8", 4.398 * u.day)])
@pytest.mark.parametrize("coordinates", ["jacobi", "democratic-heliocentric"])
@pytest.mark.parametrize("k", [1, 10.4])
def test_wh_lanes_outputs_at_the_step_people_use(scene, dt, coordinates, k):
    # a twentieth of the innermost period (Jupiter's, Mercury's): the lanes'
    # medium passes drift the outputs' copies beside the next step's drift,
    # their second iteration included; in the loop every step and every
    # 10.4 steps (each output on the step nearest its time), between calls,
    # and the scalar loop's, all the same to the bit
    from orbits.integrators import get
    bodies = (orbits.scenes.outer_solar_system() if scene == "outer"
              else orbits.scenes.solar_system(moon=False))
    until = 40 * k * dt

    def run(lanes, every=None):
        sim = orbits.Simulation(bodies, get("wh", lanes=lanes, coordinates=coordinates),
                                dt=dt, monitors=["energy", "angular_momentum"])
        if every:
            sim.monitor_every = every
        return sim.run(until=until, outputs=41, progress=False)

    inloop = run("on")
    _same(inloop, run("on", every=10 ** 9))
    _same(inloop, run("off"))
    steps = np.round(inloop.times.value / dt.to_value(inloop.times.unit))
    assert set(np.diff(steps)) == ({1} if k == 1 else {10, 11})

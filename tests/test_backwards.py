"""Runs backwards in time: ``run(until=t)`` with ``t`` before ``sim.time``.

Every integrator in the registry runs backwards (the fixed-step ones with the
signed step -dt, the adaptive ones choosing negative steps); a run forwards
and back recovers the start to the method's accuracy, and to round-off for
the time-symmetric ones.  Outputs, in-loop monitors, stopping conditions,
output files and restarts see the times decrease.
"""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.errors import CloseEncounter, Collision
from orbits.io.h5md import FileRecorder

from helpers import KEPLER_F0, kepler_bodies

ALL = [i.name for i in orbits.integrators.available()]
SYMMETRIC = [n for n in ALL if orbits.integrators.get(n).time_symmetric]

E = 0.5
#: a fixed step of 1/400 of the period (2 pi)
DT = 2 * math.pi / 400
#: 128 steps, about a third of the orbit: a run that went on forwards instead
#: of back would end about an au from the start, not on it; a whole number of
#: steps, so that the steps back are those forwards, retraced
SPAN = 128 * DT

#: what a time-symmetric method's round trip may miss its start by (G = M =
#: a = 1): its steps back retrace those forwards up to rounding, n eps |x| with
#: n = 128 steps each way (about 3e-14); measured at most 4.4e-15 (yoshida8,
#: saba4; leapfrog 6.7e-16) on a 2-core AMD EPYC, and allowed 1e-13
ROUND_TRIP_ROUNDING = 1e-13


def _mean_anomaly(f, e):
    E_ = 2.0 * math.atan(math.sqrt((1 - e) / (1 + e)) * math.tan(f / 2))
    return E_ - e * math.sin(E_)


def exact_state(t, f0=KEPLER_F0):
    """The test particle of :func:`kepler_bodies` (true anomaly ``f0`` at t = 0)
    at time ``t``, from Kepler's equation (mean motion 1)."""
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0)
    b.add("planet", mass=0.0, primary="star", a=1.0, e=E, M=_mean_anomaly(f0, E) + t)
    return b.positions.value[1], b.velocities.value[1]


def _error(sim, x, v):
    b = sim.bodies
    return max(np.abs(b.positions.value[1] - x).max(), np.abs(b.velocities.value[1] - v).max())


def _simulation(name, bodies=None, **kw):
    integ = orbits.integrators.get(name)
    step = {} if integ.adaptive else {"dt": DT}
    return orbits.Simulation(kepler_bodies(e=E) if bodies is None else bodies, name,
                             **step, **kw)


@pytest.mark.parametrize("name", ALL)
def test_forwards_and_back_recovers_the_start(name):
    sim = _simulation(name)
    x0, v0 = exact_state(0.0)
    sim.run(until=SPAN, outputs=5, progress=False)
    forwards = _error(sim, *exact_state(SPAN))
    back = sim.run(until=0.0, outputs=5, progress=False)
    assert sim.time_value == 0.0
    t = back.times.value
    assert t[0] == SPAN and t[-1] == 0.0 and np.all(np.diff(t) < 0)
    trip = _error(sim, x0, v0)
    integ = orbits.integrators.get(name)
    if name in SYMMETRIC:
        assert trip < ROUND_TRIP_ROUNDING, (name, trip)
    elif integ.adaptive:
        # a tolerance-controlled method's error over these steps is a few times
        # its tolerance either way, not tied to the error at SPAN (which may
        # be smaller by cancellation): measured trips of 3 rtol (dop853,
        # dopri5) to 43 rtol (lsoda), 1e-16 for ias15 and taylor; allowed
        # 100 times the tolerance
        assert trip <= 100 * _tolerance(integ) + 4 * forwards + 1e-13, (name, trip)
    else:
        # the way back makes an error of the size of the way there and carries
        # that one on: measured 0.03 to 4.4 times the forward error
        # (implicit-euler 4.4, euler 3.3, rk2 0.15); allowed 8 times, and
        # 1e-13 of rounding
        assert trip <= 8 * forwards + 1e-13, (name, trip, forwards)


def _tolerance(integ):
    c = integ.config
    return c.get("rtol", c.get("epsilon", c.get("tol")))


@pytest.mark.parametrize("name, options", [
    ("wh", {}), ("wh", {"corrector": 17}),
    ("wh", {"coordinates": "democratic-heliocentric"}), ("saba4", {}), ("trace", {}),
    ("leapfrog", {}),
])
def test_a_planetary_system_retraces_its_steps(name, options):
    # Jupiter and a Saturn close enough to make the kicks matter: the
    # symmetric maps retrace 2000 steps of 10 days to rounding (2000 steps of
    # n eps |x| with |x| ~ 10 au is about 4e-12; measured 4.8e-13 au (wh in
    # democratic heliocentric coordinates, trace) to 1.5e-12 au (saba4), wh
    # with corrector 17 6.5e-13 au); allowed 1e-11 au
    from helpers import jupiter_saturn
    b = jupiter_saturn(7.3)
    sim = orbits.Simulation(b, orbits.integrators.get(name, **options), dt=10 * u.day)
    sim.run(until=20_000 * u.day, outputs=3, progress=False)
    moved = np.abs(sim.bodies.positions - b.positions).max()
    sim.run(until=0 * u.day, outputs=3, progress=False)
    back = np.abs((sim.bodies.positions - b.positions).to_value(u.au)).max()
    assert moved > 1 * u.au          # it went somewhere
    assert back < 1e-11, back


def test_outputs_monitors_and_a_shortened_last_step_backwards():
    # outputs not a whole number of steps apart (recorded at marks in the
    # loop), a monitor series every 7 steps, and a last step shortened to
    # land on until: the times decrease, each where the clock says
    sim = _simulation("rk4", monitor_every=7)
    start = sim.bodies
    res = sim.run(until=-1.234, outputs=9, progress=False)
    t = res.times.value
    assert t[0] == 0.0 and t[-1] == -1.234 and np.all(np.diff(t) < 0)
    assert sim.time_value == -1.234
    # the outputs between are at step boundaries: whole steps of DT back
    k = -t[1:-1] / DT
    np.testing.assert_allclose(k, np.round(k), rtol=0, atol=1e-9)
    mt = res.monitor["times"].value
    assert np.all(np.diff(mt) < 0) and mt[0] == pytest.approx(-7 * DT, rel=1e-12)
    # against the same steps taken forwards from the mirrored start: with the
    # velocities reversed, the motion forwards is the motion backwards
    mirror = orbits.BodySet.from_arrays(start.masses.value, start.positions.value,
                                        -start.velocities.value, names=start.names,
                                        units=start.units)
    fwd = _simulation("rk4", bodies=mirror).run(until=1.234, outputs=9, progress=False)
    np.testing.assert_allclose(fwd.times.value, -t, rtol=0, atol=1e-14)
    # the same arithmetic up to the signs: equal to rounding
    np.testing.assert_allclose(fwd.positions.value, res.positions.value, rtol=0, atol=1e-14)


@pytest.mark.parametrize("name", ["leapfrog", "rk4", "ias15", "dop853", "taylor", "trace"])
def test_stopping_conditions_stop_a_run_backwards(name):
    # a test particle leaving the star after pericentre (q = 0.5, r = 0.95
    # now): backwards it comes in again, so the encounter and the collision
    # lie in the past
    bodies = kepler_bodies(e=E, f=2.0)
    r0 = np.linalg.norm(bodies.positions.value[1])
    sim = _simulation(name, bodies=bodies, encounter_distance=0.6)
    assert r0 > 0.6
    with pytest.raises(CloseEncounter) as info:
        sim.run(until=-3.0, outputs=4, progress=False)
    t = info.value.result.times.value
    assert -3.0 < info.value.time.value < 0 and np.all(np.diff(t) < 0)
    assert np.linalg.norm(np.diff(sim.bodies.positions.value, axis=0)) < 0.6 + 0.05
    # a star of radius 0.55: the particle touches it on the way in
    b = kepler_bodies(e=E, f=2.0)
    b2 = orbits.BodySet.from_arrays(b.masses.value, b.positions.value, b.velocities.value,
                                    names=b.names, units=b.units, radii=[0.55, 0.0])
    sim = _simulation(name, bodies=b2, collisions="halt")
    with pytest.raises(Collision) as info:
        sim.run(until=-3.0, outputs=4, progress=False)
    # closest inside the step that found the contact: a separation below 0.55
    # that the exact orbit has at the time reported (the closest approach in a
    # step of either sign, orbits._kernels.encounters.closest_approach)
    d = info.value.distance.value
    tc = info.value.contact_time.value
    assert d < 0.55 and info.value.time.value <= tc < 0
    x, _ = exact_state(tc, f0=2.0)
    assert np.linalg.norm(x) == pytest.approx(d, rel=1e-3)


def test_escape_is_found_backwards():
    # a hyperbolic flyby seen after pericentre: it came from afar, so a run
    # backwards finds it beyond the escape distance in the past (wh checks it)
    b = orbits.BodySet(units=orbits.UnitSystem.nbody())
    b.add("star", mass=1.0)
    b.add("probe", mass=0.0, primary="star", a=-1.0, e=1.5, f=0.5)
    sim = orbits.Simulation(b, "wh", dt=0.01, escape_distance=20.0)
    with pytest.raises(orbits.Escape) as info:
        sim.run(until=-100.0, outputs=3, progress=False)
    assert -100.0 < info.value.time.value < 0
    assert np.linalg.norm(sim.bodies.positions.value[1]) > 20.0


class Crash(Exception):
    pass


@pytest.mark.parametrize("name", ["leapfrog", "wh", "ias15", "dop853", "trace"])
def test_a_run_backwards_into_a_file_resumes_bit_for_bit(tmp_path, name, monkeypatch):
    # the file's times decrease, its checkpoints hold the clock counted down,
    # and a run killed after an output resumes to the same file
    whole, cut = tmp_path / "whole.h5", tmp_path / "cut.h5"
    _simulation(name).run(until=-SPAN, outputs=21, output=whole, progress=False,
                          checkpoint_interval=0)
    real = FileRecorder.output
    seen = []

    def crashing(self, sim, final=False):
        real(self, sim, final)
        seen.append(1)
        if len(seen) == 9:
            raise Crash()
    monkeypatch.setattr(FileRecorder, "output", crashing)
    with pytest.raises(Crash):
        _simulation(name).run(until=-SPAN, outputs=21, output=cut, progress=False,
                              checkpoint_interval=0)
    monkeypatch.setattr(FileRecorder, "output", real)
    sim = orbits.Simulation.from_file(cut)
    assert sim.time_value < 0
    sim.resume(progress=False)
    a, b = orbits.load(whole), orbits.load(cut)
    assert np.all(np.diff(a.times.value) < 0) and a.times.value[-1] == -SPAN
    np.testing.assert_array_equal(a.times.value, b.times.value)
    np.testing.assert_array_equal(a.positions.value, b.positions.value)
    assert b.status == "completed"
    again = orbits.Simulation.from_file(whole)
    assert again.time_value == -SPAN


def test_until_now_is_an_error():
    sim = _simulation("leapfrog")
    with pytest.raises(ValueError, match="is the current time"):
        sim.run(until=0.0)


@pytest.mark.parametrize("name", ["ias15", "rk4"])
def test_a_dissipative_force_runs_backwards(name):
    # migration takes energy out forwards and puts it back backwards: the
    # equations integrate either way (not reversible as physics, but as
    # mathematics), and the start and the work W (3.1e-5 out) come back to
    # the method's accuracy: measured 1.1e-16 and W = -7e-21 (ias15), 4.8e-11
    # and 2.9e-16 (rk4 at 1/400 of the period, whose error over the span is
    # about 4e-8); allowed 1e-7 and 1e-7 of W
    bodies = kepler_bodies(e=0.1, m_orbiter=1e-3)
    x0 = bodies.positions.value.copy()
    mig = orbits.forces.Migration("planet", tau_a=30.0)
    sim = _simulation(name, bodies=bodies, forces=[mig])
    sim.run(until=SPAN, outputs=2, progress=False)
    work = sim.work.value
    assert work > 1e-6          # energy went out
    sim.run(until=0.0, outputs=2, progress=False)
    assert np.abs(sim.bodies.positions.value - x0).max() < 1e-7
    assert abs(sim.work.value) < 1e-7 * work

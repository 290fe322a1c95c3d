"""Collisions that a run resolves and goes on: ``collisions="merge"``,
``"bounce"`` or a function (see :mod:`orbits.collisions`)."""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.collisions import bounce_pair, merge_pair
from orbits.errors import Collision, SimulationOptionError

MONITORS = ("energy", "angular_momentum", "momentum")


def _crossing(m1=2e-3, m2=1e-3, radius=0.01):
    # two planets on the same circle at 1 au, one prograde and one
    # retrograde, 0.1 rad apart: they meet head on after about 2.9 d
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=0.005 * u.au)
    vc = math.sqrt(orbits.UnitSystem().G)          # au/d on a circle of 1 au
    b.add("P1", mass=m1 * u.Msun, position=[1, 0, 0] * u.au,
          velocity=[0, vc, 0] * u.au / u.day, radius=radius * u.au)
    c, s = math.cos(0.1), math.sin(0.1)
    b.add("P2", mass=m2 * u.Msun, position=[c, s, 0] * u.au,
          velocity=[vc * s, -vc * c, 0] * u.au / u.day, radius=radius * u.au)
    b.move_to_com()
    return b


def _row_of(result, k):
    # the outputs' total momentum (the momentum monitor)
    return result.momentum[k].value


def test_a_merger_conserves_mass_and_momentum_and_keeps_the_energy_books():
    sim = orbits.Simulation(_crossing(), "ias15", collisions="merge", monitors=MONITORS)
    res = sim.run(until=10 * u.day, outputs=11, progress=False)
    (row,) = res.collisions
    assert (row["body_1"], row["body_2"], row["resolution"], row["survivor"]) == \
        ("P1", "P2", "merge", "P1")
    assert 2.0 * u.day < row["time"] <= row["step_time"] < 4.0 * u.day
    assert row["distance"] < 0.02 * u.au
    # the set after it: P2 gone, P1 with both masses and the summed volume
    after = sim.bodies
    assert after.names == ["Star", "P1"]
    assert after.masses[1].to_value(u.Msun) == pytest.approx(3e-3, rel=1e-15)
    assert after.radii[1].to_value(u.au) == pytest.approx(0.01 * 2 ** (1 / 3), rel=1e-15)
    # outputs keep the columns of the start: P2 is NaN once merged
    gone = res.times > row["step_time"]
    assert np.isnan(res.positions[gone, 2].value).all()
    assert np.isfinite(res.positions[~gone].value).all()
    assert np.isfinite(res.positions[:, :2].value).all()
    assert res.masses_at_outputs[-1, 1].to_value(u.Msun) == pytest.approx(3e-3, rel=1e-15)
    assert np.isnan(res.masses_at_outputs[-1, 2])
    # momentum: gravity and the merger conserve it to round-off; the scale is
    # the sum of |m v|, and 1e-14 of it allows ~100 roundings of its terms
    scale = np.sum(np.abs(res.masses.value[:, None] * res.velocities[0].value))
    assert np.abs(_row_of(res, -1) - _row_of(res, 0)).max() < 1e-14 * scale
    # the energy the merger took out is W; E + W stays E0 to ias15's error
    # (1e-15 a step over these ~100 steps) and the table's pair formula
    # agrees with the whole-system difference to round-off of E0
    assert res.energy_error.max() < 1e-13
    assert res.work[-1].value == pytest.approx(-row["energy_change"].value, rel=1e-9)
    # head on at 0.034 au/d, far above their mutual escape speed (0.005 au/d):
    # the merger takes out about mu u^2 / 2 - G m1 m2 / d
    mu = 2e-3 * 1e-3 / 3e-3
    G = orbits.UnitSystem().G
    expect = 0.5 * mu * row["speed"].value ** 2 - G * 2e-6 / row["distance"].value
    assert -row["energy_change"].value == pytest.approx(expect, rel=0.05)
    # the pair's angular momentum about each other became P1's spin
    assert res.angular_momentum_error.max() < 1e-13


def test_a_comet_falling_into_the_star_is_absorbed():
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun, radius=0.005 * u.au)
    b.add("Comet", mass=1e-9 * u.Msun, position=[1, 0, 0] * u.au,
          velocity=[-0.001, 0, 0] * u.au / u.day, radius=1 * u.km)
    sim = orbits.Simulation(b, "ias15", collisions="merge")
    res = sim.run(until=100 * u.day, outputs=3, progress=False)
    assert list(res.collisions["survivor"]) == ["Star"]
    assert sim.bodies.names == ["Star"]
    assert sim.bodies.masses[0].to_value(u.Msun) == pytest.approx(1 + 1e-9, rel=1e-15)
    assert res.energy_error.max() < 1e-12


def _line(restitution_masses=1e-12):
    # three small spheres on the x axis, far from anything, A and C moving
    # towards B at rest; their pull on each other is negligible (G m / r^2
    # ~ 3e-16 au/d^2 against speeds of 1 au/d)
    b = orbits.BodySet()
    for name, x, vx in (("A", 0.0, 1.0), ("B", 2.5, 0.0), ("C", 5.0, -1.0)):
        b.add(name, mass=restitution_masses * u.Msun, position=[x, 0, 0] * u.au,
              velocity=[vx, 0, 0] * u.au / u.day, radius=1.2 * u.au)
    return b


def test_two_collisions_in_one_step_and_a_chain_are_all_resolved():
    # in the first step of 1 d, A and B, and B and C, come within 2.4 au; the
    # merger of A and B (radius 1.2 * 2^(1/3) au) then overlaps C: one body
    sim = orbits.Simulation(_line(), "leapfrog", dt=1 * u.day, collisions="merge",
                            monitors=MONITORS)
    res = sim.run(until=3 * u.day, outputs=4, progress=False)
    assert len(res.collisions) == 2
    assert set(res.collisions["step_time"].to_value(u.day)) == {1.0}
    assert sim.bodies.names == ["A"]
    assert sim.bodies.masses[0].to_value(u.Msun) == pytest.approx(3e-12, rel=1e-15)
    # the momenta +m and -m cancel: the merger is at rest
    assert np.abs(sim.bodies.velocities.to_value(u.au / u.day)).max() < 1e-15
    assert np.isnan(res.positions[-1, 1:].value).all()


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_a_bounce_reverses_the_approach_scaled_by_the_restitution(e):
    b = orbits.BodySet()
    b.add("A", mass=1e-12 * u.Msun, position=[0, 0, 0] * u.au,
          velocity=[1, 0, 0] * u.au / u.day, radius=1 * u.au)
    b.add("B", mass=3e-12 * u.Msun, position=[2.5, 0.5, 0] * u.au,
          velocity=[-1, 0, 0] * u.au / u.day, radius=1 * u.au)
    kw = {} if e == 1.0 else {"restitution": e}
    sim = orbits.Simulation(b, "leapfrog", dt=0.01 * u.day, collisions="bounce",
                            monitors=MONITORS, **kw)
    x0 = b.positions.to_value(u.au)
    res = sim.run(until=3 * u.day, outputs=31, progress=False)
    (row,) = res.collisions
    assert row["resolution"] == "bounce" and row["survivor"] == ""
    # at the step's end the pair overlaps by under a step's approach (0.02 au);
    # the normal component of the relative velocity then flips and scales by e
    # (the bodies' pull changes speeds by under 1e-15 au/d here)
    v = sim.bodies.velocities.to_value(u.au / u.day)
    x = sim.bodies.positions.to_value(u.au)
    assert np.linalg.norm(x[1] - x[0]) > 2.0
    assert np.allclose(1e-12 * v[0] + 3e-12 * v[1], [-2e-12, 0, 0], rtol=0, atol=1e-24)
    # energy: the table's change is -(1 - e^2) mu un^2 / 2 and W books it
    assert res.work[-1].value == pytest.approx(-row["energy_change"].value, rel=1e-12,
                                               abs=1e-40)
    assert res.energy_error.max() < 1e-12
    if e == 1.0:
        assert abs(row["energy_change"].value) < 1e-27
    else:
        assert row["energy_change"].value < 0
    assert np.isfinite(res.positions.value).all()
    assert x0.shape == x.shape


def test_a_collision_function_chooses_per_pair_and_may_halt():
    seen = []

    def choose(event):
        seen.append(event)
        return "halt" if event.bodies == ("P1", "P2") else "merge"

    sim = orbits.Simulation(_crossing(), "ias15", collisions=choose)
    with pytest.raises(Collision) as info:
        sim.run(until=10 * u.day, outputs=3, progress=False)
    exc = info.value
    assert exc.bodies == ("P1", "P2")
    (event,) = seen
    assert event.bodies == ("P1", "P2")
    assert event.time <= event.step_time == exc.time
    assert event.masses.unit == u.Msun and event.positions.shape == (2, 3)
    assert sim.bodies.names == ["Star", "P1", "P2"]
    assert len(exc.result.collisions) == 0

    sim = orbits.Simulation(_crossing(), "ias15", collisions=lambda ev: "explode")
    with pytest.raises(SimulationOptionError, match="explode"):
        sim.run(until=10 * u.day, outputs=3, progress=False)


def test_bad_resolution_options_are_refused_by_name():
    with pytest.raises(SimulationOptionError, match="restitution"):
        orbits.Simulation(_crossing(), "ias15", collisions="merge", restitution=0.5)
    with pytest.raises(SimulationOptionError, match="restitution"):
        orbits.Simulation(_crossing(), "ias15", collisions="bounce", restitution=1.5)
    with pytest.raises(SimulationOptionError, match="variations"):
        orbits.Simulation(_crossing(), "ias15", collisions="merge", variations="state")
    # the chaos monitors integrate tangent vectors too, which neither a
    # merger nor a bounce carries (after a merger they were drawn again from
    # a new seed, so that two runs of one simulation differed)
    with pytest.raises(SimulationOptionError, match="megno"):
        orbits.Simulation(_crossing(), "ias15", collisions="bounce",
                          monitors=("energy", "megno"))


def test_the_pair_formulas_conserve_what_they_should():
    rng = np.random.default_rng(3)
    m = rng.uniform(0.1, 2.0, 2)
    r = rng.uniform(0.1, 1.0, 2)
    x = rng.normal(size=(2, 3))
    v = rng.normal(size=(2, 3))
    M, R, X, V = merge_pair(m, r, x, v, 0, 1)
    assert M == m.sum()
    assert R ** 3 == pytest.approx(r[0] ** 3 + r[1] ** 3, rel=1e-15)
    assert np.allclose(M * V, m @ v, rtol=1e-15, atol=1e-15)
    assert np.allclose(M * X, m @ x, rtol=1e-15, atol=1e-15)
    va, vb, _ = bounce_pair(m, x, v, 0, 1, 0.3)
    assert np.allclose(m[0] * va + m[1] * vb, m @ v, rtol=1e-15, atol=1e-15)
    n = (x[1] - x[0]) / np.linalg.norm(x[1] - x[0])
    un0, un1 = (v[1] - v[0]) @ n, (vb - va) @ n
    if un0 < 0:
        assert un1 == pytest.approx(-0.3 * un0, rel=1e-14)
    # the tangential part of the relative velocity is untouched
    t0 = (v[1] - v[0]) - un0 * n
    t1 = (vb - va) - un1 * n
    assert np.allclose(t0, t1, rtol=1e-14, atol=1e-15)


class _Crash(Exception):
    pass


def test_a_run_interrupted_after_a_merger_resumes_bit_for_bit(tmp_path, monkeypatch):
    # the file keeps the columns of the start (NaN for P2 once merged), the
    # masses at every output and the collisions; a run killed after the
    # merger resumes from its checkpoint (fewer bodies, ias15's state of
    # them) to the same file as the whole run
    from orbits.io.h5md import FileRecorder
    whole, cut = tmp_path / "whole.h5", tmp_path / "cut.h5"
    kw = dict(until=10 * u.day, outputs=11, progress=False, checkpoint_interval=0)

    def sim():
        return orbits.Simulation(_crossing(), "ias15", collisions="merge", monitors=MONITORS)
    r_whole = sim().run(output=whole, **kw)
    real = FileRecorder.output
    seen = []

    def crashing(self, s, final=False):
        real(self, s, final)
        seen.append(1)
        if len(seen) == 6:           # at 5 d, after the merger at 2.3 d
            raise _Crash()
    monkeypatch.setattr(FileRecorder, "output", crashing)
    with pytest.raises(_Crash):
        sim().run(output=cut, **kw)
    monkeypatch.setattr(FileRecorder, "output", real)
    again = orbits.Simulation.from_file(cut)
    assert again.bodies.names == ["Star", "P1"]
    again.resume(progress=False)
    a, b = orbits.load(whole), orbits.load(cut)
    for name in ("positions", "velocities", "masses_at_outputs", "energy", "work"):
        assert np.array_equal(getattr(a, name).value, getattr(b, name).value,
                              equal_nan=True), name
    assert np.isnan(a.positions[-1, 2].value).all()
    assert len(a.collisions) == len(b.collisions) == 1
    assert a.collisions["survivor"][0] == "P1"
    assert r_whole.masses_at_outputs[-1, 1] == a.masses_at_outputs[-1, 1]


def test_a_file_names_the_collisions_function_and_asks_for_it_back(tmp_path):
    path = tmp_path / "f.h5"

    def merge_all(event):
        return "merge"
    sim = orbits.Simulation(_crossing(), "ias15", collisions=merge_all)
    sim.run(until=5 * u.day, outputs=3, progress=False, output=path)
    with pytest.raises(SimulationOptionError, match="merge_all"):
        orbits.Simulation.from_file(path)
    again = orbits.Simulation.from_file(path, collisions=merge_all)
    assert again.bodies.names == ["Star", "P1"]
    again.run(until=6 * u.day, outputs=2, progress=False)


def test_the_barycentre_and_the_summary_follow_the_bodies_left():
    sim = orbits.Simulation(_crossing(), "ias15", collisions="merge", monitors=MONITORS,
                            encounter_log=0.05 * u.au)
    res = sim.run(until=10 * u.day, outputs=11, progress=False)
    bary = res.barycentric()
    m = np.nan_to_num(res.masses_at_outputs.value)
    com = np.einsum("kn,knd->kd", m, np.nan_to_num(bary.positions.value))
    # the bodies started in their centre-of-mass frame and the merger keeps
    # it: the barycentre of what is left is the origin to round-off of 1 au
    assert np.abs(com).max() < 1e-15
    assert np.isnan(bary.positions[-1, 2].value).all()
    lines = res.summary().splitlines()
    assert "collisions      1 (merge 1)" in lines
    # the pair merged while still closing: it had no closest approach to log
    # (the collisions table has it), and the log goes on with the bodies left
    assert len(res.encounters) == 0


def test_elements_follow_the_masses_and_end_where_a_body_merged_away():
    sim = orbits.Simulation(_crossing(), "ias15", collisions="merge")
    res = sim.run(until=10 * u.day, outputs=11, progress=False)
    gone = res.times > res.collisions["step_time"][0]
    el2 = res.elements("P2", primary="Star")
    assert np.isnan(el2["a"][gone].value).all() and np.isfinite(el2["a"][~gone].value).all()
    # the merger's elements use its mass at each output: at the last output
    # they equal those of the body set the run ended with (same state, same mu)
    el1 = res.elements("P1", primary="Star")
    end = sim.bodies.elements("P1", primary="Star")
    assert el1["a"][-1].value == pytest.approx(end["a"].value, rel=1e-14)
    assert el1["e"][-1].value == pytest.approx(float(end["e"]), rel=1e-12, abs=1e-15)


def _crossing_sim(m2):
    return orbits.Simulation(_crossing(m2=m2), "ias15", collisions="merge")


def test_ensemble_rows_count_the_collisions_and_the_bodies_left():
    df = orbits.Ensemble.grid(_crossing_sim, m2=[1e-3, 1e-6]).run(
        10 * u.day, client="serial", outputs=3, progress=False)
    assert df["collisions"].tolist() == [1, 1]
    assert df["bodies_left"].tolist() == [2, 2]
    # the merged-away body has no elements; the survivor has (m2 = 1e-6:
    # P1 keeps nearly its circular orbit at 1 au)
    assert "P2_a_au" not in df or df["P2_a_au"].isna().all()
    assert df["P1_a_au"][1] == pytest.approx(1.0, abs=0.01)
    assert (df["energy_error_max"] < 1e-13).all()

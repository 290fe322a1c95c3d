"""Epochs: a body set's date (astropy Time, TDB), carried by simulations,
results, system files and output files (:mod:`orbits.epochs`)."""

import h5py
import numpy as np
import pytest
from astropy.time import Time
import astropy.units as u

import orbits
from orbits import epochs, scenes, systemfile
from orbits.cli import main
from orbits.errors import EpochError, NoEpochError, SystemFileError
from orbits.io.h5md import OrbitsFileError

J2000 = Time(2451545.0, format="jd", scale="tdb")


def test_a_body_set_carries_an_epoch_in_tdb():
    b = scenes.kepler()
    assert b.epoch is None
    b.epoch = Time("2024-01-01T00:00:00", scale="utc")
    assert b.epoch.scale == "tdb"
    # 37 leap seconds and TT - TAI = 32.184 s; TDB - TT is below 1.7 ms
    assert (b.epoch - Time("2024-01-01T00:01:09.184", scale="tt")).to_value(u.s) == \
        pytest.approx(0.0, abs=2e-3)
    assert b.copy().epoch == b.epoch
    assert "epoch 2024-01-01T00:01:09.18" in repr(b)
    b.epoch = None
    assert b.epoch is None and "epoch" not in repr(b)


@pytest.mark.parametrize("value, text", [
    ("2000-01-01", "must be an astropy.time.Time, got str"),
    (2451545.0, "must be an astropy.time.Time, got float"),
    (Time([2451545.0, 2451546.0], format="jd", scale="tdb"), "a single date"),
])
def test_anything_but_one_time_is_an_epoch_error(value, text):
    b = scenes.kepler()
    with pytest.raises(EpochError, match=text):
        b.epoch = value
    assert b.epoch is None


def test_text_reads_back_bit_for_bit():
    for jd1, jd2 in [(2451545.0, 0.0), (2460371.0, -0.25), (2451545.0, 1.1e-17),
                     (2415021.0, 0.3333333333333333)]:
        e = epochs.from_pair(jd1, jd2)
        back = epochs.from_text(epochs.to_text(e))
        assert epochs.to_pair(back) == epochs.to_pair(e)
    assert epochs.to_pair(epochs.from_text("2000-01-01T12:00:00 TDB")) == (2451545.0, 0.0)
    assert epochs.to_pair(epochs.from_text("2000-01-01T12:00:00")) == (2451545.0, 0.0)
    tt = epochs.from_text("2000-01-01T12:00:00 TT")
    assert abs((tt - J2000).to_value(u.s)) < 2e-3 and tt != J2000
    for bad in ("yesterday", "2000-13-01 TDB", "nan", "2451545.0 + x"):
        with pytest.raises(EpochError, match="cannot read"):
            epochs.from_text(bad)


def test_de421_takes_an_epoch_and_the_set_carries_it():
    default = scenes.de421()
    assert epochs.to_pair(default.epoch) == (2451545.0, 0.0)
    x, v = scenes.de421_states(2451545.0)
    assert np.array_equal(default.positions, x)      # J2000 as before, bit for bit
    when = Time("2024-03-01T00:00:00", scale="utc")
    b = scenes.de421(epoch=when)
    assert b.epoch == epochs.as_epoch(when)
    x, v = scenes.de421_states(when)
    assert np.array_equal(b.positions, x) and np.array_equal(b.velocities, v)
    # the same date as one Julian date: rounded to a double, 18 us off here, in
    # which the Moon moves about 2e-12 au (measured 5.2e-12 au); allowed 1e-10 au
    jd = b.epoch.jd1 + b.epoch.jd2
    assert np.allclose(scenes.de421(epoch=jd).positions.value, b.positions.value,
                       rtol=0, atol=1e-10)
    with pytest.raises(ValueError, match="DE421 covers"):
        scenes.de421(epoch="1850-01-01")
    with pytest.raises(EpochError):
        scenes.de421(epoch=[2451545.0])


def test_solar_system_carries_its_epoch():
    b = scenes.solar_system(epoch="2010-06-01T00:00:00")
    assert b.epoch.isot == "2010-06-01T00:00:00.000" and b.epoch.scale == "tdb"


@pytest.mark.parametrize("kind", ["toml", "csv"])
def test_system_files_keep_the_epoch_bit_for_bit(kind, tmp_path):
    b = scenes.kepler()
    b.epoch = epochs.from_pair(2460371.0, -0.123456789012345)
    path = tmp_path / f"system.{kind}"
    b.write(path)
    back = orbits.BodySet.read(path)
    assert epochs.to_pair(back.epoch) == epochs.to_pair(b.epoch)
    assert np.array_equal(back.positions, b.positions)
    # a set without one writes none and reads none
    scenes.kepler().write(path)
    assert "epoch" not in path.read_text() and orbits.BodySet.read(path).epoch is None


def test_a_person_writes_an_epoch_as_a_date():
    text = ('epoch = "2024-03-01 UTC"\n[[body]]\nname = "Sun"\nmass = "1 Msun"\n'
            '[[body]]\nname = "Earth"\nmass = "1 Mearth"\na = "1 au"\n')
    b = systemfile.loads(text).bodies
    assert b.epoch == epochs.as_epoch(Time("2024-03-01", scale="utc"))
    csv = ("# epoch: 2451545.0 TDB\nname,mass [Msun],x [au],y [au],z [au],vx [au/d],"
           "vy [au/d],vz [au/d]\nSun,1,0,0,0,0,0,0\n")
    assert epochs.to_pair(systemfile.loads(csv, "csv").bodies.epoch) == (2451545.0, 0.0)


@pytest.mark.parametrize("text, line", [
    ('epoch = 2451545.0\n', 1),
    ('epoch = "the day after"\n', 1),
    ('\nepoch = "2000-02-30"\n', 2),
])
def test_a_bad_epoch_in_a_file_names_the_line(text, line):
    text += '[[body]]\nname = "Sun"\nmass = "1 Msun"\n'
    with pytest.raises(SystemFileError, match="field 'epoch'") as info:
        systemfile.loads(text)
    assert info.value.line == line
    with pytest.raises(SystemFileError, match="before the header"):
        systemfile.loads("name,mass [Msun]\n# epoch: 2451545.0\nSun,1\n", "csv")


def _dated_simulation(**kw):
    b = scenes.kepler()
    b.epoch = Time("2030-01-01T00:00:00", scale="tdb")
    return orbits.Simulation(b, "leapfrog", dt=1 * u.day, **kw)


def test_simulation_and_result_give_dates():
    sim = _dated_simulation()
    assert sim.epoch.isot == "2030-01-01T00:00:00.000"
    res = sim.run(until=1 * u.yr, outputs=5, progress=False)
    assert res.epoch == sim.epoch
    assert np.array_equal(res.epochs.jd, (sim.epoch + res.times).jd)
    assert res.epochs[-1].isot == "2031-01-01T06:00:00.000"      # 365.25 days on
    assert sim.bodies.epoch.isot == "2031-01-01T06:00:00.000"
    # a simulation made from its own bodies later starts there
    assert orbits.Simulation(sim.bodies, "leapfrog", dt=1 * u.day).epoch == res.epochs[-1]
    back = sim.run(until=-10 * u.day, outputs=3, progress=False)
    assert back.epochs[-1].isot == "2029-12-22T00:00:00.000"
    assert np.all(np.diff(back.epochs.jd) < 0)


def test_a_result_without_an_epoch_says_so():
    res = orbits.Simulation(scenes.kepler(), "leapfrog", dt=1 * u.day).run(
        until=3 * u.day, outputs=2, progress=False)
    assert res.epoch is None
    with pytest.raises(NoEpochError, match="no epoch"):
        res.epochs


def test_output_files_keep_the_epoch_through_restarts(tmp_path):
    path = tmp_path / "run.h5"
    sim = _dated_simulation()
    first = sim.run(until=20 * u.day, outputs=3, output=path, progress=False)
    assert first.epochs[-1].isot == "2030-01-21T00:00:00.000"
    with h5py.File(path, "r") as f:
        stored = f["parameters"].attrs["epoch_tdb"]
    assert stored.dtype == np.float64 and tuple(stored) == epochs.to_pair(sim.epoch)
    loaded = orbits.load(path)
    assert loaded.epoch == sim.epoch and loaded.epochs[-1] == first.epochs[-1]
    again = orbits.Simulation.from_file(path)
    assert again.epoch == sim.epoch and again.bodies.epoch.isot == "2030-01-21T00:00:00.000"
    again.run(until=30 * u.day, outputs=2, output=path, progress=False)
    assert orbits.load(path).epochs[-1].isot == "2030-01-31T00:00:00.000"
    assert "epoch           2030-01-01T00:00:00.000 TDB (JD 2462502.5)" in \
        orbits.io.describe(path)


def test_orbits_info_prints_the_epoch(tmp_path, capsys):
    path = tmp_path / "run.h5"
    _dated_simulation().run(until=2 * u.day, outputs=2, output=path, progress=False)
    main(["info", str(path)])
    assert "2030-01-01T00:00:00.000 TDB" in capsys.readouterr().out
    plain = tmp_path / "plain.h5"
    orbits.Simulation(scenes.kepler(), "leapfrog", dt=1 * u.day).run(
        until=2 * u.day, outputs=2, output=plain, progress=False)
    main(["info", str(plain)])
    assert "none (times only)" in capsys.readouterr().out
    assert orbits.load(plain).epoch is None


@pytest.mark.parametrize("value", [
    np.array([2462502.5]), np.array([2462502.5, np.nan]), np.array([1e300, 0.0]),
    np.array([2462502, 0]), np.array([2462502.5, 7.0]), "2030-01-01",
])
def test_a_damaged_epoch_attribute_is_a_file_error(tmp_path, value):
    path = tmp_path / "run.h5"
    _dated_simulation().run(until=2 * u.day, outputs=2, output=path, progress=False)
    with h5py.File(path, "r+") as f:
        f["parameters"].attrs["epoch_tdb"] = value
    for read in (orbits.load, orbits.io.describe, orbits.Simulation.from_file):
        with pytest.raises(OrbitsFileError, match="epoch_tdb"):
            read(path)

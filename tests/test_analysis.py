"""Result analysis: elements over time, frames, tables, on runs and on loaded files."""

import csv
import math
import sys

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.cli import main
from orbits.errors import BodyError, NoMassiveBodyError, UnknownBodyError

KEYS = ("a", "e", "inc", "Omega", "omega", "f", "M")
ANGLES = ("inc", "Omega", "omega", "f", "M")

# Result.elements and BodySet.elements run the same kernel on the same numbers;
# the one difference allowed is the order of the sum that makes the interior
# centre of mass (a matmul over a stack of outputs against one over a single
# output), an ulp of the primary's state, which the angles amplify by 1/e
# (e >= 3e-3 here): a few 1e-14 at most.  Measured: identical.
SAME_KERNEL_TOL = 1e-13

# The requirement for the agreement with REBOUND's Particle.orbit()
# (relative for a, e and P, absolute in rad for angles).  Measured: 1e-13 at
# most, from Neptune's e = 3e-3 in the equatorial frame (rounding / e).
REBOUND_TOL = 1e-12


def wrapped(d):
    """An angle difference reduced to [-pi, pi)."""
    return (np.asarray(d) + math.pi) % (2 * math.pi) - math.pi


def flyby_bodies():
    """The Sun, Jupiter, and an interstellar object on a retrograde hyperbola
    (elements of 1I/'Oumuamua's size, 100 deg before its perihelion)."""
    b = orbits.BodySet()
    b.add("Sun", mass=1 * u.Msun)
    b.add("Jupiter", mass=1 * u.Mjup, primary="Sun", a=5.2 * u.au, e=0.048,
          inc=1.3 * u.deg, f=20 * u.deg)
    b.add("Oumuamua", mass=1e-20 * u.Msun, primary="Sun", a=-1.27 * u.au, e=1.2,
          inc=122.7 * u.deg, Omega=24.6 * u.deg, omega=241.8 * u.deg, f=-100 * u.deg)
    b.move_to_com()
    return b


@pytest.fixture(scope="module")
def oss():
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="leapfrog",
                            dt=10 * u.day)
    return sim.run(until=200 * u.yr, outputs=21, progress=False)


@pytest.fixture(scope="module")
def flyby():
    sim = orbits.Simulation(flyby_bodies(), integrator="ias15")
    return sim.run(until=2 * u.yr, outputs=21, progress=False)


@pytest.fixture(scope="module")
def oss_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("analysis") / "oss.h5"
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="leapfrog",
                            dt=10 * u.day)
    sim.run(until=200 * u.yr, outputs=21, progress=False, output=path)
    return path


def body_set_at(result, k):
    return orbits.BodySet.from_arrays(result.masses, result.positions[k],
                                      result.velocities[k], names=result.names,
                                      units=orbits.UnitSystem.from_dict(result.units))


def primaries(result):
    return (None, result.names[0], result.names[1])


# -- elements -------------------------------------------------------------------------
@pytest.mark.parametrize("problem", ["oss", "flyby"])
def test_elements_agree_with_body_set_at_every_output(problem, request):
    result = request.getfixturevalue(problem)
    for name in result.names[1:]:
        for primary in primaries(result):
            if primary == name:
                continue
            series = result.elements(name, primary=primary)
            assert set(series) == {*KEYS, "P"}
            for k in range(len(result)):
                single = body_set_at(result, k).elements(name, primary=primary)
                for key in KEYS:
                    got, want = series[key][k], single[key]
                    assert got.unit == want.unit
                    scale = 1.0 if key in ANGLES else abs(want.value)
                    assert abs(got.value - want.value) <= SAME_KERNEL_TOL * scale, \
                        (name, primary, k, key)


@pytest.mark.parametrize("problem", ["oss", "flyby"])
def test_elements_agree_with_rebound(problem, request):
    rebound = pytest.importorskip("rebound")
    result = request.getfixturevalue(problem)
    G = orbits.UnitSystem.from_dict(result.units).G
    worst = 0.0
    for k in range(len(result)):
        sim = rebound.Simulation()
        sim.G = G
        for m, x, v in zip(result.masses.value, result.positions.value[k],
                           result.velocities.value[k]):
            sim.add(m=m, x=x[0], y=x[1], z=x[2], vx=v[0], vy=v[1], vz=v[2])
        for i, name in enumerate(result.names[1:], start=1):
            for primary in (None, result.names[0]):
                ours = result.elements(name, primary=primary)
                theirs = sim.particles[i].orbit(
                    primary=None if primary is None else sim.particles[0])
                hyperbolic = ours["e"][k] > 1
                for key in KEYS:
                    a, b = ours[key].value[k], getattr(theirs, key)
                    if key in ANGLES:
                        # REBOUND reduces angles (hyperbolic M too) modulo 2 pi
                        err = abs(wrapped(a - b)) / max(1.0, abs(a))
                    else:
                        err = abs(a - b) / abs(b)
                    worst = max(worst, err)
                    assert err < REBOUND_TOL, (name, primary, k, key, a, b)
                if hyperbolic:
                    # no period; REBOUND writes -2 pi sqrt(|a|^3 / mu)
                    assert np.isnan(ours["P"][k]) and theirs.P < 0
                else:
                    assert ours["P"].value[k] == pytest.approx(theirs.P, rel=REBOUND_TOL)
    assert worst > 0  # the comparison ran on numbers, not on NaNs


def test_hyperbolic_elements(flyby):
    el = flyby.elements("Oumuamua", primary="Sun")
    assert np.all(el["a"] < 0) and np.all(el["e"] > 1) and np.all(np.isnan(el["P"]))
    assert el["P"].unit == u.day and el["a"].unit == u.au
    # the object passes perihelion during the run: f goes from -100 deg through 0
    f = el["f"].to_value(u.deg)
    assert f[0] == pytest.approx(-100, abs=1) and f[-1] > 0
    # M is e sinh F - F, not reduced modulo 2 pi: it grows through the run
    assert np.all(np.diff(el["M"].value) > 0) and el["M"].value[-1] > 2 * math.pi
    jupiter = flyby.elements("Jupiter")
    assert np.all(jupiter["a"] > 0) and np.all(np.isfinite(jupiter["P"]))


def test_elements_do_not_depend_on_the_frame(oss):
    # a shift common to all bodies leaves relative states, so elements, unchanged
    # but for the rounding of the shifted coordinates: |x| eps / (e |r|) <~ 1e-13
    for framed in (oss.barycentric(), oss.relative_to("Saturn")):
        for primary in (None, "Sun"):
            a = oss.elements("Neptune", primary=primary)
            b = framed.elements("Neptune", primary=primary)
            for key in KEYS:
                tol = 1e-13 * (1.0 if key in ANGLES else abs(a[key].value).max())
                assert np.max(np.abs(wrapped(a[key].value - b[key].value))) < tol, key


def test_elements_bad_input_is_named(oss):
    with pytest.raises(UnknownBodyError, match="'Vulcan'.*'body'.*known: Sun, Jupiter"):
        oss.elements("Vulcan")
    with pytest.raises(UnknownBodyError, match="'Jupiter'.*'primary'.*unknown primary 'Vulcan'"):
        oss.elements("Jupiter", primary="Vulcan")
    with pytest.raises(BodyError, match="'Jupiter'.*no orbit about itself"):
        oss.elements("Jupiter", primary="Jupiter")
    with pytest.raises(BodyError, match="'Sun'.*'primary'.*name one with primary="):
        oss.elements("Sun")
    assert oss.elements("Sun", primary="Jupiter")["a"].shape == (len(oss),)


def test_elements_table(oss):
    columns, table = oss.elements_table("Saturn", primary="Sun")
    assert columns == ["time [d]", "a [AU]", "e", "inc [deg]", "Omega [deg]",
                       "omega [deg]", "f [deg]", "M [deg]", "P [d]"]
    el = oss.elements("Saturn", primary="Sun")
    np.testing.assert_array_equal(table[:, 0], oss.times.value)
    np.testing.assert_array_equal(table[:, 1], el["a"].value)
    np.testing.assert_allclose(table[:, 3], el["inc"].to_value(u.deg), rtol=1e-15)


# -- frames ---------------------------------------------------------------------------
def test_relative_to_and_barycentric(oss):
    helio = oss.relative_to("Sun")
    assert helio.frame == "Sun" and oss.frame is None
    assert np.all(helio.positions[:, 0].value == 0) and np.all(helio.velocities[:, 0].value == 0)
    np.testing.assert_array_equal(helio.positions[:, 1], oss.positions[:, 1] - oss.positions[:, 0])
    assert helio.times is oss.times and helio.energy is oss.energy
    assert not np.all(oss.positions[:, 0].value == 0)  # the original is untouched

    bary = oss.barycentric()
    assert bary.frame == "barycentric"
    m = bary.masses.value
    com_x = np.einsum("j,tjk->tk", m, bary.positions.to_value(u.au)) / m.sum()
    com_v = np.einsum("j,tjk->tk", m, bary.velocities.to_value(u.au / u.day)) / m.sum()
    # rounding of coordinates of up to 50 au: a few 1e-15 au
    assert np.abs(com_x).max() < 1e-13 and np.abs(com_v).max() < 1e-17
    assert bary.positions.unit == u.au and bary.velocities.unit == u.au / u.day


def test_in_frame_names(oss):
    assert oss.in_frame().frame == "Sun"                 # the Sun holds most of the mass
    assert oss.in_frame("heliocentric").frame == "Sun"
    assert oss.in_frame("barycentric").frame == "barycentric"
    assert oss.in_frame("Jupiter").frame == "Jupiter"
    with pytest.raises(UnknownBodyError, match="'Vulcan'.*'frame'.*barycentric, "
                                               "heliocentric or a body's name"):
        oss.in_frame("Vulcan")
    with pytest.raises(UnknownBodyError, match="'frame'"):
        oss.relative_to("Vulcan")


def test_default_frame_without_a_dominant_body():
    # masses 3, 4, 5: none holds half, so no body is a natural centre
    sim = orbits.Simulation(orbits.scenes.pythagorean(), integrator="ias15")
    result = sim.run(until=0.5, outputs=3, progress=False)
    assert result.in_frame().frame == "barycentric"


def test_barycentre_needs_mass(oss):
    massless = oss.relative_to("Sun")
    massless.masses = oss.masses * 0
    with pytest.raises(NoMassiveBodyError):
        massless.barycentric()


# -- tables ---------------------------------------------------------------------------
def test_to_pandas(oss):
    df = oss.to_pandas()
    assert len(df) == len(oss)
    assert df.columns[0] == "time [d]"
    assert list(df.columns[1:7]) == ["Sun.x [AU]", "Sun.y [AU]", "Sun.z [AU]",
                                     "Sun.vx [AU / d]", "Sun.vy [AU / d]", "Sun.vz [AU / d]"]
    assert len([c for c in df.columns if c.startswith("Jupiter.")]) == 6
    np.testing.assert_array_equal(df["Jupiter.y [AU]"], oss.positions[:, 1, 1].value)
    np.testing.assert_array_equal(df["Pluto.vz [AU / d]"], oss.velocities[:, 5, 2].value)
    np.testing.assert_array_equal(df["time [d]"], oss.times.value)
    # the monitors that were on, with units where they have one
    assert "energy_error" in df.columns and "angular_momentum_error" in df.columns
    assert "energy [AU2 solMass / d2]" in df.columns
    assert "angular_momentum.z [AU2 solMass / d]" in df.columns
    assert df.attrs["frame"] is None and df.attrs["names"] == oss.names
    assert oss.relative_to("Sun").to_pandas().attrs["frame"] == "Sun"


def test_to_xarray(oss):
    pytest.importorskip("xarray")
    ds = oss.to_xarray()
    assert ds["position"].dims == ("time", "body", "axis")
    assert ds["position"].attrs["units"] == "AU"
    assert ds["velocity"].attrs["units"] == "AU / d"
    assert ds["time"].attrs["units"] == "d"
    assert list(ds["body"].values) == oss.names
    np.testing.assert_array_equal(ds["position"].sel(body="Saturn", axis="x"),
                                  oss.positions[:, 2, 0].value)
    assert ds["energy_error"].dims == ("time",)
    assert ds.attrs["frame"] == "as integrated"
    assert oss.barycentric().to_xarray().attrs["frame"] == "barycentric"


def test_to_xarray_without_xarray_says_how_to_install(oss, monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)   # import xarray raises ImportError
    with pytest.raises(ImportError, match="pip install xarray"):
        oss.to_xarray()


# -- loaded files ---------------------------------------------------------------------
def test_loaded_file_has_the_same_analysis(oss, oss_file):
    loaded = orbits.load(oss_file)
    assert isinstance(loaded, orbits.Result) and len(loaded) == len(oss)
    for primary in (None, "Sun"):
        a, b = loaded.elements("Uranus", primary=primary), oss.elements("Uranus", primary)
        for key in (*KEYS, "P"):
            np.testing.assert_array_equal(a[key], b[key])   # same run, same numbers
    helio = loaded.relative_to("Sun")
    assert helio.frame == "Sun" and np.all(helio.positions[:, 0].value == 0)
    assert loaded.barycentric().frame == "barycentric"
    df = loaded.to_pandas()
    assert list(df.columns) == list(oss.to_pandas().columns)


def test_cli_elements(oss, oss_file, tmp_path, capsys):
    assert main(["elements", str(oss_file), "--body", "Jupiter", "--primary", "Sun"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["time", "[d]", "a", "[AU]", "e", "inc", "[deg]", "Omega",
                                "[deg]", "omega", "[deg]", "f", "[deg]", "M", "[deg]", "P",
                                "[d]"]
    assert len(lines) == 1 + len(oss)
    a = oss.elements("Jupiter", primary="Sun")["a"].value
    assert float(lines[-1].split()[1]) == pytest.approx(a[-1], rel=1e-9)  # printed to 10 digits

    out = tmp_path / "jupiter.csv"
    assert main(["elements", str(oss_file), "--body", "Jupiter", "--out", str(out)]) == 0
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    columns, table = oss.elements_table("Jupiter")
    assert rows[0] == columns
    np.testing.assert_array_equal(np.array(rows[1:], dtype=float), table)  # full precision

    assert main(["elements", str(oss_file), "--body", "Vulcan"]) == 3
    err = capsys.readouterr().err
    assert "'Vulcan'" in err and "known: Sun, Jupiter" in err
    assert main(["elements", str(oss_file), "--body", "Jupiter", "--primary", "Vulcan"]) == 3
    assert "unknown primary 'Vulcan'" in capsys.readouterr().err

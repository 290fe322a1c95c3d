"""Plots, rendered with matplotlib's Agg canvas and checked for what they show."""

import math

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits.cli import main
from orbits.errors import UnknownBodyError

pytest.importorskip("matplotlib")

from orbits import plotting  # noqa: E402  (after the skip: it draws with matplotlib)

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def oss():
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="leapfrog",
                            dt=10 * u.day)
    return sim.run(until=300 * u.yr, outputs=301, progress=False)


@pytest.fixture(scope="module")
def long_file(tmp_path_factory):
    # the issue's example: 1e5 years of the outer solar system in its published
    # frame, where the centre of mass drifts 250 au over the run
    path = tmp_path_factory.mktemp("plots") / "oss-1e5yr.h5"
    sim = orbits.Simulation(orbits.scenes.outer_solar_system(), integrator="wh",
                            dt=100 * u.day)
    sim.run(until=1e5 * u.yr, outputs=200, progress=False, output=path)
    return path


def legend_labels(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_time_unit_follows_the_span():
    assert plotting.time_unit(30 * u.day) == u.day
    assert plotting.time_unit(300 * u.yr) == u.yr
    assert plotting.time_unit(1e5 * u.yr) == u.kyr
    assert plotting.time_unit(3e7 * u.yr) == u.Myr
    assert plotting.time_unit(3e7 * u.day) == u.kyr
    assert plotting.time_unit(10 * u.one) == u.one        # N-body units stay as they are


def test_plot_default_frame_is_about_the_most_massive_body(oss, tmp_path):
    fig = oss.plot(path=tmp_path / "oss.png")
    assert (tmp_path / "oss.png").read_bytes()[:8] == PNG
    ax_orbit, ax_err = fig.axes
    assert ax_orbit.get_title() == "orbits (x-y plane), about Sun"
    assert ax_orbit.get_xlabel() == "x [AU]" and ax_orbit.get_ylabel() == "y [AU]"
    # one path per planet; the Sun is the star at the origin, not a path
    assert [line.get_label() for line in ax_orbit.lines] == oss.names[1:]
    assert legend_labels(ax_orbit)[0] == "Sun (centre)"
    star = ax_orbit.collections[0]
    np.testing.assert_array_equal(star.get_offsets(), [[0.0, 0.0]])
    helio = oss.relative_to("Sun").positions.to_value(u.au)
    np.testing.assert_array_equal(ax_orbit.lines[0].get_xdata(), helio[:, 1, 0])
    np.testing.assert_array_equal(ax_orbit.lines[3].get_ydata(), helio[:, 4, 1])
    assert ax_err.get_xlabel() == "time since start [yr]"
    assert ax_err.get_xscale() == "log" and ax_err.get_yscale() == "log"
    assert len(ax_err.lines) == 2          # energy and angular momentum


def test_plot_barycentric_and_about_a_body(oss):
    ax = oss.plot(frame="barycentric").axes[0]
    assert ax.get_title() == "orbits (x-y plane), barycentric"
    assert [line.get_label() for line in ax.lines] == oss.names
    bary = oss.barycentric().positions.to_value(u.au)
    np.testing.assert_array_equal(ax.lines[0].get_xdata(), bary[:, 0, 0])

    ax = oss.plot(frame="Jupiter").axes[0]
    assert ax.get_title() == "orbits (x-y plane), about Jupiter"
    assert "Jupiter" not in [line.get_label() for line in ax.lines]
    assert oss.plot(frame="heliocentric").axes[0].get_title().endswith("about Sun")
    with pytest.raises(UnknownBodyError, match="'Vulcan'.*'frame'"):
        oss.plot(frame="Vulcan")


def test_plot_well_sampled_paths_are_lines_and_sparse_ones_dots(oss):
    lines = {line.get_label(): line for line in oss.plot().axes[0].lines}
    # 300 outputs a year apart: a year is 30 deg of Jupiter's orbit, 1.5 of Pluto's;
    # ten years are 300 deg of Jupiter's (a chord of 0.97 r) and 15 of Pluto's (0.25 r)
    assert lines["Pluto"].get_linestyle() == "-" and lines["Pluto"].get_marker() == "None"
    thin = oss.relative_to("Sun")
    thin.times, thin.positions = thin.times[::10], thin.positions[::10]
    thin.energy_error = thin.angular_momentum_error = None
    lines = {line.get_label(): line for line in thin.plot().axes[0].lines}
    assert lines["Jupiter"].get_linestyle() == "None" and lines["Jupiter"].get_marker() == "."
    assert lines["Pluto"].get_linestyle() == "-"


def test_plot_of_the_issue_example_has_no_smear_and_a_kyr_axis(long_file, tmp_path):
    png = tmp_path / "long.png"
    assert main(["plot", str(long_file), "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == PNG
    fig = orbits.load(long_file).plot()
    ax_orbit, ax_err = fig.axes
    assert ax_err.get_xlabel() == "time since start [kyr]"
    assert ax_err.get_xlim()[1] < 1000                      # 100 kyr, not 3.65e7 days
    extent = max(np.abs(np.concatenate([line.get_xydata() for line in ax_orbit.lines])).max(0))
    assert 40 < extent < 55                                  # Pluto's aphelion, no 250 au drift
    published = orbits.load(long_file).positions.to_value(u.au)
    assert np.abs(published[:, :, :2]).max() > 200           # what the old plot showed


def test_cli_plot_frame(long_file, tmp_path, capsys):
    png = tmp_path / "bary.png"
    assert main(["plot", str(long_file), "-o", str(png), "--frame", "barycentric"]) == 0
    assert png.read_bytes()[:8] == PNG and f"wrote {png}" in capsys.readouterr().out
    assert main(["plot", str(long_file), "-o", str(png), "--frame", "Vulcan"]) == 3
    err = capsys.readouterr().err
    assert "'Vulcan'" in err and "barycentric, heliocentric or a body's name" in err


def test_plot_elements(oss, tmp_path):
    fig = oss.plot_elements(primary="Sun", path=tmp_path / "el.png")
    assert (tmp_path / "el.png").read_bytes()[:8] == PNG
    ax_a, ax_e, ax_i = fig.axes
    assert [ax.get_ylabel() for ax in fig.axes] == ["a [AU]", "e", "inc [deg]"]
    assert ax_i.get_xlabel() == "time [yr]"
    assert all(len(ax.lines) == len(oss.names) - 1 for ax in fig.axes)
    assert legend_labels(ax_a) == oss.names[1:]
    assert "about Sun" in ax_a.get_title()
    el = oss.elements("Saturn", primary="Sun")
    np.testing.assert_array_equal(ax_a.lines[1].get_ydata(), el["a"].value)
    np.testing.assert_allclose(ax_i.lines[1].get_ydata(), el["inc"].to_value(u.deg),
                               rtol=1e-15)
    np.testing.assert_allclose(ax_a.lines[1].get_xdata(), oss.times.to_value(u.yr),
                               rtol=1e-15)

    fig = oss.plot_elements(bodies=["Neptune"])
    assert [len(ax.lines) for ax in fig.axes] == [1, 1, 1]
    assert "Jacobi" in fig.axes[0].get_title()
    with pytest.raises(UnknownBodyError, match="'Vulcan'"):
        oss.plot_elements(bodies=["Vulcan"])


def two_orbits():
    b = orbits.BodySet()
    b.add("Star", mass=1 * u.Msun)
    b.add("Planet", mass=1e-3 * u.Msun, primary="Star", a=2 * u.au, e=0.5,
          omega=30 * u.deg, f=60 * u.deg)
    b.add("Comet", mass=0 * u.Msun, primary="Star", a=-3 * u.au, e=1.5, f=-40 * u.deg)
    return b


def test_plot_orbits_draws_the_osculating_conics(tmp_path):
    bodies = two_orbits()
    fig = plotting.plot_orbits(bodies, primary="Star", path=tmp_path / "o.png")
    assert (tmp_path / "o.png").read_bytes()[:8] == PNG
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x [AU]" and ax.get_ylabel() == "y [AU]"
    assert "about Star" in ax.get_title()
    planet, comet = ax.lines
    assert (planet.get_label(), comet.get_label()) == ("Planet", "Comet")
    star = bodies.positions[0].to_value(u.au)[:2]
    r = np.hypot(*(planet.get_xydata() - star).T)
    # the ellipse's extremes are q = a (1 - e) and Q = a (1 + e); 721 points put
    # a vertex within 0.5 deg of each apse, where r is flat: (0.5 deg)^2 e Q / 2
    assert r.min() == pytest.approx(1.0, rel=1e-4) and r.max() == pytest.approx(3.0, rel=1e-4)
    assert np.allclose(planet.get_xydata()[0], planet.get_xydata()[-1])   # closed
    # the hyperbola: open, its pericentre q = a (1 - e) = 1.5 au, reaching 4 q
    rc = np.hypot(*(comet.get_xydata() - star).T)
    assert rc.min() == pytest.approx(1.5, rel=1e-4) and rc.max() == pytest.approx(6.0, rel=1e-6)
    # each body's dot lies on its curve
    for i, line in ((1, planet), (2, comet)):
        here = bodies.positions[i].to_value(u.au)[:2]
        gap = np.hypot(*(line.get_xydata() - here).T).min()
        assert gap < 2 * math.pi * 3.0 / 720, bodies.names[i]       # one step along the curve


def test_plot_orbits_jacobi_and_planes():
    bodies = orbits.scenes.outer_solar_system()
    fig = bodies.plot_orbits()
    ax = fig.axes[0]
    assert [line.get_label() for line in ax.lines] == bodies.names[1:]
    assert "Jacobi" in ax.get_title()
    # Jupiter's orbit in the equatorial xz plane is tilted by 23 deg: its z reaches
    # a (1 + e) sin(inc) at most
    xz = plotting.plot_orbits(bodies, primary="Sun", plane="xz").axes[0]
    assert xz.get_ylabel() == "z [AU]"
    el = bodies.elements("Jupiter", primary="Sun")
    zmax = np.abs(xz.lines[0].get_ydata()).max()
    assert zmax <= (el["a"] * (1 + el["e"]) * np.sin(el["inc"])).to_value(u.au) + 1e-9
    assert zmax > 0.3 * el["a"].to_value(u.au)
    with pytest.raises(ValueError, match="unknown plane 'xw'; expected one of xy, xz, yz"):
        bodies.plot_orbits(plane="xw")
    with pytest.raises(UnknownBodyError, match="Vulcan"):
        bodies.plot_orbits(primary="Vulcan")


def test_plots_of_an_empty_result_say_so(oss):
    empty = oss.relative_to("Sun")
    empty.times, empty.positions = empty.times[:0], empty.positions[:0]
    for draw in (empty.plot, empty.plot_elements):
        with pytest.raises(ValueError, match="no outputs"):
            draw()

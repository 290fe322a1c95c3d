"""The examples run and print what they promise."""

import pathlib
import runpy

import astropy.units as u
import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.slow  # ~20 s compiling every method for a user force; the docs' build runs it too
def test_spring_example_prints_every_method(capsys):
    runpy.run_path(str(EXAMPLES / "spring.py"), run_name="__main__")
    out = capsys.readouterr().out
    for name in ("euler", "symplectic-euler", "verlet", "leapfrog", "rk2", "rk4"):
        assert f"\n{name} " in out


def test_sun_jupiter_probe_example(capsys):
    mod = runpy.run_path(str(EXAMPLES / "sun_jupiter_probe.py"))
    result = mod["main"](until=50 * u.yr)
    assert result.positions.shape == (500, 3, 3)
    assert "Jupiter at the end: a = 5.2" in capsys.readouterr().out


def test_mercury_perihelion_example(capsys):
    # 20 years keep the test short; the fit's error then grows as T^-3/2
    # from the 100-year run's 1e-4 relative, to about 1e-3
    mod = runpy.run_path(str(EXAMPLES / "mercury_perihelion.py"))
    theory, rates = mod["main"](years=20)
    assert abs(theory - 42.98) < 0.01
    assert abs(rates["no GR (wh)"]) < 0.01
    for label in ("GR (ias15)", "GRPotential (wh)", "GRFull (ias15)"):
        assert abs(rates[label] / theory - 1) < 2e-3, label
    assert "GRFull (ias15)" in capsys.readouterr().out


def test_plotting_a_run_example(capsys):
    # 2000 years keep it to a few seconds; the figures' layout does not depend on the length
    import matplotlib.pyplot as plt
    plt.close("all")
    mod = runpy.run_path(str(EXAMPLES / "plotting_a_run.py"))
    result, figures = mod["main"](until=2000 * u.yr, outputs=100)
    # drawn into pyplot's figures (fig=, ax=), which the gallery's scraper collects
    assert [plt.figure(n) for n in plt.get_fignums()] == list(figures.values())
    assert "status          completed" in capsys.readouterr().out
    assert sorted(figures) == ["elements", "orbits", "sketch"]

    orbit_axes, error_axes = figures["orbits"].axes
    assert orbit_axes.get_title() == "orbits (x-y plane), about Sun"
    assert (orbit_axes.get_xlabel(), orbit_axes.get_ylabel()) == ("x [AU]", "y [AU]")
    assert len(orbit_axes.lines) == 5          # every body but the Sun, at the centre
    assert [t.get_text() for t in orbit_axes.get_legend().get_texts()][:2] == [
        "Sun (centre)", "Jupiter"]
    assert error_axes.get_xlabel() == "time since start [yr]"
    assert len(error_axes.lines) == 2          # energy and angular momentum

    element_axes = figures["elements"].axes
    assert [ax.get_ylabel() for ax in element_axes] == ["a [AU]", "e", "inc [deg]"]
    assert [len(ax.lines) for ax in element_axes] == [5, 5, 5]
    assert element_axes[-1].get_xlabel() == "time [yr]"

    (sketch_axes,) = figures["sketch"].axes
    assert [line.get_label() for line in sketch_axes.lines] == [
        "Jupiter", "Saturn", "Uranus", "Neptune", "Pluto"]
    assert sketch_axes.get_xlabel() == "x [AU]"
    plt.close("all")

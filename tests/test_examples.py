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

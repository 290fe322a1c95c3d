"""The examples run and print what they promise."""

import pathlib
import runpy

import astropy.units as u

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


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

"""The command line, called as main([...])."""

import pathlib
import re

import pytest

from orbits.cli import main, parse_quantity


def test_integrators_and_scenes_lists(capsys):
    assert main(["integrators"]) == 0
    out = capsys.readouterr().out
    for name in ("euler", "symplectic-euler", "verlet", "leapfrog", "rk2", "rk4"):
        assert name in out
    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    for name in ("earth-moon", "outer-solar-system", "figure-eight", "plummer"):
        assert name in out


def test_run_prints_summary(capsys):
    code = main(["run", "outer-solar-system", "--integrator", "leapfrog", "--dt", "10d",
                 "--until", "100yr", "--no-progress"])
    assert code == 0
    out = capsys.readouterr().out
    # 100 yr / 10 d = 3652.5: 3652 steps and a last half step
    assert "leapfrog" in out and re.search(r"steps\s+3653 ", out) and "energy" in out


def test_run_errors_are_reported(capsys):
    assert main(["run", "outer-solar-system", "--integrator", "nope", "--dt", "10d",
                 "--until", "1yr"]) == 3
    assert "valid names" in capsys.readouterr().err
    assert main(["run", "no-such-scene", "--dt", "10d", "--until", "1yr"]) == 3
    assert "outer-solar-system" in capsys.readouterr().err


def test_parse_quantity():
    assert parse_quantity("10d").to_value("day") == 10
    assert parse_quantity("1000 yr").to_value("yr") == 1000
    assert parse_quantity("0.5") == 0.5
    import argparse
    with pytest.raises(argparse.ArgumentTypeError):
        parse_quantity("10 au")
    with pytest.raises(argparse.ArgumentTypeError):
        parse_quantity("ten days")


# -- exit statuses ------------------------------------------------------------------------

COINCIDENT = """
[[body]]
name = "A"
mass = "1 Msun"

[[body]]
name = "B"
mass = "1 Msun"
position = ["1e-200 au", "0 au", "0 au"]
velocity = ["0 km/s", "0 km/s", "0 km/s"]
"""


def test_each_way_of_ending_has_its_own_exit_status(tmp_path, capsys, monkeypatch):
    # before, every uncaught error left Python with status 1, the status of a
    # run stopped by a stopping condition, and every named error gave 2
    from orbits import cli
    with pytest.raises(SystemExit) as info:          # argparse's own
        main(["run", "kepler", "--no-such-option"])
    assert info.value.code == cli.EXIT_USAGE == 2
    capsys.readouterr()
    assert main(["run", "kepler", "-i", "nope", "--dt", "1d", "--until", "2d"]) == 3
    assert "valid names" in capsys.readouterr().err
    assert main(["info", str(tmp_path / "nope.h5")]) == 4
    assert "nope.h5: no such file" in capsys.readouterr().err
    # r**3 underflows at 1e-200 au: the state is non-finite after one step
    system = tmp_path / "coincident.toml"
    system.write_text(COINCIDENT)
    assert main(["run", str(system), "-i", "leapfrog", "--dt", "1d", "--until", "2d",
                 "--outputs", "3", "--no-progress"]) == 5
    out, err = capsys.readouterr()
    assert "orbits: the run failed: the state became non-finite" in err
    assert "status          non-finite state" in out        # the summary up to there

    def broken():
        raise ZeroDivisionError("a bug")
    monkeypatch.setattr("orbits.scenes.describe", broken)
    assert main(["scenes"]) == 70
    err = capsys.readouterr().err
    assert "Traceback" in err and "ZeroDivisionError: a bug" in err
    assert "internal error" in err


def test_the_exit_statuses_are_documented():
    from orbits import cli
    help_text = " ".join(cli._parser().format_help().split())
    page = (pathlib.Path(__file__).resolve().parents[1] / "docs" / "guides"
            / "cli.rst").read_text()
    page = " ".join(page.replace("*", "").replace("-", "").split())
    assert set(cli.EXIT_STATUSES) == {0, 1, 2, 3, 4, 5, 70}
    for code, text in cli.EXIT_STATUSES.items():
        assert f"{code} {text}" in help_text, code
        assert f"``{code}`` {' '.join(text.replace('-', '').split())}" in page, code

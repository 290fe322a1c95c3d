"""The command line, called as main([...])."""

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
                 "--until", "1yr"]) == 2
    assert "valid names" in capsys.readouterr().err
    assert main(["run", "no-such-scene", "--dt", "10d", "--until", "1yr"]) == 2
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

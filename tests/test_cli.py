"""The command line, called as main([...])."""

import pathlib
import re
import signal

import astropy.units as u
import numpy as np
import pytest

import orbits
from orbits import plotting
from orbits.cli import main, parse_quantity
from orbits.io.h5md import FileRecorder
from orbits.units import format_time, time_unit


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


# -- times as a person reads them ----------------------------------------------------------

@pytest.mark.parametrize("bound, below, at", [
    (1 * u.day, u.s, u.day),
    (1 * u.yr, u.day, u.yr),
    (1e3 * u.yr, u.yr, u.kyr),
    (1e6 * u.yr, u.kyr, u.Myr),
    (1e9 * u.yr, u.Myr, u.Gyr),
])
def test_time_unit_changes_at_each_bound(bound, below, at):
    # one chooser for the summary, `orbits info` and the plots; the bounds given
    # in days as a file stores them, to the last bit on either side
    days = bound.to_value(u.day)
    assert time_unit(days * u.day) == at
    assert time_unit(np.nextafter(days, 0) * u.day) == below
    assert time_unit(-days * u.day) == at                 # a run backwards
    assert plotting.time_unit is time_unit


def test_format_time_reads_the_issue_example():
    assert format_time(4.383e9 * u.day) == "12 Myr"
    assert format_time(3.6525e7 * u.day) == "100 kyr"
    assert format_time(3600 * u.s) == "3600 s"
    assert format_time(0 * u.day, time_unit(1e5 * u.yr)) == "0 kyr"
    assert format_time(10 * u.one) == "10"                   # N-body units have no unit


def test_summary_and_info_give_times_by_their_span(tmp_path, capsys):
    path = tmp_path / "run.h5"
    assert main(["run", "kepler", "-i", "leapfrog", "--dt", "10d", "--until", "1000yr",
                 "--outputs", "3", "--out", str(path), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "time            0 -> 1 kyr, dt = 10 d" in out
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "outputs         3, t = 0 .. 1 kyr" in out
    assert "the last at step 36525, t = 1 kyr" in out
    assert "365250 d" not in out and "e+" not in out


# -- orbits elements FILE BODY ---------------------------------------------------------------

@pytest.fixture(scope="module")
def kepler_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("elements") / "kepler.h5"
    sim = orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day)
    sim.run(until=10 * u.day, outputs=3, output=path, progress=False)
    return path


def test_elements_takes_the_body_as_an_argument_or_as_before(kepler_file, capsys):
    assert main(["elements", str(kepler_file), "Planet"]) == 0
    positional = capsys.readouterr().out
    assert main(["elements", str(kepler_file), "--body", "Planet"]) == 0
    assert capsys.readouterr().out == positional
    assert len(positional.splitlines()) == 4 and "a [AU]" in positional
    assert main(["elements", str(kepler_file), "Vulcan"]) == 3
    assert "Vulcan" in capsys.readouterr().err


@pytest.mark.parametrize("argv, words", [
    (["Planet", "--body", "Star"], "give the body once"),
    ([], "give the body, as in 'orbits elements FILE Jupiter'"),
])
def test_elements_needs_the_body_once(kepler_file, argv, words, capsys):
    with pytest.raises(SystemExit) as info:
        main(["elements", str(kepler_file), *argv])
    assert info.value.code == 2
    assert words in capsys.readouterr().err


# -- orbits resume ---------------------------------------------------------------------------

class Crash(Exception):
    pass


@pytest.fixture
def interrupted(tmp_path, monkeypatch):
    """A file of a 100-day leapfrog run (a step a day) killed before its last output,
    after a checkpoint at each of the others (the last at day 90)."""
    path = tmp_path / "cut.h5"
    real = FileRecorder.output

    def output(self, sim, final=False):
        if final:
            raise Crash()
        real(self, sim, final)
    with monkeypatch.context() as mp:
        mp.setattr(FileRecorder, "output", output)
        with pytest.raises(Crash):
            orbits.Simulation(orbits.scenes.kepler(), "leapfrog", dt=1 * u.day).run(
                until=100 * u.day, outputs=11, output=path, progress=False,
                checkpoint_interval=0)
    assert "interrupted" in orbits.io.describe(path)
    return path


def test_resume_summarises_the_whole_run(interrupted, capsys):
    assert main(["resume", str(interrupted), "--no-progress"]) == 0
    out = capsys.readouterr().out
    # the 10 steps after the last checkpoint were done here; the summary is of all 100
    assert re.search(r"steps\s+100 \(100 force evaluations\)", out)
    assert "time            0 -> 100 d" in out
    assert "this command    10 of these steps, from t = 90 d" in out
    assert main(["resume", str(interrupted), "--until", "200d", "--outputs", "3",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"steps\s+200 ", out) and "time            0 -> 200 d" in out
    assert "this command    100 of these steps, from t = 100 d" in out
    # the largest energy error is the file's, as orbits.load reads it
    whole = orbits.load(interrupted)
    assert f"largest relative error {whole.max_energy_error():.3e}" in out


def test_resume_finishes_and_continues_in_one_command(interrupted, capsys):
    assert main(["resume", str(interrupted), "--until", "200d", "--outputs", "3",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "finished the interrupted run" in out
    assert re.search(r"steps\s+200 ", out)
    assert "this command    110 of these steps, from t = 90 d" in out


def test_resume_until_before_the_end_is_refused_before_any_work(interrupted, capsys):
    # before, the interrupted run was finished first and only then was --until refused
    before = interrupted.read_bytes()
    assert main(["resume", str(interrupted), "--until", "50d", "--no-progress"]) == 3
    err = capsys.readouterr().err
    assert "--until 50 d is not after the end of the interrupted run" in err
    assert "(t = 100 d)" in err and "or none to only finish the run" in err
    assert interrupted.read_bytes() == before
    assert "interrupted" in orbits.io.describe(interrupted)
    assert main(["resume", str(interrupted), "--until", "100d", "--no-progress"]) == 3
    capsys.readouterr()
    # a finished run: its end is the time it reached
    assert main(["resume", str(interrupted), "--no-progress"]) == 0
    capsys.readouterr()
    # a plain number is in the file's unit of time, days
    assert main(["resume", str(interrupted), "--until", "0.5", "--no-progress"]) == 3
    assert ("--until 43200 s is not after the end of the run in" in capsys.readouterr().err)


def test_an_interrupted_run_says_when_it_stopped_in_readable_units(monkeypatch, capsys):
    from orbits.errors import RunInterrupted

    def interrupted(self, *args, **kwargs):
        raise RunInterrupted("interrupted", signal=signal.SIGINT, time=4.383e9 * u.day,
                             step=43830000)
    monkeypatch.setattr(orbits.Simulation, "run", interrupted)
    assert main(["run", "kepler", "-i", "leapfrog", "--dt", "100d", "--until", "20Myr",
                 "--no-progress"]) == 128 + signal.SIGINT
    assert "stopped by SIGINT at t = 12 Myr (step 43830000)" in capsys.readouterr().err

"""An integrator's options are declared once, with its class: the checks and the
command line's flags are made from the declaration."""

import argparse
import ast

import numpy as np
import pytest

import orbits
from orbits import _integrator_options, cli
from orbits._integrator_options import Option
from orbits.errors import IntegratorOptionError
from orbits.integrators import _classes


def _run_parser():
    parser = cli._parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices["run"]


def _flags(parser, group):
    actions = next(g for g in parser._action_groups if g.title == group)._group_actions
    return {action.option_strings[0]: action for action in actions}


def test_the_source_reading_finds_what_the_classes_declare():
    # the command line reads the declarations without importing the integrators;
    # what it reads is what the registered classes hold, in the registry's order
    live = {cls.name: cls.option_specs for cls in _classes()}
    assert _integrator_options.declared() == live
    assert list(_integrator_options.declared()) == list(live)
    assert any(live.values())


def test_options_are_made_from_the_declarations():
    for cls in _classes():
        assert cls.options == {spec.name: spec.default for spec in cls.option_specs}
        assert orbits.integrators.get(cls.name).config == cls.options, cls.name


def test_every_declared_option_has_a_flag_and_every_flag_a_declaration():
    flags = _flags(_run_parser(), "integrator options")
    declared = {spec.flag: spec for cls in _classes() for spec in cls.option_specs}
    assert set(flags) == set(declared)
    for flag, action in flags.items():
        spec = declared[flag]
        assert action.dest == spec.name
        assert spec.help in action.help
        takers = [c.name for c in _classes() if spec in c.option_specs]
        assert ", ".join(takers) in action.help, flag


def test_a_new_declaration_is_read_and_gets_a_flag(tmp_path, monkeypatch):
    # a new option is one declaration: copy the integrators' source, add one to
    # ias15, and the reading and the command line's flags follow
    for path in _integrator_options.INTEGRATORS.glob("*.py"):
        text = path.read_text(encoding="utf-8")
        if path.name == "ias15.py":
            text = text.replace('        MIN_DT,\n', '        MIN_DT,\n        Option("safety", '
                                'float, 0.25, "a new option", sign="positive"),\n', 1)
        (tmp_path / path.name).write_text(text, encoding="utf-8")
    monkeypatch.setattr(_integrator_options, "INTEGRATORS", tmp_path)
    _integrator_options.declared.cache_clear()
    try:
        new = Option("safety", float, 0.25, "a new option", sign="positive")
        assert new in _integrator_options.declared()["ias15"]
        assert "--safety" in _flags(_run_parser(), "integrator options")
    finally:
        _integrator_options.declared.cache_clear()


def test_the_reading_refuses_what_it_cannot_evaluate():
    # a declaration computed at run time cannot be read from the source: an error,
    # not a silently different table
    tree = ast.parse("X = f(1)\n")
    modules = {"m": _integrator_options._Module(tree)}
    with pytest.raises(ValueError):
        _integrator_options._evaluate(ast.Name("X"), modules, "m")


@pytest.mark.parametrize("spec, value, words", [
    (Option("a", float, 1.0, "", sign="positive"), 0.0, "a positive finite number, got 0.0"),
    (Option("a", float, 1.0, "", sign="positive"), "1", "(a string)"),
    (Option("a", float, 1.0, "", sign="non-negative"), -1.0, "non-negative"),
    (Option("a", float, 1.0, ""), float("inf"), "a finite number"),
    (Option("a", float, 1.0, ""), True, "a finite number"),
    (Option("a", int, 1, "", sign="non-negative"), 2.5, "a non-negative whole number"),
    (Option("a", str, "x", ""), 3, "must be a string"),
    (Option("a", int, 0, "", choices=(0, 3)), True, "valid values: 0, 3"),
    (Option("a", str, "x", "", choices=("x", "y")), "z", "unknown a 'z'; valid values: 'x', 'y'"),
])
def test_a_value_outside_its_declaration_is_named(spec, value, words):
    assert words in spec.problem(value)
    with pytest.raises(ValueError, match="option 'a'|unknown a"):
        spec.checked(value)


def test_values_are_converted_to_the_declared_type():
    assert type(Option("a", float, 1.0, "").checked(np.int64(3))) is float
    assert Option("a", int, 0, "", choices=(0, 3)).checked(3.0) == 3
    assert type(Option("a", int, 0, "", choices=(0, 3)).checked(3.0)) is int


def test_the_integrator_names_itself_in_the_error():
    with pytest.raises(IntegratorOptionError, match="integrator 'trace': option 'hill' "
                                                   "must be a positive finite number"):
        orbits.integrators.get("trace", hill=0.0)


def test_a_unit_option_takes_a_quantity_on_the_command_line(capsys):
    # --min-dt 24h on a scene in days: the integrator gets 1.0 (its internal unit),
    # above the steps ias15 takes on this orbit (0.2 d), so the run stops at once
    status = cli.main(["run", "kepler", "-i", "ias15", "--min-dt", "24h", "--until", "100d",
                       "--no-progress"])
    out, err = capsys.readouterr()
    assert status == cli.EXIT_RUN_FAILED
    assert "min_dt=1.0," in out and "step size of 'ias15' collapsed" in err
    # a plain number is in the scene's unit of time, as the help says
    assert cli.main(["run", "kepler", "-i", "ias15", "--min-dt", "0.001", "--until", "10d",
                     "--no-progress"]) == cli.EXIT_COMPLETED
    assert "min_dt=0.001," in capsys.readouterr().out

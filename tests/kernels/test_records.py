"""The compiled loops take records (orbits._kernels.records and each kernel
module's Work), not dozens of positional arguments."""

import inspect
import typing

import numpy as np
import pytest

from orbits._kernels import (doubling, embedded, ias15, implicit, records, stepping, taylor,
                             trace, wh_batch, wisdom_holman)

LOOPS = [stepping._splitting_loop, stepping._runge_kutta_loop, implicit._implicit_loop,
         embedded._adaptive_loop, ias15._ias15_loop,
         taylor._taylor_loop, trace._trace_loop, wisdom_holman._wh_loop,
         wh_batch._advance_lanes]

#: the most positional arguments a loop takes: the state (x, v, the time, the
#: step or nothing, the steps), the force's arguments, the pointers, and a
#: handful of records (trace's 14 today, its pointer for the look ahead and
#: the terms' arguments among them)
MOST_ARGUMENTS = 14


@pytest.mark.parametrize("loop", LOOPS, ids=lambda f: f.__name__)
def test_a_loop_takes_records(loop):
    params = list(inspect.signature(loop).parameters)
    assert len(params) <= MOST_ARGUMENTS, (loop.__name__, params)


@pytest.mark.parametrize("module", [implicit, embedded, doubling, ias15, taylor, trace,
                                    wisdom_holman], ids=lambda m: m.__name__.rsplit(".", 1)[1])
def test_each_workspace_is_a_named_tuple_of_arrays(module):
    fields = typing.get_type_hints(module.Work)
    assert fields and all(t is np.ndarray for t in fields.values()), fields


def test_monitors_become_one_record_type_whatever_the_caller_passes():
    # a tuple from a test or a doctest and the simulation's record compile
    # the same loop: the numbers take the loops' types
    m = np.ones(2)
    rec = records.monitors((0, 0, m, 1, 2, 0))
    assert type(rec) is records.Monitors
    assert [type(f) for f in rec] == [int, int, np.ndarray, float, int, float]
    assert records.monitors(rec) is rec
    with_terms = records.monitors((0, 0, m, 1.0, 2, 0.0, ((),)))
    assert type(with_terms) is records.MonitorsWithTerms and with_terms.terms == ((),)


def test_monitors_of_another_length_are_refused():
    with pytest.raises(ValueError, match="6 or 7"):
        records.monitors((0, 0, np.ones(2), 1.0, 2))


def test_a_workspace_record_is_made_of_the_workspace_dicts_arrays():
    ws = {name: np.zeros(1) for name in wisdom_holman.Work._fields}
    ws["extra"] = np.zeros(3)
    work = records.work(wisdom_holman.Work, ws)
    assert all(getattr(work, name) is ws[name] for name in wisdom_holman.Work._fields)
    del ws["cdt"]
    with pytest.raises(KeyError, match="cdt"):
        records.work(wisdom_holman.Work, ws)

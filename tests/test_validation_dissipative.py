"""The report's section on the dissipative force terms
(orbits.validation.dissipative): parity with REBOUNDx and the analytic rates."""

import math
import re

import numpy as np
import pytest

from orbits import validation
from orbits.validation import dissipative

pytest.importorskip("rebound")


def _fake_rows(broken=None):
    """Rows as the tasks return them, made up: ours 1e-12 au from REBOUNDx, which
    is 0.1 au from REBOUND without the force (as a fraction of a = 2 au)."""
    rows = []
    times = np.linspace(0.0, 10.0, 3)
    for case in dissipative.PARITY_CASES:
        base = np.zeros((3, 2, 3))
        for code, shift in (("orbits", 1e-12), ("reboundx", 0.0), ("rebound", 0.1)):
            x = base.copy()
            x[1:, 1, 0] += shift
            outcome = "completed"
            if (case, code) == broken:
                x[2] = np.nan
                outcome = "NonFiniteState"
            rows.append({"kind": "parity", "case": case, "code": code, "times": times,
                         "period": 5.0, "names": ["Star", "Planet"], "scale": 2.0, "x": x,
                         "wall_time": 0.5, "steps": 10, "outcome": outcome,
                         "message": "made up" if outcome != "completed" else ""})
    for case in dissipative.RATE_CASES:
        rows.append({"kind": "rate", "case": case, "outcome": "completed", "message": "",
                     "rows": [{"what": f"{case} rate", "analytic": 2.0, "measured": 2.002,
                               "unit": "yr", "left_out": "nothing"}]})
    return rows


def test_the_section_is_registered_with_its_tasks():
    assert "dissipative" in validation.SECTIONS
    tasks = dissipative.tasks(quick=True)
    parity = [t for t in tasks if t.function.endswith(":measure")]
    assert len(parity) == 3 * len(dissipative.PARITY_CASES)
    assert {t.kwargs["case"] for t in tasks if t.function.endswith(":rate")} == set(
        dissipative.RATE_CASES)
    assert dissipative.orbits_run(True) == 200 and dissipative.orbits_run(False) == 1000


def test_the_section_renders_made_up_rows(tmp_path):
    text = dissipative.section(_fake_rows(), tmp_path, quick=True)
    assert text.startswith(f"## {dissipative.TITLE}")
    # 1e-12 and 0.1 au of a 2 au orbit
    for case in dissipative.PARITY_CASES:
        line = next(ln for ln in text.splitlines()
                    if ln.startswith("| `") and dissipative.PARITY_CASES[case][1] in ln
                    and dissipative.PARITY_CASES[case][2] in ln)
        assert "| 5.0e-13 | 5.0e-02 | 0.5 / 0.5 |" in line
    rate_cell = "| 2 yr | 2.002 yr | 1.00e-03 | nothing |"
    assert text.count(rate_cell) == len(dissipative.RATE_CASES)
    assert "| TidesConstantTimeLag | tides rate |" in text
    assert "agree to 5.0e-13 of the orbit" in text
    assert (tmp_path / "dissipative_parity.png").stat().st_size > 10_000
    assert not re.search(r"\bnan\b", text, re.IGNORECASE)
    assert "5.0e-13" in dissipative.summary_line(_fake_rows())


def test_a_failed_run_is_named_and_leaves_no_nan(tmp_path):
    text = dissipative.section(_fake_rows(broken=("tides-star", "orbits")), tmp_path,
                               quick=True)
    assert "tides-star, orbits: **NonFiniteState** made up" in text
    assert not re.search(r"\bnan\b", text, re.IGNORECASE)
    assert dissipative.summary_line(_fake_rows(broken=("radiation", "reboundx"))) == ""


def test_hut_rate_at_synchronous_spin_is_the_familiar_one():
    # at Omega = n, Hut's eq. 10 is -(21/2) k2 tau n^2 q (R / a)^5 e to O(e^2) = 1e-12
    e, n, a, k2, tau, R, m, M = 1e-6, 0.3, 0.05, 0.5, 0.01, 4.7e-4, 1e-3, 1.0
    expected = -10.5 * k2 * tau * n ** 2 * (M / m) * (R / a) ** 5 * e
    assert math.isclose(dissipative.hut_de_dt(e, n, a, k2, tau, R, m, M, n), expected,
                        rel_tol=1e-10)
    # without spin, -27 k2 tau n^2 q (R / a)^5 e
    assert math.isclose(dissipative.hut_de_dt(e, n, a, k2, tau, R, m, M, 0.0),
                        expected * 27 / 10.5, rel_tol=1e-10)


def test_quick_section_measures_parity_and_rates(tmp_path):
    pytest.importorskip("reboundx")
    rows = []
    for task in dissipative.tasks(quick=True):
        func = getattr(dissipative, task.function.split(":")[1])
        rows.append(func(**task.kwargs))
    assert all(r["outcome"] == "completed" for r in rows)
    for case in dissipative.PARITY_CASES:
        _, diff, effect, _ = dissipative.parity_series(rows, case)
        # the bound of tests/test_dissipative.py, as a fraction of the orbit
        # (measured at most 4.7e-12 after 200 orbits); each term moves the
        # orbit by 4.8e-4 of its size or more, eight orders above
        assert diff[-1] < 1e-8, case
        assert effect[-1] > 1e4 * 1e-8, case
    for r in (r for r in rows if r["kind"] == "rate"):
        for q in r["rows"]:
            # the bound of tests/test_dissipative.py (measured at most 1.2e-3)
            assert abs(q["measured"] / q["analytic"] - 1) < 0.01, q["what"]
    text = dissipative.section(rows, tmp_path, quick=True)
    assert not re.search(r"\bnan\b", text, re.IGNORECASE)
    assert "Hut's d ln e / dt, spin 0" in text
    assert "Migration" in dissipative.summary_line(rows)

"""How numbers look in the report's tables (never ``nan`` in a cell)."""

import math

__all__ = ["fmt_err", "fmt_count", "fmt_time", "outcome_cell", "ABBREVIATIONS"]

#: short names of the named failures, for map cells
ABBREVIATIONS = {
    "NonFiniteState": "NF",
    "StepSizeUnderflow": "SU",
    "ConvergenceFailure": "CF",
    "WallTimeExceeded": "WT",
    "CloseEncounter": "CE",
    "Escape": "ES",
    "IntegratorOptionError": "OPT",
}


def fmt_err(x):
    """An error in three significant digits; a dash where there is none."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if math.isinf(x):
        return "∞"
    if x == 0:
        return "0"
    return f"{x:.2e}"


def fmt_count(n):
    if n is None or (isinstance(n, float) and not math.isfinite(n)):
        return "–"
    return f"{int(n):,}"


def fmt_time(s):
    if s is None or not math.isfinite(s):
        return "–"
    return f"{s:.3g}"


def outcome_cell(row):
    """``completed``, or the named error (with a warning noted)."""
    text = row["outcome"]
    if row["outcome"] != "completed":
        text = f"**{row['outcome']}**"
    if row.get("warning"):
        kind = row["warning"].split(":", 1)[0]
        text += f" ({kind})"
    return text

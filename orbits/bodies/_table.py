"""The table a body set shows of itself, as text (its repr) and as HTML (Jupyter).

One row a body: its name, mass, radius where any body has one, and, for a
bound orbit, ``a``, ``e`` and ``inc`` about the centre of mass of the bodies
before it (the default primary of :meth:`~orbits.BodySet.elements`); a long
set shows its first and last rows.
"""

import html
import math

import numpy as np

from .. import epochs as _epochs
from ._elements import bound_elements

__all__ = ["text", "html_table", "REPR_ROWS"]

REPR_ROWS = 5  # rows a repr shows at each end of a long set


def _rows(bodies):
    """Header and rows (strings); None marks the rows left out."""
    n = len(bodies)
    if n > 2 * REPR_ROWS + 1:
        shown = [*range(REPR_ROWS), None, *range(n - REPR_ROWS, n)]
    else:
        shown = list(range(n))
    # point masses (every radius 0, the usual case) get no radius column
    sized = bool(np.any(bodies._r != 0))
    length = str(bodies.units.length)
    columns = (("mass", str(bodies.units.mass)),
               *((("radius", length),) if sized else ()), ("a", length))
    head = ["name", *(f"{label} [{unit}]" if unit else label for label, unit in columns),
            "e", "inc [deg]"]
    rows = []
    for i in shown:
        if i is None:
            rows.append(None)
            continue
        el = bound_elements(bodies, i)
        rows.append([bodies._names[i], f"{bodies._m[i]:.6g}",
                     *((f"{bodies._r[i]:.6g}",) if sized else ()),
                     *(("", "", "") if el is None else
                       (f"{el[0]:.6g}", f"{el[1]:.4g}", f"{math.degrees(el[2]):.4g}"))])
    return head, rows


def text(bodies):
    """The table as text, under a line that says the size and units of the set
    and, where it has one, its epoch."""
    head, rows = _rows(bodies)
    widths = [max(len(r[k]) for r in [head, *filter(None, rows)]) for k in range(len(head))]
    lines = [f"BodySet of {len(bodies)} bodies ({bodies.units.name}; a, e, inc about the "
             f"centre of mass of the bodies before each)"]
    if bodies.epoch is not None:
        lines.append(f"  epoch {_epochs.describe(bodies.epoch)}")
    for row in [head, *rows]:
        if row is None:
            lines.append(f"  ... {len(bodies) - 2 * REPR_ROWS} more ...")
        else:
            lines.append("  " + "  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip())
    return "\n".join(lines)


def html_table(bodies):
    """The table as an HTML fragment."""
    head, rows = _rows(bodies)

    def cells(row, tag):
        return "".join(f"<{tag}>{html.escape(c)}</{tag}>" for c in row)
    body = "".join(
        f"<tr><td colspan='{len(head)}'>&hellip; {len(bodies) - 2 * REPR_ROWS} more "
        f"&hellip;</td></tr>" if row is None else f"<tr>{cells(row, 'td')}</tr>"
        for row in rows)
    return (f"<div><strong>BodySet</strong> of {len(bodies)} bodies, units "
            f"{html.escape(bodies.units.name)} (G = {bodies.units.G!r})"
            f"<table><thead><tr>{cells(head, 'th')}</tr></thead><tbody>{body}</tbody>"
            f"</table><small>a, e, inc: osculating, about the centre of mass of the "
            f"bodies before each; blank where the orbit is not bound.</small></div>")

"""Text cells of the CSV files the package writes, safe to open in a spreadsheet.

A spreadsheet reads a cell that begins with ``=``, ``+``, ``-`` or ``@``, or
with a tab or a carriage return, as a formula: a body named
``=HYPERLINK("http://...")`` would become a live link, and worse formulas
run.  OWASP's rule against this "CSV injection" is to begin such a cell with a
single quote, which a spreadsheet shows as text.  A text cell that already
begins with a quote gets one more, so that :func:`read_cell` takes exactly one
away and every text reads back as it was.  Only text is treated so: a number
such as ``-1.5`` stays a number.

Examples
--------
>>> from orbits._csvcells import read_cell, safe_cell
>>> safe_cell("=HYPERLINK(0)"), safe_cell("-x"), safe_cell("Jupiter")
("'=HYPERLINK(0)", "'-x", 'Jupiter')
>>> [read_cell(safe_cell(t)) for t in ("=1+1", "'=1", "'tis", "@a")]
['=1+1', "'=1", "'tis", '@a']
"""

__all__ = ["FORMULA_START", "safe_cell", "read_cell"]

#: What a spreadsheet takes for the start of a formula (OWASP, "CSV Injection")
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")

_ESCAPED = FORMULA_START + ("'",)


def safe_cell(text):
    """``text`` with a single quote before it where a spreadsheet would take it
    for a formula, or where it begins with a quote itself.

    Parameters
    ----------
    text : str
        A cell's text, as the package has it.

    Returns
    -------
    str
        The cell as a file holds it.
    """
    return "'" + text if text.startswith(_ESCAPED) else text


def read_cell(text):
    """The text :func:`safe_cell` was given: one leading quote taken away where
    a formula start or another quote follows it (a quote before anything else,
    as in a hand-written ``'tis``, is kept).

    Parameters
    ----------
    text : str
        A cell as a file holds it (written by :func:`safe_cell`, or by hand).

    Returns
    -------
    str
        Its text.
    """
    return text[1:] if text[:1] == "'" and text[1:].startswith(_ESCAPED) else text

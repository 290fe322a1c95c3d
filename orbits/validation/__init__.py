"""The validation report: accuracy against REBOUND, work against precision,
long-horizon drift, a stress suite and a check of a published guide.

``orbits validate [--quick] [--out DIR]`` (or :func:`validate`) runs it on
this machine's cores and writes ``report.md`` with its PNG plots.  REBOUND is
needed (``pip install -e ".[test]"``), and matplotlib for the plots.
"""

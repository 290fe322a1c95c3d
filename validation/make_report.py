"""Make the committed validation report: ``validation/report/report.md`` and its plots.

The same as ``orbits validate --out validation/report`` (the measurements live
in the package, :mod:`orbits.validation`, so that any user can rerun them);
this script only fixes where the committed copy goes.

    python validation/make_report.py            # the full report (about ten minutes on 2 cores)
    python validation/make_report.py --quick    # a few minutes, into validation/report-quick
"""

import argparse
import pathlib

from orbits.validation import validate

HERE = pathlib.Path(__file__).resolve().parent


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--workers", type=int, default=None)
    args = ap.parse_args(argv)
    out = HERE / ("report-quick" if args.quick else "report")
    path = validate(out=out, quick=args.quick, n_workers=args.workers)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()

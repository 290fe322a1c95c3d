"""The documentation builds with warnings as errors (slow: it runs the gallery).

The build is the one the README gives; it writes into a temporary folder so
that a test run leaves ``docs/_build`` alone, and reaches no network.
"""

import importlib.util
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

pytestmark = pytest.mark.slow

_MISSING = [name for name in ("sphinx", "numpydoc", "sphinx_gallery", "furo")
            if importlib.util.find_spec(name) is None]


def _sphinx(builder, out, *flags):
    env = {k: v for k, v in os.environ.items() if k != "ORBITS_DOCS_INTERSPHINX"}
    return subprocess.run(
        [sys.executable, "-m", "sphinx", *flags, "-b", builder, str(DOCS), str(out)],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=1800)


@pytest.mark.skipif(bool(_MISSING), reason=f"needs the docs extra "
                    f"(pip install -e \".[docs]\"); missing: {', '.join(_MISSING)}")
def test_html_builds_without_warnings(tmp_path):
    out = tmp_path / "html"
    proc = _sphinx("html", out, "-W", "--keep-going", "-q")
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-8000:]
    for page in ("index.html", "tutorial.html", "api.html",
                 "guides/integrators.html", "auto_examples/index.html"):
        assert (out / page).is_file(), page


@pytest.mark.skipif(bool(_MISSING), reason=f"needs the docs extra "
                    f"(pip install -e \".[docs]\"); missing: {', '.join(_MISSING)}")
def test_code_on_the_pages_runs(tmp_path):
    # the tutorial's and the guides' ``.. doctest::`` blocks, as written
    proc = _sphinx("doctest", tmp_path / "doctest", "-q")
    assert proc.returncode == 0, proc.stdout[-8000:] + proc.stderr[-4000:]

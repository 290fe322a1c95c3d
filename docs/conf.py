"""Sphinx configuration of the orbits documentation.

Build (from the repository root, after ``pip install -e ".[docs]"``)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The default build reaches no network.  Links into the numpy, astropy, h5py
and Python documentation (intersphinx) need their inventories from the web:
set ``ORBITS_DOCS_INTERSPHINX=1`` to fetch them.
"""

import os
import pathlib
import shutil
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))    # the package of this checkout, installed or not

import orbits  # noqa: E402

project = "orbits"
author = "the orbits developers"
copyright = "the orbits developers"
release = orbits.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.doctest",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
]

templates_path = ["_templates"]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]
root_doc = "index"
default_role = "code"

# -- autodoc, autosummary, numpydoc --------------------------------------------------
# The API pages are made again at every build: a stub left from an older version of
# the package (a name since renamed or removed) would otherwise fail the build.
shutil.rmtree(HERE / "generated", ignore_errors=True)
autosummary_generate = True
autosummary_ignore_module_all = False     # a module's public names are its __all__
autosummary_imported_members = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"               # the numpydoc sections say the types and units
numpydoc_show_class_members = False       # the class template lists members itself
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# -- intersphinx: off by default, so that a build needs no network -------------------
intersphinx_mapping = {}
if os.environ.get("ORBITS_DOCS_INTERSPHINX", "") not in ("", "0"):
    intersphinx_mapping = {
        "python": ("https://docs.python.org/3", None),
        "numpy": ("https://numpy.org/doc/stable/", None),
        "astropy": ("https://docs.astropy.org/en/stable/", None),
        "h5py": ("https://docs.h5py.org/en/stable/", None),
    }
    intersphinx_timeout = 30

# -- sphinx-gallery --------------------------------------------------------------------
# Every example runs during the build.  The long ones take shorter arguments here
# (reset_argv, in _gallery_argv.py), so the build stays within a minute or two on a 2-core machine:
#   mercury_perihelion.py  four runs of 20 years instead of 100 (2.5 s; the rates
#                          still agree with theory to 0.01 arcsec per century)
#   resonant_migration.py  4000 years instead of 1e4 (1.9 s): the capture into 2:1
#                          and the libration are there, the long resonant migration not
#   hot_jupiter_tides.py   1500 orbits instead of 3000 (0.9 s): e falls to 0.05, not 0.02
#   poynting_robertson.py  600 years instead of 980 (0.6 s): the smallest grain reaches
#                          0.63 au, not 0.15 au
#                          (on a cold numba cache each of these three first compiles
#                          ias15 with its term: 15-25 s on a shared 2-core machine)
#   stability_map.py       an 8 x 8 grid to 3000 yr in this process (5.6 s) instead of
#                          40 x 40 to 5e4 yr on a Dask cluster; its page shows the
#                          committed picture of the full map, examples/stability_map.png,
#                          copied next to the page (copyfile_regex)
#   planetesimal_accretion.py  30 planetesimals for 60 years instead of 80 for 400
#                          (about 2 s); its page shows the committed picture
#   megno_map.py           a 10 x 5 grid to 3000 yr in this process instead of 48 x 24
#                          to 24 000 yr on a Dask cluster; its page likewise shows the
#                          committed examples/megno_map.png
sys.path.insert(0, str(HERE))   # for _gallery_argv, named by string (a cacheable config)

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/[a-z_]+\.py$",
    "reset_argv": "_gallery_argv.reset_argv",
    "ignore_pattern": r"__init__\.py",
    "copyfile_regex": r".*\.png$",
    "download_all_examples": False,
    "remove_config_comments": True,
    "min_reported_time": 1,
    "write_computation_times": False,
    "show_memory": False,
    "plot_gallery": "True",
    "capture_repr": (),
}

# A script that is not run has no figure for its thumbnail; sphinx-gallery keeps a
# thumbnail file that already exists, so the maps' committed pictures are
# made into their thumbnails here, before the gallery is generated.
def _thumbnail_from_picture(example, picture):
    from sphinx_gallery.utils import scale_image

    src = ROOT / "examples" / picture
    thumb = HERE / "auto_examples" / "images" / "thumb" / f"sphx_glr_{example}_thumb.png"
    if src.exists() and (not thumb.exists() or thumb.stat().st_mtime < src.stat().st_mtime):
        thumb.parent.mkdir(parents=True, exist_ok=True)
        scale_image(src, thumb, *sphinx_gallery_conf.get("thumbnail_size", (400, 280)))


_thumbnail_from_picture("stability_map", "stability_map.png")
_thumbnail_from_picture("megno_map", "megno_map.png")
_thumbnail_from_picture("planetesimal_accretion", "planetesimal_accretion.png")

# -- the table of integrators, made from the registry ---------------------------------
def _integrator_table():
    """``docs/_generated/integrators.inc``: every registered integrator, for the guide."""
    rows = []
    for info in orbits.integrators.available():
        integ = orbits.integrators.get(info.name)
        cls = type(integ)
        options = ", ".join(f"``{k}={v!r}``" for k, v in integ.config.items()) or "none"
        also = (" (also called " + ", ".join(f"``{a}``" for a in info.aliases) + ")"
                if info.aliases else "")
        rows.append((f":class:`{info.name} <{cls.__module__}.{cls.__name__}>`",
                     str(info.order), "yes" if info.symplectic else "no",
                     "yes" if info.adaptive else "no", options, info.summary + also))
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 12 6 9 8 25 40", "",
             "   * - name", "     - order", "     - symplectic", "     - adaptive",
             "     - options (defaults)", "     - what it is"]
    for row in rows:
        lines.append(f"   * - {row[0]}")
        lines.extend(f"     - {cell}" for cell in row[1:])
    text = "\n".join(lines) + "\n"
    out = HERE / "_generated" / "integrators.inc"
    out.parent.mkdir(exist_ok=True)
    if not out.exists() or out.read_text() != text:
        out.write_text(text)


_integrator_table()

# -- HTML -------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"orbits {release}"
html_static_path = []
html_show_sourcelink = False

# -- doctest builder (``-b doctest``) -------------------------------------------------
# only the pages' own ``.. doctest::`` blocks: the docstrings' examples run under pytest
doctest_test_doctest_blocks = ""
doctest_global_setup = """
import astropy.units as u
import numpy as np
import orbits
"""

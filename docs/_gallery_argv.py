"""The shorter arguments the documentation's build runs the long examples with."""

import os
import pathlib
import tempfile

__all__ = ["reset_argv", "QUICK_ARGV"]

QUICK_ARGV = {
    "mercury_perihelion.py": ["--years", "20"],
    "resonant_migration.py": ["--years", "4000", "--outputs", "1601"],
    "hot_jupiter_tides.py": ["--orbits", "1500", "--outputs", "301"],
    "poynting_robertson.py": ["--years", "600", "--outputs", "601"],
    "stability_map.py": ["--n", "8", "--until", "3000", "--scheduler", "serial",
                         "--png", os.path.join(tempfile.gettempdir(),
                                               "stability_map_quick.png")],
    "planetesimal_accretion.py": ["--n", "30", "--years", "60", "--outputs", "61",
                                  "--png", os.path.join(tempfile.gettempdir(),
                                                        "planetesimal_accretion_quick.png")],
    "megno_map.py": ["--n", "10", "--until", "3000", "--scheduler", "serial",
                     "--png", os.path.join(tempfile.gettempdir(), "megno_map_quick.png")],
}


def reset_argv(gallery_conf, script_vars):
    """sphinx-gallery's ``reset_argv``: the arguments an example is run with."""
    return list(QUICK_ARGV.get(pathlib.Path(script_vars["src_file"]).name, []))

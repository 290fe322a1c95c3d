"""The import-linter contracts in pyproject.toml: orbits._kernels never imports astropy;
orbits.io and orbits.records never import orbits.simulation; the kernel modules import
one another without cycles (function-local imports count); the modules of orbits.ensemble
import one way; and the package's layers, from the command line down to the kernels, each
module importing only from its own layer and those below (every module of orbits/ given a
layer)."""

import pathlib
import shutil
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_import_linter_contract():
    exe = shutil.which("lint-imports")
    assert exe is not None, "import-linter is missing: pip install -e '.[test]'"
    proc = subprocess.run([exe], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Kernels are free of astropy KEPT" in proc.stdout
    assert "Files and ensembles go through the simulation's public records KEPT" in proc.stdout
    assert "Kernels import one another without cycles KEPT" in proc.stdout
    assert "Ensemble modules import one way" in proc.stdout and "BROKEN" not in proc.stdout
    assert "The package's layers, from the command line down to the kernels KEPT" in proc.stdout

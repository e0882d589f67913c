"""Shared fixtures of the Python tests: the pfsph program and repository, small scenes."""
import copy
import os
import shutil

import pytest

ROOT = os.environ.get("PFSPH_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# A small 2D dam break (300 fluid particles, 10 frames): the program and the package run it.
COLUMN = {
    "name": "python column",
    "dimension": 2,
    "particle_radius": 0.01,
    "gravity": [0, -9.81],
    "domain": {"min": [-0.05, -0.05], "max": [0.85, 0.6]},
    "solver": {"type": "pcisph"},
    "time": {"end": 0.5, "fps": 20, "dt_max": 0.004},
    "seed": 3,
    "phases": [{"name": "water", "kind": "fluid", "rest_density": 1000, "viscosity": 1e-3},
               {"name": "wall", "kind": "solid"}],
    "fluid": [{"shape": "box", "min": [0, 0], "max": [0.3, 0.4], "phase": "water"}],
    "solids": [{"shape": "container", "min": [0, 0], "max": [0.8, 0.5], "open_top": True, "phase": "wall"}],
    "output": {"directory": "runs/python_column", "formats": ["vtp", "ply"], "fields": ["id", "speed"],
               "boundary": True},
}


@pytest.fixture
def column():
    return copy.deepcopy(COLUMN)


@pytest.fixture(scope="session")
def pfsph_bin():
    b = os.environ.get("PFSPH_BIN") or os.path.join(ROOT, "build", "pfsph")
    if not (os.path.isfile(b) and os.access(b, os.X_OK)):
        b = shutil.which("pfsph")
    if not b:
        pytest.skip("no pfsph program (set PFSPH_BIN)")
    return b


@pytest.fixture
def root():
    return ROOT

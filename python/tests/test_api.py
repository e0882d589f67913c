"""The binding itself: every function of include/pfsph.h is declared, the library loads."""
import os
import re

import numpy as np

import pfsph
from pfsph import _ffi


def test_every_header_function_is_declared(root):
    with open(os.path.join(root, "include", "pfsph.h")) as fh:
        header = fh.read()
    header = re.sub(r"/\*.*?\*/", "", header, flags=re.S)
    declared = set(re.findall(r"\b(pfsph_\w+)\s*\(", header))
    assert declared, "no functions found in the header"
    missing = sorted(n for n in declared if not hasattr(_ffi.lib, n))
    assert not missing, "declare them in pfsph/_ffi.py: %s" % missing


def test_version_precision_threads():
    assert re.match(r"\d+\.\d+\.\d+", pfsph.__version__)
    assert pfsph.real_dtype in ("float32", "float64")
    assert pfsph.threads() >= 1


def test_default_scene_runs_a_step():
    s = pfsph.default_scene()
    assert s["dimension"] == 3
    s["time"]["end"] = 0.01
    with pfsph.Simulation(s) as sim:
        n = len(sim.fluid)
        assert n > 0 and sim.dim == 3
        sim.step()
        assert sim.steps == 1 and sim.dt > 0 and sim.time == sim.dt
        assert sim.fluid.positions.dtype == np.dtype(pfsph.real_dtype)
        assert sim.stats["n_fluid"] == n


def test_field_names_and_bad_field(column):
    sim = pfsph.Simulation(column)
    assert sim.fluid.field_names == ("position", "velocity", "density", "pressure", "phase", "id", "film", "bubble")
    assert sim.boundary.field_names == ("position", "velocity", "volume", "phase", "id", "wall")
    assert sim.boundary.volume.shape == (len(sim.boundary),)
    try:
        sim.fluid.field("temperature")
    except pfsph.InputError as e:
        assert "temperature" in str(e) and "position" in str(e)
    else:
        raise AssertionError("no error for an unknown field")
    try:
        sim.fluid.nonsense
    except AttributeError as e:
        assert "nonsense" in str(e)
    else:
        raise AssertionError("no AttributeError")

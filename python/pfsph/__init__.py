"""pfsph, a particle fluid simulator (SPH), from Python: scenes as dicts, simulations stepped by
the C library (include/pfsph.h, through cffi), particle fields as numpy arrays over the
library's memory, run directories read back. Guide: docs/python.md.

    import pfsph
    sim = pfsph.Simulation("scenes/dam_break_2d.json")
    sim.advance(0.5)
    x = sim.fluid.positions          # (n, 3), read-only view
    run = pfsph.read_run("runs/dam_break_2d")
"""
from ._ffi import ffi as _cffi, lib as _clib, library_path
from .errors import (Error, InputError, SceneError, UnstableError, InterruptedRun, PfsphIOError, PfsphMemoryError)
from .simulation import Simulation, ParticleSet, Body, set_threads, threads
from .rundir import Run, Frame, read_run, read_frame

__version__ = _cffi.string(_clib.pfsph_version()).decode()
#: numpy dtype of the library's real-valued fields (float32, or float64 in a PFSPH_DOUBLE build)
real_dtype = "float64" if _clib.pfsph_real_type() == _clib.PFSPH_FLOAT64 else "float32"


def default_scene():
    """The built-in default scene (a small 3D dam break) as a dict."""
    import json
    return json.loads(_cffi.string(_clib.pfsph_scene_default_json()).decode())


__all__ = ["Simulation", "ParticleSet", "Body", "Run", "Frame", "read_run", "read_frame", "set_threads", "threads",
           "default_scene", "library_path", "Error", "InputError", "SceneError", "UnstableError", "InterruptedRun", "PfsphIOError",
           "PfsphMemoryError", "real_dtype", "__version__"]

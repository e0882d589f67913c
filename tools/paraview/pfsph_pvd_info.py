# What ParaView makes of a pfsph .pvd collection (run with pvpython): time steps, point and cell
# arrays, sizes at the last step, as one JSON line.  pvpython pfsph_pvd_info.py RUN/fluid.pvd
import json
import sys

from paraview.simple import PVDReader

r = PVDReader(FileName=sys.argv[1])
r.UpdatePipelineInformation()
steps = r.TimestepValues
steps = list(steps) if hasattr(steps, "__len__") else [steps]
r.UpdatePipeline(steps[-1] if steps else 0.0)
info = r.GetDataInformation()
print("pfsph_pvd_info: " + json.dumps({
    "steps": len(steps), "times": [float(t) for t in steps],
    "point_arrays": sorted(r.PointData.keys()), "cell_arrays": sorted(r.CellData.keys()),
    "points": int(info.GetNumberOfPoints()), "cells": int(info.GetNumberOfCells())}, sort_keys=True))

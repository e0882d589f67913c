"""The package runs what `pfsph run` runs: positions after advance(t) equal the program's frame
at t (by id, bit for bit), write_frame writes the program's bytes, read_run reads them back."""
import filecmp
import json
import os
import subprocess

import numpy as np
import pytest

import pfsph
from conftest import COLUMN


@pytest.fixture(scope="module")
def program_run(pfsph_bin, tmp_path_factory):
    """The column run by the program once for this module's tests: (scene file, run dir)."""
    tmp = tmp_path_factory.mktemp("program")
    path = tmp / "column.json"
    path.write_text(json.dumps(COLUMN))
    out = tmp / "run"
    subprocess.run([pfsph_bin, "run", str(path), "-o", str(out), "--quiet"], check=True)
    return path, out


def _by_id(ids, *arrays):
    order = np.argsort(ids)
    return [ids[order]] + [a[order] for a in arrays]


def test_positions_equal_the_programs_frame(program_run):
    path, out = program_run
    run = pfsph.read_run(out)
    assert run.summary["status"] == "finished"
    assert run.frame_numbers() == list(range(11))
    sim = pfsph.Simulation(str(path))
    for t, k in ((0.25, 5), (0.5, 10)):
        sim.advance(t)
        assert sim.time == t and sim.frame == k
        frame = run.frame(k)
        assert frame.time == t
        ids, pos, vel = _by_id(sim.fluid.ids, sim.fluid.positions, sim.fluid.velocities)
        fids, fpos, fvel = _by_id(frame["id"], frame["position"], frame["velocity"])
        assert np.array_equal(ids, fids)
        assert np.array_equal(pos, fpos), "max difference %g m" % np.abs(pos - fpos).max()
        assert np.array_equal(vel, fvel)
        # the steps as the program's stats.csv counts them
        assert sim.steps == run.stats["steps"][k]
    # and the clock: a straight advance lands on other step sizes (documented): not equal
    other = pfsph.Simulation(str(path)).advance(0.5, land_on_frames=False)
    assert other.time == 0.5 and other.steps != sim.steps


def test_write_frame_writes_the_programs_bytes(program_run, tmp_path):
    path, out = program_run
    mine = tmp_path / "mine"
    sim = pfsph.Simulation(str(path))
    written = [sim.write_frame(mine) for k in sim.frames(0.25)]
    assert written == [0, 1, 2, 3, 4, 5]
    for k in written:
        for name in ("fluid_%05d.vtp" % k, "fluid_%05d.ply" % k):
            assert filecmp.cmp(mine / "frames" / name, out / "frames" / name, shallow=False), name
    for name in ("boundary_00000.vtp", "boundary_00000.ply"):
        assert filecmp.cmp(mine / "frames" / name, out / "frames" / name, shallow=False)
    assert not (mine / "frames" / "boundary_00001.vtp").exists()  # the program's choice: frame 0 only
    # the .pvd collections list the frames written so far
    assert (mine / "fluid.pvd").exists()


def test_read_run(program_run):
    path, out = program_run
    run = pfsph.read_run(out)
    assert run.scene == json.loads(path.read_text())
    assert run.run["end_time"] == 0.5
    st = run.stats
    assert list(st["frame"]) == list(range(11))
    assert st["time"][4] == pytest.approx(0.2)
    assert st["n_fluid"].dtype.kind == "i" and st["vmax"].dtype.kind == "f"
    vtp = pfsph.read_frame(str(out / "frames" / "fluid_00007.vtp"))
    ply = pfsph.read_frame(str(out / "frames" / "fluid_00007.ply"))
    assert vtp.time == ply.time == pytest.approx(0.35)
    for key in ("position", "velocity", "density", "pressure", "phase", "id", "speed"):
        assert np.array_equal(vtp[key], ply[key]), key
    assert vtp["position"].shape == (300, 3) and vtp["id"].dtype == np.uint32
    b = run.frame(0, "boundary")
    assert "volume" in b and len(b) > 0
    ks = [k for k, f in run.frames()]
    assert ks == run.frame_numbers()
    assert run.frame(-1).time == pytest.approx(0.5)
    with pytest.raises(FileNotFoundError):
        run.frame(99)
    by = vtp.by_id()
    assert np.all(np.diff(by["id"].astype(np.int64)) > 0)


def test_callback_per_frame(column):
    sim = pfsph.Simulation(column)
    seen = []
    sim.advance(0.2, callback=lambda s, k: seen.append((k, s.time, len(s.fluid.positions))))
    assert [k for k, _, _ in seen] == [1, 2, 3, 4]
    assert [t for _, t, _ in seen] == [k / 20 for k in (1, 2, 3, 4)]
    # off a frame time, then on: the frame index follows the clock
    sim.advance(0.23)
    assert sim.frame == 4 and sim.time == 0.23
    assert list(sim.frames(0.3)) == [5, 6]

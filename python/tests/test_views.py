"""Particle fields as numpy arrays over the library's memory: views, not copies; read-only;
taken afresh after each grid sort; never dangling (the memory lives while an array views it);
copies where a step reallocates; writes between steps."""
import gc
import weakref

import numpy as np
import pytest

import pfsph
from pfsph._ffi import ffi


def _c_address(sim, set_name, field, k=0):
    f = getattr(sim, set_name)._field(field)
    return int(ffi.cast("uintptr_t", f.data[k]))


def test_fields_are_read_only_views(column):
    sim = pfsph.Simulation(column)
    n = len(sim.fluid)
    for name, k, arr in (("position", 0, sim.fluid.x), ("position", 2, sim.fluid.z), ("velocity", 1, sim.fluid.vy),
                         ("density", 0, sim.fluid.density), ("pressure", 0, sim.fluid.pressure),
                         ("id", 0, sim.fluid.ids), ("phase", 0, sim.fluid.phase)):
        assert arr.shape == (n,)
        assert not arr.flags.owndata and not arr.flags.writeable
        assert arr.__array_interface__["data"][0] == _c_address(sim, "fluid", name, k), name
    assert np.shares_memory(sim.fluid.density, sim.fluid.density)  # two accesses, one memory
    with pytest.raises(ValueError):
        sim.fluid.density[0] = 1.0
    x, y, z = sim.fluid.components("position")
    p = sim.fluid.positions  # (n, 3): a copy of the three arrays
    assert p.flags.owndata and not p.flags.writeable
    assert np.array_equal(p, np.stack([x, y, z], axis=1))
    assert sim.fluid.zero_copy and sim.boundary.zero_copy and not sim.diffuse.zero_copy
    assert len(sim.diffuse) == 0 and sim.diffuse.positions.shape == (0, 3)


def test_arrays_survive_the_grid_sort(column):
    sim = pfsph.Simulation(column)
    ids_view, x_view = sim.fluid.ids, sim.fluid.x
    ids0, pos0 = sim.fluid.ids.copy(), sim.fluid.positions
    sim.advance(0.3)  # the column collapses: the sort reorders the particles
    ids1, pos1 = sim.fluid.ids, sim.fluid.positions
    assert not np.array_equal(ids0, ids1), "the order did not change: the test shows nothing"
    assert sorted(ids0) == sorted(ids1)
    # an array taken before the steps views the same memory: the particles in their new order
    assert np.array_equal(ids_view, ids1) and np.array_equal(x_view, sim.fluid.x)
    # matched by id, each particle moved by what its speed allows, not by a reshuffle
    o0, o1 = np.argsort(ids0), np.argsort(ids1)
    moved = np.linalg.norm(pos1[o1] - pos0[o0], axis=1)
    assert moved.max() < 0.3 * 0.3 * 9.81 * 2 and moved.max() > 0.01
    # the fluid falls, so fresh arrays agree with the clock
    assert sim.fluid.y.mean() < pos0[:, 1].mean()


def test_views_keep_the_memory_alive(column):
    sim = pfsph.Simulation(column)
    sim.advance(0.1)
    y = sim.fluid.y
    expect = y.copy()
    handle = weakref.ref(sim._handle)
    sim.close()
    del sim
    gc.collect()
    assert handle() is not None, "freed while an array views it"
    junk = [np.ones(len(expect), np.float32) * 7 for _ in range(50)]  # reuse of freed memory would show
    assert np.array_equal(y, expect)
    del y, junk
    gc.collect()
    assert handle() is None, "not freed after the last view went"


def test_closed_simulation_refuses(column):
    sim = pfsph.Simulation(column)
    sim.close()
    with pytest.raises(pfsph.Error):
        sim.step()
    with pytest.raises(pfsph.Error):
        sim.fluid.x


def test_growing_sets_are_copies():
    # an emitter adds fluid during steps (its arrays grow): copies, never views
    scene = {"dimension": 2, "particle_radius": 0.01, "gravity": [0, -9.81],
             "domain": {"min": [-0.05, -0.05], "max": [0.45, 0.6]}, "time": {"end": 0.2, "fps": 20},
             "phases": [{"name": "water", "kind": "fluid"}, {"name": "wall", "kind": "solid"}],
             "solids": [{"shape": "container", "min": [0, 0], "max": [0.4, 0.5], "open_top": True, "phase": "wall"}],
             "emitters": [{"shape": "segment", "phase": "water", "center": [0.2, 0.4], "width": 0.06,
                           "direction": [0, -1], "speed": 1.0}]}
    sim = pfsph.Simulation(scene)
    assert not sim.fluid.zero_copy
    sim.advance(0.1)
    n = len(sim.fluid)
    assert n > 0
    x = sim.fluid.x
    assert x.flags.owndata and not x.flags.writeable and len(x) == n
    sim.advance(0.2)
    assert len(sim.fluid) > n and len(x) == n


def test_set_velocities_between_steps(column):
    sim = pfsph.Simulation(column)
    sim.advance(0.1)
    v = sim.fluid.velocities
    v2 = v + np.array([0.5, 0, 0], np.float32)
    sim.fluid.velocities = v2
    assert np.array_equal(sim.fluid.velocities, v2.astype(np.float32))
    ids = sim.fluid.ids.copy()
    sim.step()
    # the kick shows in the next step's speeds (the time step follows them)
    assert sim.stats["vmax"] > np.linalg.norm(v, axis=1).max() + 0.3
    # bad values: an error naming the particle, the old values back
    before = sim.fluid.velocities
    bad = before.copy()
    bad[3, 0] = np.nan
    with pytest.raises(pfsph.InputError) as ei:
        sim.fluid.velocities = bad
    assert "not finite" in str(ei.value) and "id %d" % sim.fluid.ids[3] in str(ei.value)
    assert np.array_equal(sim.fluid.velocities, before)
    with pytest.raises(pfsph.InputError):
        sim.fluid.velocities = before[:-1]
    with pytest.raises(pfsph.InputError):
        sim.boundary.set(velocities=sim.boundary.velocities)
    zbad = sim.fluid.positions.copy()
    zbad[0, 2] = 0.1  # z in a 2D scene
    with pytest.raises(pfsph.InputError):
        sim.fluid.positions = zbad
    sim.step()
    assert sorted(ids) == sorted(sim.fluid.ids)


def test_set_positions_removes_fluid_moved_out(column):
    sim = pfsph.Simulation(column)
    p = sim.fluid.positions.copy()
    n = len(p)
    p[:10, 0] = 5.0  # far outside the domain
    sim.fluid.positions = p
    sim.step()
    assert len(sim.fluid) == n - 10 and sim.stats["n_removed"] == 10

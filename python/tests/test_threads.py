"""Threads: OpenMP's count as set from Python in whichever thread steps; separate simulations
in separate threads; one simulation refuses a second stepper; Ctrl-C between steps."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import pfsph
from pfsph._ffi import lib


def _by_id(sim):
    o = np.argsort(sim.fluid.ids)
    return sim.fluid.positions[o]


def test_thread_count_applies_in_the_stepping_thread(column):
    sim = pfsph.Simulation(column)
    seen = []

    def worker():
        sim.step()
        seen.append(lib.pfsph_threads(0))  # what OpenMP gives this thread's regions now

    try:
        assert pfsph.set_threads(1) == 1
        th = threading.Thread(target=worker)
        th.start()
        th.join()
        assert seen == [1]
    finally:
        pfsph.set_threads(None)
    assert pfsph.threads() >= 1
    with pytest.raises(pfsph.InputError):
        pfsph.set_threads(0)


def test_two_simulations_in_two_threads(column):
    ref = _by_id(pfsph.Simulation(column).advance(0.15))
    out = [None, None]

    def run(i):
        out[i] = _by_id(pfsph.Simulation(column).advance(0.15))

    ths = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for th in ths:
        th.start()
    for th in ths:
        th.join()
    assert np.array_equal(out[0], ref) and np.array_equal(out[1], ref)


def test_one_simulation_one_stepper(column):
    sim = pfsph.Simulation(column)
    errors = []
    started = threading.Event()

    def first():
        sim.advance(0.2, callback=lambda s, k: (started.set(), time.sleep(0.05)))

    th = threading.Thread(target=first)
    th.start()
    started.wait(30)
    # the callback runs between frames with the simulation free; catch it stepping instead
    deadline = time.time() + 10
    while th.is_alive() and time.time() < deadline:
        try:
            sim.step()
        except pfsph.Error as e:
            errors.append(str(e))
            break
    th.join()
    assert errors and "another thread" in errors[0]


def test_ctrl_c_stops_between_steps(column):
    """SIGINT during advance raises KeyboardInterrupt at a step's end; the simulation goes on
    from there to the same particles as an uninterrupted run."""
    sim = pfsph.Simulation(column)
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.advance(0.5)
    finally:
        timer.cancel()
    t = sim.time
    assert 0 < t < 0.5
    sim.advance(0.5)
    ref = pfsph.Simulation(column).advance(0.5)
    assert sim.steps == ref.steps
    assert np.array_equal(_by_id(sim), _by_id(ref))

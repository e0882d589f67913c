"""Simulation: a scene (dict or file) stepped by the C library, its particle fields as numpy
arrays that view the library's own memory. Design and lifetimes: docs/python.md."""
import collections
import json
import math
import os
import threading

import numpy as np

from . import errors
from ._ffi import ffi, lib

_DTYPES = {lib.PFSPH_FLOAT32: np.dtype("<f4"), lib.PFSPH_FLOAT64: np.dtype("<f8"),
           lib.PFSPH_UINT8: np.dtype("u1"), lib.PFSPH_UINT32: np.dtype("<u4")}

_default_threads = None
_initial_threads = lib.pfsph_threads(0)  # OpenMP's own count, for set_threads(None)


def set_threads(n):
    """OpenMP threads of every simulation's steps from now on, in whichever Python thread
    steps it (OpenMP's setting is per calling thread: pfsph applies it before each step).
    None: OpenMP's own choice ($OMP_NUM_THREADS, else every core). Returns the count."""
    global _default_threads
    _default_threads = None if n is None else int(n)
    if _default_threads is not None and _default_threads < 1:
        raise errors.InputError("threads: %d; at least 1, or None for OpenMP's own" % _default_threads)
    return lib.pfsph_threads(_default_threads or _initial_threads)


def threads():
    """The OpenMP threads a step started from this Python thread gets."""
    return lib.pfsph_threads(_default_threads or 0)


def _check(rc, err, scene=False):
    if rc != lib.PFSPH_OK:
        raise errors.from_code(rc, ffi.string(err.msg).decode("utf-8", "replace"), scene)


def _tol(t):
    # pfsph_sim_advance's own tolerance (src/sim.c): frame times are sums of doubles
    return 1e-12 * max(1.0, abs(t))


class _Handle:
    """Owns the C simulation. The Simulation and every array viewing its memory hold it, so
    the memory is freed when the last of them goes (close() only drops the Simulation's)."""

    __slots__ = ("ptr", "__weakref__")

    def __init__(self, ptr):
        self.ptr = ptr

    def __del__(self):
        if self.ptr is not None and lib is not None:
            lib.pfsph_sim_free(self.ptr)
            self.ptr = None


class _View:
    """The base object of a numpy array over C memory: numpy takes the address, type and
    shape from __array_interface__ and keeps this object (and through it the handle) alive."""

    __slots__ = ("__array_interface__", "_handle")

    def __init__(self, handle, addr, dtype, shape, strides, readonly):
        self._handle = handle
        self.__array_interface__ = {"version": 3, "data": (addr, readonly), "typestr": dtype.str,
                                    "shape": shape, "strides": strides}


def _addr(p):
    return int(ffi.cast("uintptr_t", p))


Body = collections.namedtuple("Body", "name position orientation velocity angular_velocity")
Body.__doc__ = """A rigid body's state, world frame: centre of mass position [m], unit quaternion
orientation (w, x, y, z), velocity [m/s], angular velocity [rad/s] (numpy arrays, copies)."""


class ParticleSet:
    """One particle set of a simulation ("fluid", "boundary" or "diffuse"): its fields as numpy
    arrays, taken afresh at every attribute access (the grid sort reorders particles every step:
    match them across steps by ``ids``).

    Zero-copy: the arrays view the library's structure-of-arrays storage (read-only) where a
    step cannot reallocate it: the boundary set, and the fluid of scenes without emitters. The
    diffuse set, and the fluid of a scene with emitters, grow during steps (their memory moves):
    they are given as copies (``zero_copy`` is False), so no array ever views freed memory.
    An array taken before a step still views the set's memory after it: the same slots, now in
    the new order, and its length is the count when it was taken (take it again). The library
    stores the three components of a vector in three arrays: ``positions`` and ``velocities``
    are (n, 3) copies (12 bytes a particle in single precision); ``x``, ``y``, ``z``, ``vx``,
    ``vy``, ``vz`` and ``components(name)`` are the views."""

    def __init__(self, sim, name):
        self._sim = sim
        self.name = name
        self.field_names = tuple(ffi.string(p).decode() for p in _names(name))

    @property
    def zero_copy(self):
        """Whether the arrays view the library's memory (True) or are copies (False)."""
        if self.name == "boundary":
            return True
        if self.name == "diffuse":
            return False
        return not self._sim._has_emitters

    def __len__(self):
        n = ffi.new("size_t *")
        err = ffi.new("pfsph_error *")
        _check(lib.pfsph_sim_count(self._sim._ptr, self.name.encode(), n, err), err)
        return int(n[0])

    def _field(self, name, write=False):
        f = ffi.new("pfsph_field *")
        err = ffi.new("pfsph_error *")
        fn = lib.pfsph_sim_field_write if write else lib.pfsph_sim_field
        _check(fn(self._sim._ptr, self.name.encode(), name.encode(), f, err), err)
        return f

    def _component(self, f, k, writable=False):
        dtype = _DTYPES[f.type]
        n = int(f.count)
        if n == 0:
            a = np.empty(0, dtype)
            a.flags.writeable = writable
            return a
        a = np.asarray(_View(self._sim._handle, _addr(f.data[k]), dtype, (n,), (int(f.stride),),
                             not writable))
        if not writable and not self.zero_copy:
            a = a.copy()
            a.flags.writeable = False
        return a

    def field(self, name):
        """Field ``name`` (one of ``field_names``): 1 component as an (n,) array (a view where the
        set is zero-copy), 3 as an (n, 3) copy."""
        f = self._field(name)
        if f.components == 1:
            return self._component(f, 0)
        return self._vector(f)

    def components(self, name):
        """The three component arrays (x, y, z) of a 3-component field, each a view where the set
        is zero-copy."""
        f = self._field(name)
        return tuple(self._component(f, k) for k in range(f.components))

    def _vector(self, f):
        # the library keeps x, y and z in three separate arrays (structure of arrays): an (n, 3)
        # array of them is a copy, always (a view only when the three happened to lie equally
        # spaced would make a snapshot sometimes and a live view other times)
        a = np.empty((int(f.count), 3), _DTYPES[f.type])
        for k in range(3):
            if f.count:
                a[:, k] = self._component(f, k)
        a.flags.writeable = False
        return a

    # the fields by their Python names (docs/python.md lists them per set)
    positions = property(lambda self: self.field("position"), doc="(n, 3) positions [m] (z = 0 in 2D), a copy")
    velocities = property(lambda self: self.field("velocity"), doc="(n, 3) velocities [m/s], a copy")
    ids = property(lambda self: self.field("id"), doc="(n,) uint32 particle ids, stable across steps")
    phase = property(lambda self: self.field("phase" if self.name != "diffuse" else "type"),
                     doc="(n,) uint8 phase index in the scene's phases (diffuse: type 0 spray, 1 foam, 2 bubble)")
    density = property(lambda self: self.field("density"), doc="(n,) density [kg/m^3] (fluid)")
    pressure = property(lambda self: self.field("pressure"), doc="(n,) pressure [Pa] (fluid)")
    x = property(lambda self: self.components("position")[0])
    y = property(lambda self: self.components("position")[1])
    z = property(lambda self: self.components("position")[2])
    vx = property(lambda self: self.components("velocity")[0])
    vy = property(lambda self: self.components("velocity")[1])
    vz = property(lambda self: self.components("velocity")[2])

    def __getattr__(self, name):
        # the other fields by their C names: film, bubble, volume, wall, lifetime, type
        if name.startswith("_") or name not in self.__dict__.get("field_names", ()):
            raise AttributeError("%s set has no attribute %r (fields: %s)" % (
                self.__dict__.get("name"), name, ", ".join(self.__dict__.get("field_names", ()))))
        return self.field(name)

    @positions.setter
    def positions(self, value):
        self.set(positions=value)

    @velocities.setter
    def velocities(self, value):
        self.set(velocities=value)

    def set(self, positions=None, velocities=None):
        """Write the fluid's positions and/or velocities ((n, 3) arrays, in the current order:
        read ``ids`` first) between steps: a user's own forcing. The library checks them
        (finite; z = 0 in 2D) and makes the next time step follow the new speeds; the next
        step's grid sort sees the new positions (fluid moved out of the domain is removed
        there). Bad values raise InputError and the old values are put back."""
        if self.name != "fluid":
            raise errors.InputError("%s: not writable; the fluid's positions and velocities are" % self.name)
        sim = self._sim
        sim._check_open()
        n = len(self)
        new = {}
        for key, value in (("position", positions), ("velocity", velocities)):
            if value is None:
                continue
            v = np.asarray(value, dtype=np.float64)
            if v.shape != (n, 3):
                raise errors.InputError("fluid %s: expected shape (%d, 3), got %s" % (key, n, v.shape))
            new[key] = v
        old = {}
        for key, v in new.items():
            f = self._field(key, write=True)
            comps = [self._component(f, k, writable=True) for k in range(3)]
            old[key] = [c.copy() for c in comps]
            for k in range(3):
                comps[k][:] = v[:, k]
        err = ffi.new("pfsph_error *")
        rc = lib.pfsph_sim_fields_written(sim._ptr, err)
        if rc != lib.PFSPH_OK:
            for key, saved in old.items():
                f = self._field(key, write=True)
                for k in range(3):
                    self._component(f, k, writable=True)[:] = saved[k]
            _check(rc, err)

    def __repr__(self):
        return "<pfsph ParticleSet %s: %d particles>" % (self.name, len(self))


def _names(set_name):
    out = []
    i = 0
    while True:
        p = lib.pfsph_field_name(set_name.encode(), i)
        if p == ffi.NULL:
            return out
        out.append(p)
        i += 1


class Simulation:
    """A pfsph simulation.

    ``scene`` is the JSON scene as Python data (a dict, docs/scene-format.md) or the path of a
    scene file. A scene that does not load raises SceneError, carrying the message and the JSON
    path as ``pfsph run`` prints them. ``source`` names a dict scene in messages and is the
    file whose directory relative paths (meshes) resolve against (default: ``<scene>`` in the
    working directory). ``threads``: OpenMP threads of this simulation's steps (default:
    ``pfsph.set_threads``, else OpenMP's own).

    The particles are prepared as ``pfsph run`` prepares its frame 0. ``advance(t)`` lands on
    every frame time k / fps of the scene on its way, as the program does, so the particles at
    a frame time equal the program's frame. One simulation must not be stepped from two Python
    threads at once; separate simulations may be. Steps release the GIL."""

    def __init__(self, scene, *, source=None, threads=None):
        err = ffi.new("pfsph_error *")
        sp = ffi.new("pfsph_scene **")
        if isinstance(scene, (str, bytes, os.PathLike)):
            path = os.fsencode(scene)
            _check(lib.pfsph_scene_new_file(sp, path, err), err, scene=True)
            with open(path, "rb") as fh:
                self._scene_data = json.loads(fh.read().decode("utf-8", "replace") or "null")
        else:
            text = json.dumps(scene)
            src = ffi.NULL if source is None else os.fsencode(source)
            _check(lib.pfsph_scene_new_json(sp, text.encode(), src, err), err, scene=True)
            self._scene_data = json.loads(text)
        simp = ffi.new("pfsph_sim **")
        try:
            rc = lib.pfsph_sim_new(simp, sp[0], err)
        finally:
            lib.pfsph_scene_free(sp[0])
        _check(rc, err, scene=True)
        self._handle = _Handle(simp[0])
        self._threads = threads
        self._busy = threading.RLock()  # one stepping thread; a callback may step
        scene_c = lib.pfsph_sim_scene(simp[0])
        self.fps = lib.pfsph_scene_fps(scene_c)
        self.end_time = lib.pfsph_scene_end_time(scene_c)
        self.name = ffi.string(lib.pfsph_scene_name(scene_c)).decode("utf-8", "replace")
        self.dim = lib.pfsph_sim_dim(simp[0])
        em = self._scene_data.get("emitters") if isinstance(self._scene_data, dict) else None
        self._has_emitters = bool(em)
        self._next_frame = int(math.floor(self.time * self.fps + 1e-9)) + 1
        self.fluid = ParticleSet(self, "fluid")
        self.boundary = ParticleSet(self, "boundary")
        self.diffuse = ParticleSet(self, "diffuse")

    # ---- life ----

    @property
    def _ptr(self):
        if self._handle is None:
            raise errors.Error("the simulation is closed")
        return self._handle.ptr

    def _check_open(self):
        return self._ptr

    def close(self):
        """Free the simulation now, unless arrays still view its memory: then when the last of
        them goes. The Simulation is unusable afterwards."""
        self._handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @property
    def scene(self):
        """The scene as given (a dict; parsed from the file for a path)."""
        return self._scene_data

    # ---- clock ----

    time = property(lambda self: lib.pfsph_sim_time(self._ptr), doc="simulated time [s]")
    dt = property(lambda self: lib.pfsph_sim_dt(self._ptr), doc="the last step's time step [s] (0 before one)")
    steps = property(lambda self: int(lib.pfsph_sim_steps(self._ptr)), doc="steps taken")

    @property
    def frame(self):
        """Index of the last frame time k / fps the simulation reached."""
        return self._next_frame - 1

    @property
    def stats(self):
        """Figures of the last step (pfsph_stats) as a dict."""
        st = ffi.new("pfsph_stats *")
        lib.pfsph_sim_stats_get(self._ptr, st)
        return {k: getattr(st, k) for k in ("time", "dt", "steps", "n_fluid", "n_boundary", "n_diffuse", "n_removed",
                                             "vmax", "density_err_avg", "density_err_max", "ekin", "iterations",
                                             "div_iterations")}

    # ---- stepping ----

    def _c_step(self, ptr, t_limit, err):
        n = self._threads if self._threads is not None else _default_threads
        if n:
            lib.pfsph_threads(n)  # OpenMP's count is per calling thread
        _check(lib.pfsph_sim_step(ptr, t_limit, err), err)

    def _land(self, ptr, t, err):
        # step by step (Ctrl-C is seen between steps), with pfsph_sim_advance's own test; the
        # advance then only lands the clock on t, as `pfsph run` does for each frame
        while lib.pfsph_sim_time(ptr) < t - _tol(t):
            self._c_step(ptr, t, err)
        _check(lib.pfsph_sim_advance(ptr, t, err), err)

    def _guard(self):
        if not self._busy.acquire(blocking=False):
            raise errors.Error("the simulation is being stepped by another thread (one stepper at a time)")

    def step(self, t_limit=None):
        """One time step, never past ``t_limit`` [s] (default: the next frame time, so that
        steps and advance() keep the program's step sizes). Raises UnstableError on a blow-up."""
        ptr = self._ptr
        self._guard()
        try:
            err = ffi.new("pfsph_error *")
            tf = self._next_frame / self.fps
            self._c_step(ptr, tf if t_limit is None else min(t_limit, tf), err)
            if lib.pfsph_sim_time(ptr) >= tf - _tol(tf):
                _check(lib.pfsph_sim_advance(ptr, tf, err), err)
                self._next_frame += 1
        finally:
            self._busy.release()

    def advance(self, t_end=None, *, callback=None, land_on_frames=True):
        """Advance to time ``t_end`` [s] exactly (default: the scene's end), landing on every
        frame time k / fps on the way as ``pfsph run`` does (``land_on_frames=False``: straight
        to t_end, as pfsph_sim_advance; other step sizes). ``callback(sim, frame)`` is called at
        each frame time reached. Steps one at a time, so Ctrl-C (KeyboardInterrupt) stops
        between two steps and leaves a usable simulation. Returns self."""
        t_end = self.end_time if t_end is None else float(t_end)
        ptr = self._ptr
        self._guard()
        try:
            err = ffi.new("pfsph_error *")
            if land_on_frames:
                while self._next_frame / self.fps <= t_end + _tol(t_end):
                    tf = self._next_frame / self.fps
                    self._land(ptr, tf, err)
                    self._next_frame += 1
                    if callback is not None:
                        callback(self, self._next_frame - 1)
            if lib.pfsph_sim_time(ptr) < t_end - _tol(t_end):
                self._land(ptr, t_end, err)
            self._next_frame = max(self._next_frame, int(math.floor(self.time * self.fps + 1e-9)) + 1)
        finally:
            self._busy.release()
        return self

    def frames(self, t_end=None, every=1):
        """Generator: steps to each frame time up to ``t_end`` (default: the scene's end) and
        yields the frame index, starting with the current frame when the simulation sits on
        one; every ``every``-th frame. ``for k in sim.frames(): sim.write_frame(d)`` writes
        what ``pfsph run`` writes in its frames/."""
        t_end = self.end_time if t_end is None else float(t_end)
        k = self.frame
        if abs(self.time - k / self.fps) <= _tol(self.time) and k % every == 0:
            yield k
        while (self._next_frame) / self.fps <= t_end + _tol(t_end):
            self.advance(self._next_frame / self.fps)
            if self.frame % every == 0:
                yield self.frame

    # ---- output ----

    def write_frame(self, directory, frame=None):
        """Write the particles now as frame ``frame`` (default: the frame of the current time)
        of the run directory ``directory``, with the writer of ``pfsph run``: the same files
        (frames/<set>_NNNNN.vtp/.ply per the scene's output, boundary at frame 0) and bytes as
        the program's frame of the same state. Returns the frame index written."""
        ptr = self._ptr
        err = ffi.new("pfsph_error *")
        k = self.frame if frame is None else int(frame)
        if frame is None and abs(self.time - k / self.fps) > _tol(self.time):
            k = -1  # off a frame time: the library's floor(t * fps) / frame_interval
        _check(lib.pfsph_sim_write_frame(ptr, os.fsencode(directory), k, err), err)
        return k

    # ---- bodies ----

    @property
    def bodies(self):
        """The rigid bodies' states now: a list of Body (name, position, orientation,
        velocity, angular_velocity)."""
        ptr = self._ptr
        out = []
        for i in range(lib.pfsph_sim_body_count(ptr)):
            x, q, v, w = ffi.new("double[3]"), ffi.new("double[4]"), ffi.new("double[3]"), ffi.new("double[3]")
            lib.pfsph_sim_body_state(ptr, i, x, q, v, w)
            out.append(Body(ffi.string(lib.pfsph_sim_body_name(ptr, i)).decode(), np.array(list(x)),
                            np.array(list(q)), np.array(list(v)), np.array(list(w))))
        return out

    def __repr__(self):
        if self._handle is None:
            return "<pfsph Simulation (closed)>"
        return "<pfsph Simulation %r: %dD, t = %g s, %d steps, %d fluid particles>" % (
            self.name, self.dim, self.time, self.steps, len(self.fluid))

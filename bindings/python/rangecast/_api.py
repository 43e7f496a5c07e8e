"""Context, Scene and Sensor: the C handles wrapped for Python and numpy.

Every failing C call becomes a rangecast.Error carrying the status code and
the context's last-error message. Objects created from a context hold it
alive; closing the context (or leaving its `with` block) destroys them all,
as rc_context_destroy does, and later use raises Error(ERR_INVALID_HANDLE).

The C rule "a context is used by one thread at a time" is kept by a lock per
context: ctypes lets other Python threads run during a call, so without it two
threads could enter one context at once. Different contexts run in parallel.

Memory a scene reads in place (referenced meshes' arrays, a loaded baked map)
is held by its Scene until the C scene is destroyed: by close(), by the
context's close(), or after the garbage collector drops the Scene, at the end
of the call that was running then.
"""

import ctypes
import math
import mmap
import os
import threading

import numpy as np

from . import _ffi as F

_BACKENDS = {"auto": F.BACKEND_AUTO, "bvh": F.BACKEND_BVH, "embree": F.BACKEND_EMBREE, "vulkan": F.BACKEND_VULKAN}
_QUALITIES = {"balanced": F.BUILD_BALANCED, "fast": F.BUILD_FAST, "high": F.BUILD_HIGH,
              "compact": F.BUILD_COMPACT}
_MODELS = {F.SENSOR_SPHERICAL: "spherical", F.SENSOR_PINHOLE: "pinhole", F.SENSOR_CYLINDRICAL: "cylindrical",
           F.SENSOR_O1DN: "o1dn", F.SENSOR_ONDN: "ondn"}

# attribute name: (mask bit, numpy dtype, components per ray)
ATTRIBUTES = {
    "hits": (F.ATTR_HITS, np.uint8, 1),
    "ranges": (F.ATTR_RANGES, np.float32, 1),
    "points": (F.ATTR_POINTS, np.float32, 3),
    "normals": (F.ATTR_NORMALS, np.float32, 3),
    "prim_ids": (F.ATTR_PRIM_IDS, np.uint32, 1),
    "geom_ids": (F.ATTR_GEOM_IDS, np.uint32, 1),
    "inst_ids": (F.ATTR_INST_IDS, np.uint32, 1),
}

INVALID_ID = F.INVALID_ID


class Error(Exception):
    """A rangecast call failed. status: the RC_ERR_* code (negative int);
    status_name: its name as the library spells it; the message is the
    context's last-error text (or the binding's own, for checks it makes)."""

    def __init__(self, status, message):
        self.status = int(status)
        self.status_name = F.lib.rc_status_string(self.status).decode()
        Exception.__init__(self, "%s: %s" % (self.status_name, message))


def version():
    """The library's version string, e.g. "0.1.0"."""
    return F.lib.rc_version_string().decode()


def backend_available(name):
    """True when the backend ("bvh", "embree", "vulkan") is built into the
    library (creating a context may still fail, e.g. with no Vulkan device)."""
    return bool(F.lib.rc_backend_available(_lookup(_BACKENDS, name, "backend")))


def _lookup(table, name, what):
    try:
        return table[name]
    except (KeyError, TypeError):
        raise Error(F.ERR_INVALID_ARGUMENT, "%s %r is not one of %s" % (what, name, ", ".join(sorted(table))))


def _pose(value, ctype=F.Pose):
    """A pose from 7 numbers (x y z qx qy qz qw) or None (identity)."""
    p = ctype()
    if value is None:
        p.orientation[3] = 1.0
        return p
    v = np.asarray(value, dtype=np.float64).reshape(-1)
    if v.size != 7:
        raise Error(F.ERR_INVALID_ARGUMENT, "a pose is 7 numbers x y z qx qy qz qw, got %d" % v.size)
    for i in range(3):
        p.position[i] = v[i]
    for i in range(4):
        p.orientation[i] = v[3 + i]
    return p


def _angle_axis(value, name):
    try:
        lo, inc, count = value
    except (TypeError, ValueError):
        raise Error(F.ERR_INVALID_ARGUMENT, "%s is (min, increment, count) in radians, got %r" % (name, value))
    return F.AngleAxis(float(lo), float(inc), _u32(count, name + " count"))


def _u32(value, name):
    v = int(value)
    if v < 0 or v > 0xFFFFFFFF:
        raise Error(F.ERR_INVALID_ARGUMENT, "%s %d does not fit in uint32" % (name, v))
    return v


def _ptr(array, ctype):
    return array.ctypes.data_as(ctypes.POINTER(ctype))


class Context(object):
    """A rangecast context: its arena, threads and backend.

    backend: "auto" (the built-in BVH), "bvh",
    "embree" or "vulkan". threads: 0 = every CPU, 1 = the caller's thread.
    arena_bytes: the one block the library allocates at creation (0 = its
    default, 256 MiB); size it with memory_requirements-style sums in C, or
    generously here. device: Vulkan device index or name substring.
    budget_mib: most memory Embree or Vulkan may hold outside the arena.
    log: a callable(level, message) for the library's log lines.
    vulkan_ray_query: backend "vulkan" only: trace with VK_KHR_ray_query on
    the driver's acceleration structures (RC_CONTEXT_VULKAN_RAY_QUERY);
    Error(ERR_UNSUPPORTED) on a device without it.
    """

    def __init__(self, backend="auto", threads=0, arena_bytes=0, device=None, budget_mib=0, log=None,
                 vulkan_ray_query=False):
        desc = F.lib.rc_context_desc_default()
        desc.backend = _lookup(_BACKENDS, backend, "backend")
        desc.flags = F.CONTEXT_VULKAN_RAY_QUERY if vulkan_ray_query else 0
        desc.thread_count = _u32(threads, "threads")
        desc.memory_size = int(arena_bytes)
        desc.backend_budget_mib = _u32(budget_mib, "budget_mib")
        self._device = device.encode() if isinstance(device, str) else (None if device is None else
                                                                          str(device).encode())
        desc.device = self._device
        # The log relay is always installed: a failed create has no context
        # to hold its message, only the log line says why. (It captures a
        # list, not self: no reference cycle.)
        create_errors = []

        def _relay(_user, level, message):
            text = message.decode(errors="replace")
            if create_errors is not None and level == 1:
                create_errors.append(text)
            if log is not None:
                try:
                    log(int(level), text)
                except Exception:  # an exception must not cross the C frames
                    pass
        self._log = F.LOG_FN(_relay)
        desc.log = self._log
        self._lock = threading.Lock()
        self._owner = None    # thread inside a C call on this context
        self._pending = []    # (destroy function, handle) left by the garbage collector
        handle = ctypes.c_void_p()
        status = F.lib.rc_context_create(ctypes.byref(desc), ctypes.byref(handle))
        if status != F.OK:
            raise Error(status, create_errors[-1] if create_errors else "rc_context_create failed")
        del create_errors[:]
        self._h = handle

    # -- lifetime ---------------------------------------------------------
    def close(self):
        """Destroys the context and everything created from it. Idempotent."""
        if getattr(self, "_h", None) is None:
            return
        self._enter("close")
        try:
            F.lib.rc_context_destroy(self._h)
            self._h = None
            self._pending = []
        finally:
            self._leave()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def _handle(self):
        if self._h is None:
            raise Error(F.ERR_INVALID_HANDLE, "the context is closed")
        return self._h

    def _enter(self, what):
        if self._owner == threading.get_ident():
            raise Error(F.ERR_MISUSE, "%s from inside a log or progress callback of the same context" % what)
        self._lock.acquire()
        self._owner = threading.get_ident()

    def _leave(self):
        # destroys the garbage collector asked for while a call ran; what the
        # object referenced lives until its destroy has run (dropping it may
        # queue a source scene, which this loop then destroys)
        while self._pending and self._h is not None:
            fn, handle, keep = self._pending.pop()
            fn(handle)
            del keep
        self._owner = None
        self._lock.release()

    def _call(self, what, fn, *args):
        """fn(*args) under the context's lock; a failure raises Error with
        the context's message, read before another call can replace it."""
        self._enter(what)
        try:
            self._handle()  # closed by another thread while this one waited
            status = fn(*args)
            message = F.lib.rc_context_last_error(self._h).decode(errors="replace") if status != F.OK else ""
        finally:
            self._leave()
        if status != F.OK:
            raise Error(status, message or what)

    def _release(self, fn, handle, keep=None):
        """Destroys a scene or sensor the garbage collector dropped: now when
        the context is free, else at the end of the call that holds it
        (never inside it: a callback may be what dropped the object). keep:
        the memory the C object reads, held until the destroy has run."""
        if self._h is None:
            return  # freed with the context
        if self._owner is None and self._lock.acquire(False):
            self._owner = threading.get_ident()
            self._pending.append((fn, handle, keep))
            self._leave()
        else:
            self._pending.append((fn, handle, keep))

    # -- queries ----------------------------------------------------------
    @property
    def backend(self):
        """The backend in use: "bvh", "embree" or "vulkan"."""
        b = ctypes.c_uint32()
        self._call("rc_context_get_backend", F.lib.rc_context_get_backend, self._handle(), ctypes.byref(b))
        return F.lib.rc_backend_name(b.value).decode()

    @property
    def threads(self):
        """Threads simulate uses, the caller's included."""
        n = ctypes.c_uint32()
        self._call("rc_context_get_thread_count", F.lib.rc_context_get_thread_count, self._handle(), ctypes.byref(n))
        return n.value

    def memory_stats(self):
        """Bytes: arena_size, arena_used, arena_peak, backend_bytes, device_bytes."""
        s = F.lib.rc_memory_stats_default()
        self._call("rc_context_get_memory_stats", F.lib.rc_context_get_memory_stats, self._handle(), ctypes.byref(s))
        return {k: int(getattr(s, k)) for k in ("arena_size", "arena_used", "arena_peak", "backend_bytes",
                                                 "device_bytes")}

    # -- scenes -----------------------------------------------------------
    def create_scene(self, max_triangles, max_geometries=1, max_instances=0, max_vertices=0,
                     max_copied_triangles=0, origin=(0.0, 0.0, 0.0), build_quality="balanced"):
        """An empty scene with these capacities (see rc_scene_desc):
        max_vertices and max_copied_triangles count meshes added with copy=True."""
        return Scene(self, max_triangles, max_geometries, max_instances, max_vertices, max_copied_triangles,
                     origin, build_quality)

    def mesh_scene(self, vertices, triangles, copy=False, origin=(0.0, 0.0, 0.0), build_quality="balanced",
                   progress=None):
        """A committed scene of one mesh: vertices (V, 3) float, triangles
        (T, 3) int. copy=False references the arrays (converted to float32
        and uint32 once if they are not; the scene keeps them alive)."""
        v, t = _mesh_arrays(vertices, triangles)
        scene = self.create_scene(max_triangles=len(t), max_vertices=len(v) if copy else 0,
                                  max_copied_triangles=len(t) if copy else 0, origin=origin,
                                  build_quality=build_quality)
        scene.add_mesh(v, t, copy=copy)
        scene.commit(progress)
        return scene

    def load_baked(self, source, skip_checksum=False):
        """A committed, read-only scene from a baked map (Scene.bake, or the
        .rcmap files of `rangecast bake`), used in place: no build, and on
        the "bvh" backend ranges bit-identical to the baked scene's; Embree
        and Vulkan build their own structure from its meshes.

        source: a path (str or os.PathLike), mapped read-only (replace the
        file by renaming, as bake(path) does, never by rewriting it while a
        scene maps it); bytes or a read-only mmap, used in place; any other
        bytes-like object (bytearray, memoryview, numpy array), copied once,
        so that later changes to it do not reach the scene. The scene holds
        the mapping or bytes until it is closed. skip_checksum=True skips the
        CRC-32C of the whole blob (RC_BAKED_SKIP_CHECKSUM) for a map checked
        once already; the structure is still checked. A blob that fails a
        check raises Error(ERR_CORRUPT_DATA) naming the check; a file that
        cannot be read, Error(ERR_IO). Adding to or updating the scene raises
        Error(ERR_MISUSE)."""
        self._handle()
        blob = _baked_blob(source)
        handle = ctypes.c_void_p()
        flags = F.BAKED_SKIP_CHECKSUM if skip_checksum else 0
        try:
            self._call("rc_scene_load_baked", F.lib.rc_scene_load_baked, self._handle(), blob.array.ctypes.data,
                       blob.array.size, flags, ctypes.byref(handle))
        except BaseException:
            blob.close()
            raise
        return Scene._loaded(self, handle, blob)

    # -- sensors ----------------------------------------------------------
    def preset_sensor(self, name):
        """A preset: "vlp16", "vlp16-360", "os1-64", "d435", "livox-mid40", and the
        2-D scanners "ust-10lx" (Hokuyo UST-10LX) and "lds-01" (TurtleBot3's LDS-01)."""
        preset = F.lib.rc_preset_from_name(str(name).encode())
        if preset == 0:
            raise Error(F.ERR_INVALID_ARGUMENT, "no sensor preset named %r (vlp16, vlp16-360, os1-64, d435, "
                        "livox-mid40, ust-10lx, lds-01)" % (name,))
        handle = ctypes.c_void_p()
        self._call("rc_sensor_create_preset", F.lib.rc_sensor_create_preset, self._handle(), preset, ctypes.byref(handle))
        return Sensor(self, handle)

    def spherical_sensor(self, theta, phi, range_min, range_max, mounting=None):
        """Spinning LiDAR: theta (horizontal) and phi (vertical) each
        (min, increment, count) in radians; rows follow phi, columns theta."""
        d = F.lib.rc_spherical_desc_default()
        _common(d.common, range_min, range_max, mounting)
        d.theta = _angle_axis(theta, "theta")
        d.phi = _angle_axis(phi, "phi")
        return self._create(F.lib.rc_sensor_create_spherical, d)

    def pinhole_sensor(self, width, height, fx, fy, cx, cy, range_min, range_max, optical_frame=False,
                       mounting=None):
        """Depth camera. optical_frame=True: points and normals in the ROS
        optical frame (z forward, x right, y down); else x forward, z up."""
        d = F.lib.rc_pinhole_desc_default()
        _common(d.common, range_min, range_max, mounting)
        d.frame = F.PINHOLE_FRAME_OPTICAL if optical_frame else F.PINHOLE_FRAME_BODY
        d.width, d.height = _u32(width, "width"), _u32(height, "height")
        d.fx, d.fy, d.cx, d.cy = float(fx), float(fy), float(cx), float(cy)
        return self._create(F.lib.rc_sensor_create_pinhole, d)

    def cylindrical_sensor(self, theta, height, fy, cy, range_min, range_max, mounting=None):
        """Panoramic camera: theta (min, increment, count) in radians, height
        rows, ray = normalize(cos theta, sin theta, (cy - row) / fy)."""
        d = F.lib.rc_cylindrical_desc_default()
        _common(d.common, range_min, range_max, mounting)
        d.theta = _angle_axis(theta, "theta")
        d.height = _u32(height, "height")
        d.fy, d.cy = float(fy), float(cy)
        return self._create(F.lib.rc_sensor_create_cylindrical, d)

    def rays_sensor(self, directions, range_min, range_max, origins=None, shape=None, mounting=None):
        """Any scan pattern: directions (N, 3) in the sensor frame (O1Dn), and
        with origins (N, 3) one origin per ray (OnDn). shape=(height, width)
        with height * width = N shapes the results; default (1, N). The
        library copies the arrays."""
        dirs = np.ascontiguousarray(directions, dtype=np.float32)
        if dirs.ndim != 2 or dirs.shape[1] != 3 or dirs.shape[0] == 0:
            raise Error(F.ERR_INVALID_ARGUMENT, "directions must be (N, 3) with N > 0, got shape %s" %
                        (dirs.shape,))
        d = F.lib.rc_rays_desc_default()
        _common(d.common, range_min, range_max, mounting)
        d.directions = _ptr(dirs, ctypes.c_float)
        d.ray_count = _u32(dirs.shape[0], "ray count")
        model = F.SENSOR_O1DN
        orgs = None
        if origins is not None:
            orgs = np.ascontiguousarray(origins, dtype=np.float32)
            if orgs.shape != dirs.shape:
                raise Error(F.ERR_INVALID_ARGUMENT, "origins must have the shape of directions %s, got %s" %
                            (dirs.shape, orgs.shape))
            d.origins = _ptr(orgs, ctypes.c_float)
            model = F.SENSOR_ONDN
        if shape is not None:
            d.height, d.width = _u32(shape[0], "shape height"), _u32(shape[1], "shape width")
        # the library copies dirs and orgs: they only live through this call
        return self._create(lambda h, desc, out: F.lib.rc_sensor_create_rays(h, model, desc, out), d)

    def _create(self, fn, desc):
        handle = ctypes.c_void_p()
        self._call("sensor create", fn, self._handle(), ctypes.byref(desc), ctypes.byref(handle))
        return Sensor(self, handle)

    # -- simulate ---------------------------------------------------------
    def simulate(self, scene, sensor, poses, attributes=("ranges",), out=None):
        """Simulates the sensor at each pose (base-to-map, 7 numbers x y z qx
        qy qz qw each; a (7,) pose or (N, 7) poses) in the committed scene.

        Returns a dict of the requested attributes (names in ATTRIBUTES),
        each shaped (N, rows, columns), points and normals (N, rows, columns,
        3). float64 poses go through rc_simulate_d (map coordinates far from
        the origin), float32 ones through rc_simulate. out: optional dict of
        C-contiguous arrays of those shapes and dtypes to write into instead.
        """
        h = self._handle()
        if not isinstance(scene, Scene) or scene._ctx is not self:
            raise Error(F.ERR_INVALID_ARGUMENT, "scene must be a Scene of this context")
        if not isinstance(sensor, Sensor) or sensor._ctx is not self:
            raise Error(F.ERR_INVALID_ARGUMENT, "sensor must be a Sensor of this context")
        if isinstance(attributes, str):
            attributes = (attributes,)
        arr = np.asarray(poses)
        double = arr.dtype == np.float64 or not np.issubdtype(arr.dtype, np.floating)
        arr = np.ascontiguousarray(arr, dtype=np.float64 if double else np.float32)
        if arr.ndim == 1:
            arr = arr.reshape(1, -1)
        if arr.ndim != 2 or arr.shape[1] != 7 or arr.shape[0] == 0:
            raise Error(F.ERR_INVALID_ARGUMENT, "poses must be (7,) or (N, 7) with N > 0: x y z qx qy qz qw, "
                        "got shape %s" % (np.shape(poses),))
        n = arr.shape[0]
        sensor._handle()  # a closed sensor fails here, before any buffer is made
        rows, cols = sensor._grid
        res = F.lib.rc_results_default()
        res.capacity = n * rows * cols
        result = {}
        for name in attributes:
            bit, dtype, comps = _lookup(ATTRIBUTES, name, "attribute")
            shape = (n, rows, cols) if comps == 1 else (n, rows, cols, comps)
            buf = _out_buffer(out, name, shape, dtype)
            res.attributes |= bit
            setattr(res, name, _ptr(buf, _CTYPE[dtype]))
            result[name] = buf
        if res.attributes == 0:
            raise Error(F.ERR_INVALID_ARGUMENT, "attributes is empty: ask for one of %s" % ", ".join(ATTRIBUTES))
        if double:
            fn, ptr = F.lib.rc_simulate_d, arr.ctypes.data_as(ctypes.POINTER(F.PoseD))
        else:
            fn, ptr = F.lib.rc_simulate, arr.ctypes.data_as(ctypes.POINTER(F.Pose))
        self._call("rc_simulate", fn, h, scene._handle(), sensor._handle(), ptr, _u32(n, "pose count"), ctypes.byref(res))
        return result


_CTYPE = {np.uint8: ctypes.c_uint8, np.float32: ctypes.c_float, np.uint32: ctypes.c_uint32}


def _out_buffer(out, name, shape, dtype):
    if out is None or name not in out:
        return np.empty(shape, dtype=dtype)
    buf = out[name]
    if (not isinstance(buf, np.ndarray) or buf.shape != shape or buf.dtype != dtype or
            not buf.flags["C_CONTIGUOUS"] or not buf.flags["WRITEABLE"]):
        raise Error(F.ERR_INVALID_ARGUMENT, "out[%r] must be a writeable C-contiguous %s array of shape %s" %
                    (name, np.dtype(dtype).name, shape))
    return buf


def _aligned_empty(size, align=64):
    """size uint8s from an align-byte boundary (numpy promises only the
    item's alignment; baked-map sections are 64-byte aligned)."""
    block = np.empty(size + align, dtype=np.uint8)
    skip = -block.ctypes.data % align
    return block[skip:skip + size]


class _Blob(object):
    """The baked map a loaded scene reads in place: a uint8 array over the
    caller's bytes, an aligned copy or a file's read-only mapping (then
    closed with the scene, not left to the garbage collector)."""

    def __init__(self, array, mapping=None):
        self.array = array
        self.mapping = mapping

    def close(self):
        self.array = None  # the mapping's only export: it can close now
        if self.mapping is not None:
            self.mapping.close()
            self.mapping = None


def _baked_blob(source):
    if isinstance(source, (str, os.PathLike)):
        return _map_file(os.fspath(source))
    try:
        raw = np.frombuffer(source, dtype=np.uint8)
    except (TypeError, ValueError, BufferError) as exc:
        raise Error(F.ERR_INVALID_ARGUMENT, "source must be a path (str or os.PathLike) or a contiguous "
                    "bytes-like object, got %s (%s)" % (type(source).__name__, exc))
    # bytes cannot change, and a read-only mmap is the caller's own mapping:
    # both are used in place where aligned; anything else could change
    # under the scene, so it is copied
    in_place = type(source) is bytes or (isinstance(source, mmap.mmap) and not raw.flags.writeable)
    if in_place and raw.ctypes.data % F.BAKED_ALIGN == 0:
        return _Blob(raw)
    copy = _aligned_empty(raw.size)
    copy[:] = raw
    return _Blob(copy)


def _map_file(path):
    try:
        with open(path, "rb") as f:
            if os.fstat(f.fileno()).st_size == 0:
                raise Error(F.ERR_CORRUPT_DATA, "%s is empty, not a baked map" % path)
            mapping = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)  # holds its own descriptor
    except OSError as exc:
        raise Error(F.ERR_IO, "cannot read the baked map %s: %s" % (path, exc)) from exc
    return _Blob(np.frombuffer(mapping, dtype=np.uint8), mapping)


def _write_replacing(path, data):
    """Writes data to path through a temporary file beside it, renamed into
    place (as `rangecast bake` does): a reader sees the old file or the whole
    new one, and a scene mapping the old file keeps it."""
    tmp = "%s.part%d-%s" % (path, os.getpid(), os.urandom(4).hex())
    try:
        f = open(tmp, "xb")  # 0666 less the umask, like any new file
        try:
            with f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())  # the bytes reach the disk before the name does
            os.replace(tmp, path)
        except BaseException:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            raise
    except OSError as exc:
        raise Error(F.ERR_IO, "cannot write the baked map %s: %s" % (path, exc)) from exc


def _common(common, range_min, range_max, mounting):
    common.range_min = float(range_min)
    common.range_max = float(range_max)
    common.sensor_to_base = _pose(mounting)


def _mesh_arrays(vertices, triangles):
    v = np.asarray(vertices)
    # (V, 3) packed or (V, 4) padded float32 are used as they are (Embree
    # shares padded ones in place); anything else becomes packed float32
    if v.dtype != np.float32 or v.ndim != 2 or v.shape[1] not in (3, 4) or not v.flags["C_CONTIGUOUS"]:
        v = np.ascontiguousarray(v, dtype=np.float32)
    if v.ndim != 2 or v.shape[1] not in (3, 4) or v.shape[0] == 0:
        raise Error(F.ERR_INVALID_ARGUMENT, "vertices must be (V, 3) or (V, 4) with V > 0, got shape %s" %
                    (np.shape(vertices),))
    t = np.asarray(triangles)
    if t.dtype != np.uint32 or not t.flags["C_CONTIGUOUS"]:
        if t.size and np.issubdtype(t.dtype, np.integer) and (t.min() < 0 or t.max() > 0xFFFFFFFF):
            raise Error(F.ERR_OUT_OF_RANGE, "triangle indices must lie in 0 .. 2^32-1")
        if t.size and not np.issubdtype(t.dtype, np.integer):
            raise Error(F.ERR_INVALID_ARGUMENT, "triangles must be integers, got %s" % t.dtype)
        t = np.ascontiguousarray(t, dtype=np.uint32)
    if t.ndim != 2 or t.shape[1] != 3 or t.shape[0] == 0:
        raise Error(F.ERR_INVALID_ARGUMENT, "triangles must be (T, 3) with T > 0, got shape %s" %
                    (np.shape(triangles),))
    return v, t


class _Child(object):
    """A scene or sensor: lives in its context's arena."""

    def __init__(self, ctx, handle):
        self._ctx = ctx
        self._h = handle

    def _handle(self):
        if self._h is None or self._ctx._h is None:
            raise Error(F.ERR_INVALID_HANDLE, "%s is closed (or its context is)" % type(self).__name__)
        return self._h

    def _keepalive(self):
        """What the C object reads in place (a sensor: nothing, the library
        copies its rays)."""
        return None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_h", None) is None or getattr(self, "_ctx", None) is None:
            return  # never created, or closed already
        # a scene another scene still instances cannot go (the destroy says
        # RC_ERR_MISUSE, ignored): it is freed with the context
        try:
            self._ctx._release(self._destroy_fn, self._h, self._keepalive())
        except Exception:  # interpreter shutdown: the process frees the arena
            pass
        self._h = None


class Scene(_Child):
    """A scene of meshes and instances; commit() before simulating. A scene
    from Context.load_baked is committed and read-only."""

    _destroy_fn = staticmethod(lambda h: F.lib.rc_scene_destroy(h))
    _blob = None

    def __init__(self, ctx, max_triangles, max_geometries, max_instances, max_vertices, max_copied_triangles,
                 origin, build_quality):
        d = F.lib.rc_scene_desc_default()
        d.max_triangles = int(max_triangles)
        d.max_geometries = _u32(max_geometries, "max_geometries")
        d.max_instances = _u32(max_instances, "max_instances")
        d.max_vertices = int(max_vertices)
        d.max_copied_triangles = int(max_copied_triangles)
        for i, c in enumerate(origin):
            d.origin[i] = float(c)
        d.build_quality = _lookup(_QUALITIES, build_quality, "build_quality")
        handle = ctypes.c_void_p()
        ctx._call("rc_scene_create", F.lib.rc_scene_create, ctx._handle(), ctypes.byref(d), ctypes.byref(handle))
        self._wrap(ctx, handle)

    def _wrap(self, ctx, handle, blob=None):
        _Child.__init__(self, ctx, handle)
        self._arrays = {}     # geom id -> (vertices, triangles) referenced in place
        self._sources = []    # scenes instanced here: kept alive as long as this one
        self._blob = blob     # a loaded scene's baked map (_Blob), read in place

    @classmethod
    def _loaded(cls, ctx, handle, blob):
        scene = cls.__new__(cls)
        scene._wrap(ctx, handle, blob)
        return scene

    def _keepalive(self):
        return (self._arrays, self._sources, self._blob)

    def close(self):
        """Frees the scene (it must not be instanced by a live scene), and
        unmaps the baked map it was loaded from."""
        if self._h is not None and self._ctx._h is not None:
            self._ctx._call("rc_scene_destroy", F.lib.rc_scene_destroy, self._h)
        self._h = None
        self._arrays = {}
        self._sources = []
        if self._blob is not None:
            self._blob.close()
            self._blob = None

    def bake(self, path=None):
        """The committed scene as a baked map (docs/baked-map.md) for
        Context.load_baked: bytes, or with path, written there through a
        temporary file renamed into place (returns its size). The same scene
        bakes to the same bytes on every run. The context must use the "bvh"
        backend (the map holds its tree) and the scene hold meshes only:
        else Error(ERR_UNSUPPORTED); not committed: Error(ERR_NOT_COMMITTED);
        a file that cannot be written: Error(ERR_IO)."""
        size = ctypes.c_size_t()
        self._ctx._call("rc_scene_bake", F.lib.rc_scene_bake, self._handle(), None, 0, ctypes.byref(size))
        blob = _aligned_empty(size.value)
        self._ctx._call("rc_scene_bake", F.lib.rc_scene_bake, self._handle(), blob.ctypes.data, blob.size,
                        ctypes.byref(size))
        blob = blob[:size.value]
        if path is None:
            return blob.tobytes()
        _write_replacing(os.fspath(path), blob)
        return size.value

    def add_mesh(self, vertices, triangles, copy=False):
        """Adds a mesh; returns its geometry id. copy=False references the
        arrays in place (see vertices()); copy=True copies them into the arena."""
        v, t = _mesh_arrays(vertices, triangles)
        d = F.lib.rc_mesh_desc_default()
        d.flags = F.MESH_COPY if copy else F.MESH_REFERENCE
        d.vertices = _ptr(v, ctypes.c_float)
        d.vertex_count = v.shape[0]
        d.vertex_stride = v.strides[0]
        d.indices = _ptr(t, ctypes.c_uint32)
        d.triangle_count = t.shape[0]
        gid = ctypes.c_uint32()
        self._ctx._call("rc_scene_add_mesh", F.lib.rc_scene_add_mesh, self._handle(), ctypes.byref(d), ctypes.byref(gid))
        if not copy:
            self._arrays[gid.value] = (v, t)
        return gid.value

    def vertices(self, geom_id):
        """The vertex array a referenced mesh uses in place: change it, then
        update_mesh(geom_id) and commit() to refit."""
        try:
            return self._arrays[geom_id][0]
        except KeyError:
            raise Error(F.ERR_INVALID_ARGUMENT, "geometry %r is not a referenced mesh of this scene" % (geom_id,))

    def update_mesh(self, geom_id):
        self._ctx._call("rc_scene_update_mesh", F.lib.rc_scene_update_mesh, self._handle(), _u32(geom_id, "geom_id"))

    def add_instance(self, source, pose=None, scale=1.0):
        """Places the committed scene source (meshes only) here; pose is
        source-to-this-scene, scale a number or 3 per-axis factors."""
        if not isinstance(source, Scene) or source._ctx is not self._ctx:
            raise Error(F.ERR_INVALID_ARGUMENT, "source must be a Scene of the same context")
        d = F.lib.rc_instance_desc_default()
        d.source = source._handle()
        d.transform = _pose(pose)
        d.scale[:] = _scale3(scale)
        iid = ctypes.c_uint32()
        self._ctx._call("rc_scene_add_instance", F.lib.rc_scene_add_instance, self._handle(), ctypes.byref(d), ctypes.byref(iid))
        self._sources.append(source)
        return iid.value

    def set_instance_transform(self, inst_id, pose, scale=1.0):
        p = _pose(pose)
        s = (ctypes.c_float * 3)(*_scale3(scale))
        self._ctx._call("rc_scene_set_instance_transform", F.lib.rc_scene_set_instance_transform, self._handle(), _u32(inst_id, "inst_id"), ctypes.byref(p), s)

    def commit(self, progress=None):
        """Builds or refits the acceleration structure. progress: an optional
        callable(stage, fraction) called on this thread."""
        cb = F.PROGRESS_FN()
        if progress is not None:
            def _relay(_user, stage, fraction):
                try:
                    progress(stage.decode(errors="replace"), float(fraction))
                except Exception:  # an exception must not cross the C frames
                    pass
                return 1
            cb = F.PROGRESS_FN(_relay)
        self._ctx._call("rc_scene_commit", F.lib.rc_scene_commit_with_progress, self._handle(), cb, None)

    @property
    def bounds(self):
        """(6,) float32: min x y z, max x y z of the committed scene."""
        b = np.empty(6, dtype=np.float32)
        self._ctx._call("rc_scene_get_bounds", F.lib.rc_scene_get_bounds, self._handle(), _ptr(b, ctypes.c_float))
        return b

    @property
    def info(self):
        i = F.lib.rc_scene_info_default()
        self._ctx._call("rc_scene_get_info", F.lib.rc_scene_get_info, self._handle(), ctypes.byref(i))
        return {"geometry_count": i.geometry_count, "instance_count": i.instance_count,
                "committed": bool(i.committed), "triangle_count": int(i.triangle_count),
                "bvh_nodes": int(i.bvh_nodes), "bytes": int(i.bytes)}


def _scale3(scale):
    s = np.asarray(scale, dtype=np.float64).reshape(-1)
    if s.size == 1:
        s = np.repeat(s, 3)
    if s.size != 3:
        raise Error(F.ERR_INVALID_ARGUMENT, "scale is one number or 3 per-axis factors, got %d" % s.size)
    return [float(x) for x in s]


class Sensor(_Child):
    """A sensor model; its scan shape is in info."""

    _destroy_fn = staticmethod(lambda h: F.lib.rc_sensor_destroy(h))

    def __init__(self, ctx, handle):
        _Child.__init__(self, ctx, handle)
        info = self.info
        self._grid = (info["rows"], info["columns"])  # fixed at create: simulate's result shape

    def close(self):
        if self._h is not None and self._ctx._h is not None:
            self._ctx._call("rc_sensor_destroy", F.lib.rc_sensor_destroy, self._h)
        self._h = None

    @property
    def info(self):
        """model, rows, columns, rays_per_scan, range_min, range_max."""
        i = F.lib.rc_sensor_info_default()
        self._ctx._call("rc_sensor_get_info", F.lib.rc_sensor_get_info, self._handle(), ctypes.byref(i))
        return {"model": _MODELS.get(i.model, "unknown"), "rows": i.rows, "columns": i.columns,
                "rays_per_scan": i.rays_per_scan, "range_min": i.range_min, "range_max": i.range_max}

    def set_noise(self, sigma=0.0, mean=0.0, sigma_exponent=0.0, dropout=0.0, seed=0):
        """Range noise and dropout for every later simulate with this sensor
        (rc_sensor_set_noise): a return's range r becomes
        r + mean + sigma * r**sigma_exponent * N(0, 1), clamped to the
        sensor's range, its point moved along the ray; with probability
        dropout it is lost instead. Reproducible: the n-th simulate after
        set_noise draws the same numbers on every backend and thread count.
        All zeros (the defaults) remove the noise."""
        d = F.lib.rc_noise_desc_default()
        d.mean, d.sigma, d.sigma_exponent, d.dropout = float(mean), float(sigma), float(sigma_exponent), float(dropout)
        seed = int(seed)
        if seed < 0 or seed > 0xFFFFFFFFFFFFFFFF:
            raise Error(F.ERR_INVALID_ARGUMENT, "seed %d does not fit in uint64" % seed)
        d.seed = seed
        self._ctx._call("rc_sensor_set_noise", F.lib.rc_sensor_set_noise, self._handle(), ctypes.byref(d))

    def set_mounting(self, sensor_to_base):
        """Moves the sensor on the robot (7 numbers x y z qx qy qz qw)."""
        p = _pose(sensor_to_base)
        self._ctx._call("rc_sensor_set_mounting", F.lib.rc_sensor_set_mounting, self._handle(), ctypes.byref(p))


def quaternion_from_euler(roll, pitch, yaw):
    """(qx, qy, qz, qw) of the rotation yaw about z, then pitch about y, then
    roll about x (ROS's convention, radians)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)

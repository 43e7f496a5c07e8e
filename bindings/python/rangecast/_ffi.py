"""The C ABI of include/rangecast/rangecast.h as ctypes declarations.

Only this module knows the C layout. The structs mirror the header field by
field (tests/test_layout.py checks them against tests/abi/<lp64|ilp32>.txt,
the layout the C side pins), and every function gets its argument and return
types so ctypes never guesses an int where a pointer or a struct travels.
"""

import ctypes
import ctypes.util
import os

c_u8 = ctypes.c_uint8
c_u32 = ctypes.c_uint32
c_u64 = ctypes.c_uint64
c_i32 = ctypes.c_int32
c_float = ctypes.c_float
c_double = ctypes.c_double
c_void_p = ctypes.c_void_p
c_size_t = ctypes.c_size_t
c_char_p = ctypes.c_char_p
POINTER = ctypes.POINTER

# The binding speaks this ABI (RC_VERSION_MAJOR); another major is refused.
ABI_MAJOR = 0

# Status codes (RC_OK, RC_ERR_*).
OK = 0
ERR_INVALID_ARGUMENT = -1
ERR_INVALID_HANDLE = -2
ERR_MISUSE = -3
ERR_OUT_OF_MEMORY = -4
ERR_CAPACITY = -5
ERR_UNSUPPORTED = -6
ERR_BACKEND = -7
ERR_DEVICE_LOST = -8
ERR_CORRUPT_DATA = -9
ERR_NOT_COMMITTED = -10
ERR_NON_FINITE = -11
ERR_OUT_OF_RANGE = -12
ERR_STRUCT_SIZE = -13
ERR_IO = -14

BACKEND_AUTO = 0
BACKEND_BVH = 1
BACKEND_EMBREE = 2
BACKEND_VULKAN = 3

BUILD_BALANCED = 0
BUILD_FAST = 1
BUILD_HIGH = 2
BUILD_COMPACT = 3

MESH_REFERENCE = 0
MESH_COPY = 1

SENSOR_SPHERICAL = 1
SENSOR_PINHOLE = 2
SENSOR_CYLINDRICAL = 3
SENSOR_O1DN = 4
SENSOR_ONDN = 5

PINHOLE_FRAME_BODY = 0
PINHOLE_FRAME_OPTICAL = 1

ATTR_HITS = 0x01
ATTR_RANGES = 0x02
ATTR_POINTS = 0x04
ATTR_NORMALS = 0x08
ATTR_PRIM_IDS = 0x10
ATTR_GEOM_IDS = 0x20
ATTR_INST_IDS = 0x40

INVALID_ID = 0xFFFFFFFF

CONTEXT_VULKAN_RAY_QUERY = 0x1

BAKED_MAP_VERSION = 1      # RC_BAKED_MAP_VERSION: the blob format the library writes and reads
BAKED_SKIP_CHECKSUM = 1    # rc_scene_load_baked flag
BAKED_ALIGN = 16           # rc_scene_load_baked wants the blob on a 16-byte boundary


class Pose(ctypes.Structure):
    _fields_ = [("position", c_float * 3), ("orientation", c_float * 4)]


class PoseD(ctypes.Structure):
    _fields_ = [("position", c_double * 3), ("orientation", c_double * 4)]


LOG_FN = ctypes.CFUNCTYPE(None, c_void_p, c_u32, c_char_p)
PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, c_void_p, c_char_p, c_double)


class ContextDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("backend", c_u32), ("thread_count", c_u32), ("flags", c_u32),
                ("memory", c_void_p), ("memory_size", c_size_t), ("log", LOG_FN), ("log_user", c_void_p),
                ("device", c_char_p), ("backend_budget_mib", c_u32), ("reserved", c_u32 * 7)]


class MemoryStats(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("reserved0", c_u32), ("arena_size", c_u64), ("arena_used", c_u64),
                ("arena_peak", c_u64), ("backend_bytes", c_u64), ("device_bytes", c_u64),
                ("reserved", c_u64 * 4)]


class SceneDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("max_geometries", c_u32), ("max_instances", c_u32), ("flags", c_u32),
                ("max_triangles", c_u64), ("max_vertices", c_u64), ("max_copied_triangles", c_u64),
                ("origin", c_double * 3), ("build_quality", c_u32), ("reserved", c_u32 * 7)]


class MeshDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("flags", c_u32), ("vertices", POINTER(c_float)),
                ("vertex_count", c_u64), ("vertex_stride", c_u32), ("reserved0", c_u32),
                ("indices", POINTER(c_u32)), ("triangle_count", c_u64), ("reserved", c_u32 * 8)]


class InstanceDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("reserved0", c_u32), ("source", c_void_p), ("transform", Pose),
                ("scale", c_float * 3), ("reserved", c_u32 * 8)]


class SceneInfo(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("geometry_count", c_u32), ("instance_count", c_u32),
                ("committed", c_u32), ("triangle_count", c_u64), ("bvh_nodes", c_u64), ("bytes", c_u64),
                ("reserved", c_u64 * 4)]


class SensorCommon(ctypes.Structure):
    _fields_ = [("range_min", c_float), ("range_max", c_float), ("sensor_to_base", Pose)]


class AngleAxis(ctypes.Structure):
    _fields_ = [("min", c_float), ("increment", c_float), ("count", c_u32)]


class SphericalDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("reserved0", c_u32), ("common", SensorCommon), ("theta", AngleAxis),
                ("phi", AngleAxis), ("reserved", c_u32 * 8)]


class PinholeDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("frame", c_u32), ("common", SensorCommon), ("width", c_u32),
                ("height", c_u32), ("fx", c_float), ("fy", c_float), ("cx", c_float), ("cy", c_float),
                ("reserved", c_u32 * 8)]


class CylindricalDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("reserved0", c_u32), ("common", SensorCommon), ("theta", AngleAxis),
                ("height", c_u32), ("fy", c_float), ("cy", c_float), ("reserved", c_u32 * 8)]


class RaysDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("reserved0", c_u32), ("common", SensorCommon),
                ("directions", POINTER(c_float)), ("origins", POINTER(c_float)), ("ray_count", c_u32),
                ("width", c_u32), ("height", c_u32), ("reserved", c_u32 * 8)]


class SensorInfo(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("model", c_u32), ("rows", c_u32), ("columns", c_u32),
                ("rays_per_scan", c_u32), ("range_min", c_float), ("range_max", c_float),
                ("reserved", c_u32 * 5)]


class NoiseDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("reserved0", c_u32), ("mean", c_float), ("sigma", c_float),
                ("sigma_exponent", c_float), ("dropout", c_float), ("seed", c_u64), ("reserved", c_u32 * 8)]


class OusterDesc(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("beams", c_u32), ("columns", c_u32), ("reserved0", c_u32),
                ("altitudes_deg", POINTER(c_double)), ("azimuths_deg", POINTER(c_double)),
                ("beam_to_lidar", c_double * 16), ("lidar_to_sensor", c_double * 16), ("reserved", c_u32 * 8)]


class Results(ctypes.Structure):
    _fields_ = [("struct_size", c_u32), ("attributes", c_u32), ("capacity", c_u64), ("hits", POINTER(c_u8)),
                ("ranges", POINTER(c_float)), ("points", POINTER(c_float)), ("normals", POINTER(c_float)),
                ("prim_ids", POINTER(c_u32)), ("geom_ids", POINTER(c_u32)), ("inst_ids", POINTER(c_u32)),
                ("flags", c_u32), ("reserved", c_u32 * 7)]


# Structs the layout test compares with tests/abi/*.txt, by their C names.
STRUCTS = {
    "rc_pose": Pose, "rc_pose_d": PoseD, "rc_context_desc": ContextDesc, "rc_memory_stats": MemoryStats,
    "rc_scene_desc": SceneDesc, "rc_mesh_desc": MeshDesc, "rc_instance_desc": InstanceDesc,
    "rc_scene_info": SceneInfo, "rc_sensor_common": SensorCommon, "rc_angle_axis": AngleAxis,
    "rc_spherical_desc": SphericalDesc, "rc_pinhole_desc": PinholeDesc, "rc_cylindrical_desc": CylindricalDesc,
    "rc_rays_desc": RaysDesc, "rc_sensor_info": SensorInfo, "rc_noise_desc": NoiseDesc, "rc_results": Results,
    "rc_ouster_desc": OusterDesc,
}

_P = c_void_p  # opaque handles (rc_context *, rc_scene *, rc_sensor *)

# name: (restype, argtypes)
_PROTOTYPES = {
    "rc_version_number": (c_u32, []),
    "rc_version_string": (c_char_p, []),
    "rc_status_string": (c_char_p, [c_i32]),
    "rc_context_desc_default": (ContextDesc, []),
    "rc_context_memory_requirements": (c_i32, [POINTER(ContextDesc), POINTER(c_size_t)]),
    "rc_context_create": (c_i32, [POINTER(ContextDesc), POINTER(_P)]),
    "rc_context_destroy": (None, [_P]),
    "rc_context_last_error": (c_char_p, [_P]),
    "rc_context_get_backend": (c_i32, [_P, POINTER(c_u32)]),
    "rc_context_get_thread_count": (c_i32, [_P, POINTER(c_u32)]),
    "rc_memory_stats_default": (MemoryStats, []),
    "rc_context_get_memory_stats": (c_i32, [_P, POINTER(MemoryStats)]),
    "rc_backend_available": (ctypes.c_int, [c_u32]),
    "rc_backend_name": (c_char_p, [c_u32]),
    "rc_scene_desc_default": (SceneDesc, []),
    "rc_scene_memory_requirements": (c_i32, [_P, POINTER(SceneDesc), POINTER(c_size_t)]),
    "rc_scene_create": (c_i32, [_P, POINTER(SceneDesc), POINTER(_P)]),
    "rc_scene_destroy": (c_i32, [_P]),
    "rc_mesh_desc_default": (MeshDesc, []),
    "rc_scene_add_mesh": (c_i32, [_P, POINTER(MeshDesc), POINTER(c_u32)]),
    "rc_scene_update_mesh": (c_i32, [_P, c_u32]),
    "rc_instance_desc_default": (InstanceDesc, []),
    "rc_scene_add_instance": (c_i32, [_P, POINTER(InstanceDesc), POINTER(c_u32)]),
    "rc_scene_set_instance_transform": (c_i32, [_P, c_u32, POINTER(Pose), POINTER(c_float)]),
    "rc_scene_commit_with_progress": (c_i32, [_P, PROGRESS_FN, c_void_p]),
    "rc_scene_get_bounds": (c_i32, [_P, POINTER(c_float)]),
    "rc_scene_info_default": (SceneInfo, []),
    "rc_scene_get_info": (c_i32, [_P, POINTER(SceneInfo)]),
    "rc_scene_bake": (c_i32, [_P, c_void_p, c_size_t, POINTER(c_size_t)]),
    "rc_scene_baked_memory_requirements": (c_i32, [_P, c_void_p, c_size_t, POINTER(c_size_t)]),
    "rc_scene_load_baked": (c_i32, [_P, c_void_p, c_size_t, c_u32, POINTER(_P)]),
    "rc_baked_get_mesh": (c_i32, [c_void_p, c_size_t, c_u32, POINTER(MeshDesc), POINTER(c_u32)]),
    "rc_spherical_desc_default": (SphericalDesc, []),
    "rc_pinhole_desc_default": (PinholeDesc, []),
    "rc_cylindrical_desc_default": (CylindricalDesc, []),
    "rc_rays_desc_default": (RaysDesc, []),
    "rc_sensor_create_spherical": (c_i32, [_P, POINTER(SphericalDesc), POINTER(_P)]),
    "rc_sensor_create_pinhole": (c_i32, [_P, POINTER(PinholeDesc), POINTER(_P)]),
    "rc_sensor_create_cylindrical": (c_i32, [_P, POINTER(CylindricalDesc), POINTER(_P)]),
    "rc_sensor_create_rays": (c_i32, [_P, c_u32, POINTER(RaysDesc), POINTER(_P)]),
    "rc_sensor_destroy": (c_i32, [_P]),
    "rc_preset_from_name": (c_u32, [c_char_p]),
    "rc_preset_model": (c_u32, [c_u32]),
    "rc_sensor_create_preset": (c_i32, [_P, c_u32, POINTER(_P)]),
    "rc_sensor_info_default": (SensorInfo, []),
    "rc_sensor_get_info": (c_i32, [_P, POINTER(SensorInfo)]),
    "rc_sensor_set_mounting": (c_i32, [_P, POINTER(Pose)]),
    "rc_ouster_desc_default": (OusterDesc, []),
    "rc_ouster_rays": (c_i32, [POINTER(OusterDesc), POINTER(RaysDesc), POINTER(c_float), POINTER(c_float),
                               POINTER(c_double)]),
    "rc_noise_desc_default": (NoiseDesc, []),
    "rc_sensor_set_noise": (c_i32, [_P, POINTER(NoiseDesc)]),
    "rc_results_default": (Results, []),
    "rc_simulate": (c_i32, [_P, _P, _P, POINTER(Pose), c_u32, POINTER(Results)]),
    "rc_simulate_d": (c_i32, [_P, _P, _P, POINTER(PoseD), c_u32, POINTER(Results)]),
}


def _candidates():
    """Where to look for the shared library, first hit wins."""
    env = os.environ.get("RANGECAST_LIBRARY")
    if env:
        return [env]  # asked for this one: no silent fallback to another
    names = []
    here = os.path.dirname(os.path.abspath(__file__))
    # installed by cmake --install: _installed.py (generated) names the library
    # installed with the package, relative to this folder
    try:
        from . import _installed
        names.append(os.path.normpath(os.path.join(here, _installed.LIBRARY)))
    except ImportError:
        pass
    # a source checkout: bindings/python/rangecast -> <repo>/build/librangecast.so
    repo = os.path.abspath(os.path.join(here, "..", "..", ".."))
    names.append(os.path.join(repo, "build", "librangecast.so"))
    found = ctypes.util.find_library("rangecast")
    if found:
        names.append(found)
    names.append("librangecast.so.%d" % ABI_MAJOR)
    return names


def _load():
    tried = []
    for name in _candidates():
        if os.sep in name and not os.path.exists(name):
            tried.append("%s (no such file)" % name)
            continue
        try:
            return ctypes.CDLL(name)
        except OSError as exc:
            tried.append("%s (%s)" % (name, exc))
    raise ImportError("rangecast: cannot load the shared library librangecast.so; tried: " + "; ".join(tried) +
                      ". Build it (make build), install it (cmake --install), or set RANGECAST_LIBRARY "
                      "to its path.")


lib = _load()
for _name, (_res, _args) in _PROTOTYPES.items():
    _fn = getattr(lib, _name)
    _fn.restype = _res
    _fn.argtypes = _args

_major = lib.rc_version_number() // 10000
if _major != ABI_MAJOR:
    raise ImportError("rangecast: %s is version %s, this binding speaks ABI %d.x" %
                      (getattr(lib, "_name", "the library"), lib.rc_version_string().decode(), ABI_MAJOR))

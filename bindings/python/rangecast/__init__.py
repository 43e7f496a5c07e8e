"""rangecast for Python: range sensor simulation over the C library's ABI.

    import numpy as np
    import rangecast

    with rangecast.Context(backend="bvh", threads=2) as ctx:
        scene = ctx.mesh_scene(vertices, triangles)        # (V, 3) float, (T, 3) int
        lidar = ctx.preset_sensor("vlp16")
        scan = ctx.simulate(scene, lidar, [0, 0, 1, 0, 0, 0, 1], ("ranges", "points"))
        scan["ranges"].shape                               # (1, 16, 900), +inf = no return
        scene.bake("map.rcmap")                            # later: ctx.load_baked("map.rcmap")

The binding is ctypes over librangecast.so (found through RANGECAST_LIBRARY,
the library cmake --install put beside this package, a source checkout's
build/, or the system's library path) and numpy; it
compiles nothing. Failures raise rangecast.Error with the library's status and
message. Conventions are the C header's (include/rangecast/rangecast.h):
metres, radians, quaternions x y z w, base-to-map poses, REP 117 ranges.
"""

from ._api import (ATTRIBUTES, INVALID_ID, Context, Error, Scene, Sensor, backend_available,
                   quaternion_from_euler, version)
from . import ouster  # noqa: E402  (Ouster lidars from their metadata JSON)

__all__ = ["ATTRIBUTES", "INVALID_ID", "Context", "Error", "Scene", "Sensor", "backend_available", "ouster",
           "quaternion_from_euler", "version"]
__version__ = version()

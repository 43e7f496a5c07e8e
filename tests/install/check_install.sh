#!/bin/sh
# Installs the build into a scratch prefix, then builds a consumer with the
# CMake package (static target) and with pkg-config (shared), and runs both.
# embree_dir (optional): the Embree CMake package the build used, so that the
# consumer finds the same one (the package asks for the same major version).
set -eu
build=$1; src=$2; work=$3; embree_dir=${4:-}
rm -rf "$work"; mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
case "$embree_dir" in
*NOTFOUND* | "") embree_dir= ;;
esac
cmake -S "$src" -B "$work/cmake" -DCMAKE_PREFIX_PATH="$work/prefix" ${embree_dir:+"-Dembree_DIR=$embree_dir"} >/dev/null
cmake --build "$work/cmake" >/dev/null
"$work/cmake/consumer_cmake"
lib=$(ls -d "$work"/prefix/lib*/pkgconfig | head -n1)
# shellcheck disable=SC2046
${CC:-cc} "$src/consumer.c" -o "$work/consumer_pc" $(PKG_CONFIG_PATH="$lib" pkg-config --cflags --libs rangecast) \
    -Wl,-rpath,"$(dirname "$lib")"
"$work/consumer_pc"
# The Python binding on the installed shared library (where python3 has numpy):
# one VLP-16 scan of a plane 5 m ahead through ctypes.
libdir=$(dirname "$lib")
if [ -e "$libdir/librangecast.so" ] && python3 -c "import numpy" 2>/dev/null; then
    RANGECAST_LIBRARY="$libdir/librangecast.so" PYTHONPATH="$src/../../bindings/python" python3 - <<'PY'
import numpy as np
import rangecast
v = np.array([[5, -9, -9], [5, 9, -9], [5, 0, 9]], np.float32)
with rangecast.Context(backend="bvh", threads=1) as ctx:
    scan = ctx.simulate(ctx.mesh_scene(v, [[0, 1, 2]]), ctx.preset_sensor("vlp16"), [0, 0, 0, 0, 0, 0, 1])
r = scan["ranges"][0]
assert r.shape == (16, 900) and abs(float(r[8, 450]) - 5.0 / np.cos(np.radians(1.0))) < 1e-4, r[8, 450]
print("installed library through the Python binding:", rangecast.version())
PY
fi

#!/bin/sh
# Installs the build into a scratch prefix, then builds a consumer with the
# CMake package (static target) and with pkg-config (shared), and runs both.
# embree_dir (optional): the Embree CMake package the build used, so that the
# consumer finds the same one (the package asks for the same major version).
# pydir (optional): RANGECAST_PYTHON_INSTALL_DIR, where the Python package goes.
set -eu
build=$1; src=$2; work=$3; embree_dir=${4:-}; pydir=${5:-}
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
# The Python binding (where python3 has numpy), one VLP-16 scan of a plane 5 m
# ahead through ctypes: the source package on the installed library through
# RANGECAST_LIBRARY, then the installed package (pydir: RANGECAST_PYTHON_INSTALL_DIR)
# on its own, without RANGECAST_LIBRARY.
libdir=$(dirname "$lib")
[ -e "$libdir/librangecast.so" ] || exit 0
case "$pydir" in
"") echo "no Python package installed (RANGECAST_PYTHON_INSTALL_DIR is empty)"; pkg= ;;
/*) echo "Python package installed outside the prefix ($pydir): not checked"; pkg= ;;
*) pkg="$work/prefix/$pydir"
   [ -f "$pkg/rangecast/__init__.py" ] && [ -f "$pkg/rangecast/_installed.py" ] ||
       { echo "the install has no Python package in $pkg/rangecast" >&2; exit 1; } ;;
esac
if ! python3 -c "import numpy" 2>/dev/null; then
    echo "no python3 with numpy: the Python binding is not checked"
    exit 0
fi
# argv: the folder the package must come from, the one the library must come from
cat >"$work/scan.py" <<'PY'
import os, sys
import numpy as np
import rangecast
from rangecast import _ffi
for path, folder in ((rangecast.__file__, sys.argv[1]), (_ffi.lib._name, sys.argv[2])):
    assert os.path.realpath(path).startswith(os.path.realpath(folder) + os.sep), (path, folder)
v = np.array([[5, -9, -9], [5, 9, -9], [5, 0, 9]], np.float32)
with rangecast.Context(backend="bvh", threads=1) as ctx:
    scan = ctx.simulate(ctx.mesh_scene(v, [[0, 1, 2]]), ctx.preset_sensor("vlp16"), [0, 0, 0, 0, 0, 0, 1])
r = scan["ranges"][0]
assert r.shape == (16, 900) and abs(float(r[8, 450]) - 5.0 / np.cos(np.radians(1.0))) < 1e-4, r[8, 450]
print("%s on %s: %s" % (os.path.dirname(rangecast.__file__), _ffi.lib._name, rangecast.version()))
PY
bindings="$src/../../bindings/python"
RANGECAST_LIBRARY="$libdir/librangecast.so" PYTHONPATH="$bindings" python3 "$work/scan.py" "$bindings" "$libdir"
if [ -n "$pkg" ]; then
    env -u RANGECAST_LIBRARY PYTHONPATH="$pkg" python3 "$work/scan.py" "$pkg" "$libdir"
fi

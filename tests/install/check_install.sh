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

#!/bin/sh
# Builds cmocka for a cross target from Debian bookworm's source package and
# installs it into a prefix inside the build folder, for targets whose
# libcmocka-dev:<arch> is not at hand (armhf: its multiarch index has broken
# `apt-get update` on these machines; riscv64: not a bookworm architecture).
#
#   toolchains/cmocka-from-source.sh TOOLCHAIN_FILE DEPS_DIR
#
# DEPS_DIR (e.g. build-armhf/_deps) gets:
#   apt/        a private apt state holding only bookworm's deb-src index: the
#               system's sources, architectures and lists are not touched, and
#               root is not needed
#   src/        the downloaded source package (kept: a rerun does not refetch)
#   cmocka/     the install prefix (lib/libcmocka.so, lib/pkgconfig/cmocka.pc);
#               pass it to the project with -DCMAKE_PREFIX_PATH
# A rerun with cmocka/ installed does nothing. Offline: set CMOCKA_SOURCE to a
# cmocka-1.1.x tarball (cmocka_1.1.5.orig.tar.xz) to skip the download.
set -eu

toolchain=$1
deps=$2
case $toolchain in /*) ;; *) toolchain=$(pwd)/$toolchain ;; esac
mkdir -p "$deps"
deps=$(cd "$deps" && pwd)
prefix=$deps/cmocka

if [ -f "$prefix/lib/pkgconfig/cmocka.pc" ]; then
  exit 0
fi

tarball=${CMOCKA_SOURCE:-}
if [ -z "$tarball" ]; then
  tarball=$(ls "$deps"/src/cmocka_1.1.*.orig.tar.* 2>/dev/null | head -n 1 || true)
fi
if [ -z "$tarball" ]; then
  echo "cmocka-from-source: fetching Debian bookworm's cmocka source package into $deps/src"
  apt=$deps/apt
  mkdir -p "$apt/lists/partial" "$apt/cache/archives/partial" "$deps/src"
  echo "deb-src [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian bookworm main" \
    >"$apt/sources.list"
  set -- -o Dir::Etc::SourceList="$apt/sources.list" -o Dir::Etc::SourceParts=/nonexistent \
    -o Dir::State::Lists="$apt/lists" -o Dir::Cache="$apt/cache" -o Debug::NoLocking=1 \
    -o APT::Sandbox::User="$(id -un)"
  apt-get -qq "$@" update
  (cd "$deps/src" && apt-get -qq "$@" source --download-only cmocka)
  tarball=$(ls "$deps"/src/cmocka_1.1.*.orig.tar.* | head -n 1)
fi

# The orig tarball is upstream's release; Debian's only patch (bookworm 1.1.5-2.1)
# touches the documentation build, which is off here.
rm -rf "$deps/cmocka-src" "$deps/cmocka-build"
mkdir -p "$deps/cmocka-src"
tar -xf "$tarball" -C "$deps/cmocka-src" --strip-components=1
cmake -S "$deps/cmocka-src" -B "$deps/cmocka-build" -DCMAKE_TOOLCHAIN_FILE="$toolchain" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib \
  -DWITH_EXAMPLES=OFF -DUNIT_TESTING=OFF >/dev/null
cmake --build "$deps/cmocka-build" -j "$(nproc 2>/dev/null || echo 2)" >/dev/null
cmake --install "$deps/cmocka-build" >/dev/null
rm -rf "$deps/cmocka-src" "$deps/cmocka-build"
echo "cmocka-from-source: installed $(sed -n 's/^Version: //p' "$prefix/lib/pkgconfig/cmocka.pc") into $prefix"

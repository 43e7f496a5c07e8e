#!/bin/sh
# Packs a Vulkan build's programs and the shared libraries they need (all but
# the C library's own) into one folder, for a GPU machine that has a driver
# but not Debian 12's packages: run there as tools/device/gpu-run.sh FOLDER.
#   sh tools/device/bundle.sh [BUILD (build-gpu)] [FOLDER (.gpu)]
# A build for it: cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release
#   -DRANGECAST_WITH_EMBREE=OFF (Embree's 44 MB library would not travel).
set -eu
build=${1:-build-gpu}
dest=${2:-.gpu}
[ -x "$build/tools/rangecast" ] || { echo "bundle.sh: no $build/tools/rangecast; build it first" >&2; exit 1; }
rm -rf "$dest"
mkdir -p "$dest/bin" "$dest/lib"
cp "$build/tools/rangecast" "$dest/bin/"
for t in "$build"/tests/test_*; do
    [ -x "$t" ] && [ -f "$t" ] && cp "$t" "$dest/bin/"
done
# every library a program links, less glibc, the compiler's runtime and the
# loader, which the other machine has (newer); the Vulkan loader travels
ldd "$dest"/bin/* 2>/dev/null | awk '/=> \//{print $3}' | sort -u | while read -r lib; do
    case $(basename "$lib") in
        libc.so*|libm.so*|libpthread.so*|libdl.so*|librt.so*|ld-linux*|libstdc++.so*|libgcc_s.so*) ;;
        *) cp -L "$lib" "$dest/lib/" ;;
    esac
done
# NVIDIA's Vulkan driver (libGLX_nvidia) links libglvnd's dispatch libraries,
# which a bare GPU image may lack: Debian's own, unpacked beside the rest
tmp=$(mktemp -d)
if (cd "$tmp" && apt-get download libglvnd0 libglx0 libegl1 >/dev/null 2>&1); then
    for deb in "$tmp"/*.deb; do dpkg -x "$deb" "$tmp/root"; done
    cp -P "$tmp"/root/usr/lib/*-linux-gnu/lib*.so.* "$dest/lib/"
else
    echo "bundle.sh: note: apt-get download libglvnd0 failed; the GPU machine must have libglvnd" >&2
fi
rm -rf "$tmp"
du -sh "$dest"

#!/bin/sh
# Unpacks a lavapipe with VK_KHR_ray_query next to the system's, without
# installing it: mesa-vulkan-drivers (and the libdrm it needs) from Debian 12's
# bookworm-backports, for the tests of the Vulkan backend's ray query
# traversal (RC_CONTEXT_VULKAN_RAY_QUERY). Debian 12's own lavapipe (Mesa
# 22.3) has no ray query, and replacing it would leave the default compute
# path untested on the driver Debian ships.
#
# Usage: tools/fetch-lavapipe-rq.sh [DIR]   (default ~/.cache/rangecast/lavapipe-rq)
# Writes DIR/lvp_icd.json, an ICD manifest naming the unpacked driver by its
# absolute path: tests select it with VK_ICD_FILENAMES=DIR/lvp_icd.json and
# LD_LIBRARY_PATH=DIR/root/usr/lib/<triple> (tests/CMakeLists.txt does both).
# apt runs on a private state folder under DIR: the system's sources and
# package lists are left alone, and root is not needed. A second run with the
# manifest present does nothing.
set -eu

dir=${1:-${HOME:-/tmp}/.cache/rangecast/lavapipe-rq}
if [ -f "$dir/lvp_icd.json" ]; then
  exit 0
fi
command -v apt-get >/dev/null && command -v dpkg-deb >/dev/null || {
  echo "fetch-lavapipe-rq: needs apt-get and dpkg-deb (Debian)" >&2
  exit 1
}
mkdir -p "$dir/apt/lists/partial" "$dir/apt/cache/archives/partial" "$dir/debs"
cat >"$dir/apt/sources.list" <<EOF
deb http://deb.debian.org/debian bookworm main
deb http://deb.debian.org/debian bookworm-backports main
EOF
opts="-o Dir::Etc::SourceList=$dir/apt/sources.list -o Dir::Etc::SourceParts=/dev/null
      -o Dir::State::Lists=$dir/apt/lists -o Dir::Cache=$dir/apt/cache -o Debug::NoLocking=1
      -o APT::Sandbox::User=root"
echo "fetch-lavapipe-rq: bookworm-backports lists into $dir/apt"
# shellcheck disable=SC2086
apt-get $opts -qq update
cd "$dir/debs"
# shellcheck disable=SC2086
apt-get $opts -qq download mesa-vulkan-drivers/bookworm-backports libdrm2/bookworm-backports \
  libdrm-amdgpu1/bookworm-backports
rm -rf "$dir/root"
for deb in ./*.deb; do
  dpkg-deb -x "$deb" "$dir/root"
done
lib=$(find "$dir/root" -name libvulkan_lvp.so | head -n 1)
[ -n "$lib" ] || {
  echo "fetch-lavapipe-rq: no libvulkan_lvp.so in the unpacked packages" >&2
  exit 1
}
# the packaged manifest names the library by file name: point at ours
sed "s#\"library_path\": *\"[^\"]*\"#\"library_path\": \"$lib\"#" \
  "$dir/root/usr/share/vulkan/icd.d/lvp_icd.json" >"$dir/lvp_icd.json.tmp"
mv "$dir/lvp_icd.json.tmp" "$dir/lvp_icd.json"
echo "fetch-lavapipe-rq: $(ls ./mesa-vulkan-drivers_*.deb) -> $dir/lvp_icd.json"
cd "$dir"
rm -rf "$dir/apt" "$dir/debs" # the package lists are most of the bytes

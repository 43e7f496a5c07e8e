#!/bin/sh
# Installs the Debian 12 packages a make target needs, or prints the exact
# apt-get line when not root.
# Usage: tools/setup-deps.sh demo|test|fuzz|cross|all
#                            |cross-aarch64|cross-armhf|cross-riscv64|multiarch-arm64
#   cross-<target>   that target's cross gcc, cross libc and qemu-user (make cross-<target>)
#   multiarch-arm64  arm64 packages next to the amd64 ones (dpkg --add-architecture
#                    arm64): cmocka and the Vulkan loader for make cross-aarch64
set -eu

profile=${1:-demo}
base="build-essential cmake pkg-config"
demo="$base libpng-dev libassimp-dev libmeshoptimizer-dev libcjson-dev"
# python3-matplotlib: tools/chart.py (make accuracy-docs); python3-numpy: the
# Python binding and its tests (bindings/python)
test="$demo python3-matplotlib python3-numpy libcmocka-dev libembree-dev libvulkan-dev mesa-vulkan-drivers glslang-tools clang valgrind"
# make fuzz: clang's libFuzzer runtime comes in its own package
fuzz="$base clang libclang-rt-14-dev libcjson-dev"
# qemu-user runs the cross-built tests; xz-utils unpacks the cmocka source
# package that make cross-armhf / cross-riscv64 build (toolchains/cmocka-from-source.sh).
cross_aarch64="$base gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user"
cross_armhf="$base gcc-arm-linux-gnueabihf libc6-dev-armhf-cross qemu-user xz-utils"
cross_riscv64="$base gcc-riscv64-linux-gnu libc6-dev-riscv64-cross qemu-user xz-utils"
cross="$cross_aarch64 $cross_armhf $cross_riscv64"
# glslangValidator runs on the build machine: the Vulkan kernels are SPIR-V,
# the same for every target.
multiarch_arm64="libcmocka-dev:arm64 libvulkan-dev:arm64 glslang-tools"
foreign=""
case "$profile" in
  demo) want=$demo ;;
  test) want=$test ;;
  fuzz) want=$fuzz ;;
  cross) want=$cross ;;
  cross-aarch64) want=$cross_aarch64 ;;
  cross-armhf) want=$cross_armhf ;;
  cross-riscv64) want=$cross_riscv64 ;;
  multiarch-arm64) want=$multiarch_arm64; foreign=arm64 ;;
  all) want="$test $fuzz $cross" ;;
  *) echo "usage: $0 demo|test|fuzz|cross|all|cross-aarch64|cross-armhf|cross-riscv64|multiarch-arm64" >&2; exit 2 ;;
esac

# The Vulkan ray query tests' driver (tools/fetch-lavapipe-rq.sh): unpacked
# under the user's cache, not installed; without it those tests are left out.
case "$profile" in
  test|all)
    sh "$(dirname "$0")/fetch-lavapipe-rq.sh" ||
      echo "setup-deps: no lavapipe with ray query; its tests will be left out" >&2 ;;
esac

missing=""
for p in $want; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done
[ -z "$missing" ] && exit 0

add_arch=""
if [ -n "$foreign" ] && ! dpkg --print-foreign-architectures | grep -qx "$foreign"; then
  add_arch=$foreign
fi

if [ "$(id -u)" -eq 0 ]; then
  echo "setup-deps: installing:$missing"
  export DEBIAN_FRONTEND=noninteractive
  if [ -n "$add_arch" ]; then
    echo "setup-deps: dpkg --add-architecture $add_arch"
    dpkg --add-architecture "$add_arch"
  fi
  case "$profile" in
    cross*|multiarch*)
      # A foreign architecture's index can be briefly inconsistent (seen with
      # armhf's security suite) and fail the whole update: let the install
      # decide whether what it needs is there.
      apt-get update -qq || echo "setup-deps: apt-get update failed; trying the install anyway" >&2 ;;
    *) apt-get update -qq ;;
  esac
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
else
  echo "setup-deps: missing packages. Run as root:" >&2
  if [ -n "$add_arch" ]; then
    echo "  sudo dpkg --add-architecture $add_arch && sudo apt-get update && sudo apt-get install -y$missing" >&2
  else
    echo "  sudo apt-get update && sudo apt-get install -y$missing" >&2
  fi
  exit 1
fi

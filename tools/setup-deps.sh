#!/bin/sh
# Installs the Debian 12 packages a make target needs, or prints the exact
# apt-get line when not root. Usage: tools/setup-deps.sh demo|test|cross|all
set -eu

profile=${1:-demo}
base="build-essential cmake pkg-config"
demo="$base libpng-dev libassimp-dev"
test="$demo libcmocka-dev libembree-dev libvulkan-dev mesa-vulkan-drivers glslang-tools clang valgrind"
cross="$base gcc-aarch64-linux-gnu gcc-arm-linux-gnueabihf gcc-riscv64-linux-gnu libc6-dev-arm64-cross libc6-dev-armhf-cross libc6-dev-riscv64-cross qemu-user"
case "$profile" in
  demo) want=$demo ;;
  test) want=$test ;;
  cross) want=$cross ;;
  all) want="$test $cross" ;;
  *) echo "usage: $0 demo|test|cross|all" >&2; exit 2 ;;
esac

missing=""
for p in $want; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done
[ -z "$missing" ] && exit 0

if [ "$(id -u)" -eq 0 ]; then
  echo "setup-deps: installing:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
else
  echo "setup-deps: missing packages. Run as root:" >&2
  echo "  sudo apt-get update && sudo apt-get install -y$missing" >&2
  exit 1
fi

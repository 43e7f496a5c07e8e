#!/bin/sh
# Size of the static core library (built-in backend only, -Os: CMake's
# MinSizeRel) for the host and each cross target, with threads on and off.
# Prints a markdown table:
#   archive   bytes of librangecast.a
#   text/data/bss   size(1) totals over the archive's objects
#   linked    text the core adds to a program: tests/static_link/main.c (one
#             static block, a two-triangle scene, one ray) linked with
#             --gc-sections against the archive, minus an empty main linked
#             the same way (dynamic libc, so libc itself is not counted)
#
#   tools/static-size.sh [target...]      targets: x86_64 aarch64 armhf riscv64 (default: all)
#
# Builds in build-static-size/<target>-threads-<on|off>. A target whose cross
# compiler is missing is listed as such (tools/setup-deps.sh cross installs them).
set -eu
cd "$(dirname "$0")/.."
root=$(pwd)
out=$root/build-static-size
jobs=$(nproc 2>/dev/null || echo 2)
targets=${*:-x86_64 aarch64 armhf riscv64}
mkdir -p "$out"

triple_of() {
  case $1 in
    x86_64) echo "" ;;
    aarch64) echo aarch64-linux-gnu ;;
    armhf) echo arm-linux-gnueabihf ;;
    riscv64) echo riscv64-linux-gnu ;;
    *) echo "static-size: unknown target $1" >&2; exit 2 ;;
  esac
}

text_of() { "$1" "$2" | awk 'NR == 2 { print $1 }'; }

echo "| target | threads | librangecast.a (bytes) | text | data | bss | linked text |"
echo "|---|---|---:|---:|---:|---:|---:|"
for t in $targets; do
  triple=$(triple_of "$t")
  if [ -n "$triple" ]; then
    cc=$triple-gcc
    sizeprog=$triple-size
    toolchain="-DCMAKE_TOOLCHAIN_FILE=$root/toolchains/$triple.cmake"
  else
    cc=${CC:-cc}
    sizeprog=size
    toolchain=""
  fi
  if ! command -v "$cc" >/dev/null 2>&1; then
    echo "| $t | - | ($cc not installed) | | | | |"
    continue
  fi
  for threads in ON OFF; do
    dir=$out/$t-threads-$(echo $threads | tr A-Z a-z)
    # shellcheck disable=SC2086
    cmake -S "$root" -B "$dir" $toolchain -DCMAKE_BUILD_TYPE=MinSizeRel \
      -DRANGECAST_WITH_THREADS=$threads -DRANGECAST_WITH_EMBREE=OFF -DRANGECAST_WITH_VULKAN=OFF \
      -DRANGECAST_BUILD_SHARED=OFF -DRANGECAST_BUILD_TOOLS=OFF -DRANGECAST_BUILD_TESTS=OFF >"$dir.log" 2>&1 ||
      { echo "static-size: configuring $t failed, see $dir.log" >&2; exit 1; }
    cmake --build "$dir" -j "$jobs" --target rangecast_static >>"$dir.log" 2>&1 ||
      { echo "static-size: building $t failed, see $dir.log" >&2; exit 1; }
    lib=$dir/librangecast.a
    bytes=$(wc -c <"$lib" | tr -d ' ')
    # size -t: the last line holds the totals (text data bss dec hex)
    totals=$("$sizeprog" -t "$lib" | tail -n 1)
    text=$(echo "$totals" | awk '{ print $1 }')
    data=$(echo "$totals" | awk '{ print $2 }')
    bss=$(echo "$totals" | awk '{ print $3 }')
    # shellcheck disable=SC2086
    flags=$(sed -n 's/^CMAKE_C_FLAGS:STRING=//p' "$dir/CMakeCache.txt")
    libs="-lm"
    [ "$threads" = ON ] && libs="$libs -pthread"
    printf 'int main(void) { return 0; }\n' >"$dir/empty.c"
    # shellcheck disable=SC2086
    $cc $flags -Os -std=c99 -o "$dir/empty" "$dir/empty.c" -Wl,--gc-sections $libs
    # shellcheck disable=SC2086
    $cc $flags -Os -std=c99 -I"$root/include" -o "$dir/static_link" "$root/tests/static_link/main.c" \
      -Wl,--gc-sections -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc "$lib" $libs
    linked=$(( $(text_of "$sizeprog" "$dir/static_link") - $(text_of "$sizeprog" "$dir/empty") ))
    echo "| $t | $(echo $threads | tr A-Z a-z) | $bytes | $text | $data | $bss | $linked |"
  done
done

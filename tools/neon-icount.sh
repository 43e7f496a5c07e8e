#!/bin/sh
# Instruction counts of the SIMD box tests of the 4-wide BVH, without a board:
# guest instructions executed under qemu-user for aarch64 (NEON), and
# instructions executed under valgrind (callgrind Ir) for x86_64 (SSE2), each
# against the plain-C box tests (-DRC__PACKET_FORCE_SCALAR
# -DRC__WIDE_FORCE_SCALAR -fno-tree-vectorize: plain C, no auto-vectorised
# NEON/SSE either) and against single rays without packets
# (-DRANGECAST_NO_PACKETS, SIMD box tests), on one fixed workload
# (tools/neon-workload.c: 9,800-triangle UV sphere, 2 VLP-16 scans, 1 thread).
# Every build has projected scans off (RANGECAST_PROJECTED_SCANS): since
# session 31 a map of at most one triangle per ray takes them instead of the
# tree, and this counts the tree's traversals.
#
#   sh tools/neon-icount.sh            both targets
#   sh tools/neon-icount.sh aarch64    only one (aarch64 | x86_64)
#
# Needs cmake, aarch64-linux-gnu-gcc (with its static libc), qemu-aarch64,
# gcc, valgrind, python3. Builds into build-icount-<target>-<variant>/, prints
# a markdown table on stdout (progress on stderr). The qemu logs go through a
# FIFO to tools/qemu-icount.py, so nothing large is written to disk.
#
# Each program runs twice: whole ("simulate") and with argument 0, which stops
# before rc_simulate ("setup": sphere, BVH build, sensor). simulate - setup is
# the count of rc_simulate alone; the ratios are taken on it.
set -eu

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
TARGETS=${1:-"aarch64 x86_64"}
QEMU_CPU=${QEMU_CPU:-cortex-a53}
VARIANTS="simd scalar single"

log() { echo "neon-icount: $*" >&2; }

variant_flags() {
    case $1 in
    simd) echo "" ;;
    scalar) echo "-DRC__PACKET_FORCE_SCALAR -DRC__WIDE_FORCE_SCALAR -fno-tree-vectorize" ;;
    single) echo "-DRANGECAST_NO_PACKETS" ;;
    esac
}

# build TARGET VARIANT: library (CMake, Release, static only) + workload
build() {
    t=$1 v=$2 dir=build-icount-$1-$2
    vf=$(variant_flags "$v")
    case $t in
    aarch64)
        tc="-DCMAKE_TOOLCHAIN_FILE=$ROOT/toolchains/aarch64-linux-gnu.cmake"
        cflags="-march=armv8-a"
        cc=aarch64-linux-gnu-gcc ;;
    x86_64)
        tc=""
        cflags=""
        cc=${CC:-gcc} ;;
    esac
    log "build $dir"
    # shellcheck disable=SC2086
    cmake -S . -B "$dir" $tc -DCMAKE_BUILD_TYPE=Release \
        -DRANGECAST_BUILD_TOOLS=OFF -DRANGECAST_BUILD_TESTS=OFF -DRANGECAST_BUILD_SHARED=OFF \
        -DRANGECAST_WITH_EMBREE=OFF -DRANGECAST_WITH_VULKAN=OFF -DRANGECAST_WITH_THREADS=OFF \
        -DRANGECAST_PROJECTED_SCANS=OFF "-DCMAKE_C_FLAGS=$cflags $vf" >/dev/null
    cmake --build "$dir" -j "$JOBS" >/dev/null
    # shellcheck disable=SC2086
    $cc -O2 $cflags -static -Iinclude tools/neon-workload.c "$dir/librangecast.a" -lm \
        -o "$dir/neon-workload"
}

# count TARGET DIR [ARG]: instructions executed by DIR/neon-workload [ARG]
count() {
    t=$1 dir=$2
    shift 2
    case $t in
    aarch64)
        fifo=$dir/qemu-log.fifo
        rm -f "$fifo" && mkfifo "$fifo"
        python3 tools/qemu-icount.py "$fifo" >"$dir/icount.txt" 2>"$dir/icount.err" &
        pid=$!
        qemu-aarch64 -cpu "$QEMU_CPU" -L /usr/aarch64-linux-gnu \
            -E LD_LIBRARY_PATH=/usr/aarch64-linux-gnu/lib \
            -d in_asm,exec,nochain -D "$fifo" "$dir/neon-workload" "$@" >"$dir/out.txt"
        wait "$pid"
        rm -f "$fifo"
        cat "$dir/icount.txt" ;;
    x86_64)
        valgrind --tool=callgrind --callgrind-out-file="$dir/callgrind.out" \
            "$dir/neon-workload" "$@" >"$dir/out.txt" 2>"$dir/valgrind.err"
        sed -n 's/^summary: *\([0-9]*\).*/\1/p' "$dir/callgrind.out" ;;
    esac
}

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }
grp() { echo "$1" | sed ':a;s/\B[0-9]\{3\}\>/,&/;ta'; }

TABLE=""
for t in $TARGETS; do
    for v in $VARIANTS; do build "$t" "$v"; done
    ref_sum=""
    for v in $VARIANTS; do
        dir=build-icount-$t-$v
        log "run $dir (setup only)"
        setup=$(count "$t" "$dir" 0)
        log "run $dir (whole)"
        whole=$(count "$t" "$dir")
        sum=$(cat "$dir/out.txt")
        # every variant must give the same ranges
        if [ -z "$ref_sum" ]; then ref_sum=$sum
        elif [ "$sum" != "$ref_sum" ]; then
            log "$dir: results differ: '$sum' vs '$ref_sum'"; exit 1
        fi
        eval "whole_$v=$whole setup_$v=$setup sim_$v=$((whole - setup))"
    done
    for v in $VARIANTS; do
        eval "w=\$whole_$v s=\$sim_$v"
        case $v in
        simd) if [ "$t" = aarch64 ]; then name="NEON packets"; else name="SSE2 packets"; fi ;;
        scalar) name="scalar packets (forced)" ;;
        single) name="single rays (no packets)" ;;
        esac
        TABLE="$TABLE| $t | $name | $(grp "$w") | $(grp "$s") | $(ratio "$s" "$sim_single") | $(ratio "$sim_scalar" "$s") |
"
    done
    log "$t: $ref_sum"
done

echo "| target | variant | instructions, whole program | instructions, rc_simulate | ratio vs single rays | scalar / this |"
echo "|---|---|---:|---:|---:|---:|"
printf '%s' "$TABLE"

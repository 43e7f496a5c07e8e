#!/bin/sh
# On a machine with a GPU and its Vulkan driver: rangecast bench on the GPU
# (issue 4's target: VLP-16 on the 1M-triangle sphere, 10,000 poses a call,
# ranges downloaded to the host), the ranges of five sensors against the
# built-in backend's, then the test suites on its Vulkan device.
#   sh tools/device/gpu-run.sh BUNDLE OUTDIR [bench|split|parity|tests|all]
# BUNDLE is tools/device/bundle.sh's folder. Logs and JSON lines go to OUTDIR;
# a summary is printed last. split (not in all) times the kernel's stages by
# leaving one out (RANGECAST_VULKAN_SKIP) and the float-only kernel, at 1k and
# 1M. bench logs the driver's statistics of each kernel (registers, local
# memory: RANGECAST_VULKAN_PIPELINE_STATS) into bench.err.
set -u
bundle=$(cd "$1" && pwd)
out=$2
what=${3:-all}
mkdir -p "$out"
export LD_LIBRARY_PATH="$bundle/lib"
for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json \
           /etc/vulkan/icd.d/nvidia_icd.json; do
    if [ -f "$icd" ]; then export VK_DRIVER_FILES="$icd" VK_ICD_FILENAMES="$icd"; break; fi
done
export RANGECAST_LOG=info
rc=$bundle/bin/rangecast
summary=$out/summary.txt
: >"$summary"
{
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader 2>&1
    echo "ICD: ${VK_DRIVER_FILES:-none found}; CPUs: $(nproc)"
} | tee -a "$summary"

if [ "$what" = bench ] || [ "$what" = all ]; then
    # issue 4's figure, then the other sizes; stderr (the device note) kept
    for n in 1M 1k 10k 100k 10M; do
        RANGECAST_VULKAN_PIPELINE_STATS=1 "$rc" bench --backend vulkan --triangles "$n" --pose-count 10000 --poses-per-call 10000 --repeat 5 \
            >>"$out/bench.jsonl" 2>>"$out/bench.err"
        echo "bench vulkan $n: exit $?; $(tail -n 1 "$out/bench.jsonl" | tr ',' '\n' | \
grep -E 'scans_per_s|range_err_p999|hit_mismatch|build_s' | tr '\n' ' ')" | tee -a "$summary"
    done
fi
if [ "$what" = split ]; then
    # where the kernel's time goes: each stage's cost is the full kernel's time
    # less the time without it (the results of the skipping runs are wrong)
    for n in 1k 1M; do
        for mode in full walk refine float-only full; do
            case $mode in
                walk|refine) set -- env RANGECAST_VULKAN_SKIP=$mode ;;
                float-only) set -- env RANGECAST_VULKAN_NO_FP64=1 ;;
                *) set -- env ;;
            esac
            "$@" "$rc" bench --backend vulkan --triangles "$n" --pose-count 10000 --poses-per-call 10000 --repeat 5 \
                >"$out/one.json" 2>>"$out/bench.err"
            sed "s/^{/{\"split\":\"$mode\",/" "$out/one.json" >>"$out/split.jsonl"
            echo "split $n $mode: $(tr ',' '\n' <"$out/one.json" | grep -E '"scans_per_s' | tr '\n' ' ')" | tee -a "$summary"
        done
    done
    rm -f "$out/one.json"
fi
if [ "$what" = parity ] || [ "$what" = all ]; then
    # the float64 kernel's ranges must be the built-in backend's to the bit
    # (a driver's inexact division once broke that: architecture.md)
    for s in vlp16 d435 os1-64 livox-mid40 random-ondn; do
        for b in bvh vulkan; do
            "$rc" bench --backend "$b" --triangles 100k --pose-count "${PARITY_POSES:-300}" --repeat 1 --sensor "$s" \
                --ranges-out "$out/$b.f32" >/dev/null 2>>"$out/bench.err"
        done
        echo "ranges $s, bvh against vulkan: $(cmp -l "$out/bvh.f32" "$out/vulkan.f32" 2>&1 | wc -l) bytes differ \
($(($(wc -c <"$out/bvh.f32") / 4)) rays)" | tee -a "$summary"
    done
    rm -f "$out/bvh.f32" "$out/vulkan.f32"
fi

if [ "$what" = tests ] || [ "$what" = all ]; then
    # every suite that runs a Vulkan context (the CPU backends too: some
    # suites compare against them), into one log
    log=$out/tests.log
    : >"$log"
    for t in test_vulkan_backend test_vulkan_parity test_vulkan_device test_vulkan_device_results \
             test_vulkan_ray_query test_scenes test_stability test_noise test_dynamic_maps test_baked test_ouster \
             test_bad_input test_context; do
        [ -x "$bundle/bin/$t" ] || continue
        start=$(date +%s)
        echo "==== $t" >>"$log"
        timeout 600 "$bundle/bin/$t" >"$out/one.log" 2>&1
        s=$?
        cat "$out/one.log" >>"$log"
        echo "$t: exit $s, $(( $(date +%s) - start )) s, $(grep -c '\[       OK \]' "$out/one.log") ok, \
$(grep -c '\[  FAILED  \]' "$out/one.log") failed lines" | tee -a "$summary"
    done
    start=$(date +%s)
    echo "==== test_dynamic_maps (staged)" >>"$log"
    RANGECAST_VULKAN_STAGING=1 timeout 600 "$bundle/bin/test_dynamic_maps" >>"$log" 2>&1
    echo "test_dynamic_maps (staged): exit $?, $(( $(date +%s) - start )) s" | tee -a "$summary"
    rm -f "$out/one.log"
fi

echo "== summary"; cat "$summary"

#!/bin/sh
# `rangecast bake` and baked maps (.rcmap) in the other commands, as a user
# runs them: the baked map gives the PLY map's ranges bit for bit (bench
# --ranges-out), bench reports its size, simulate and info read it, and a
# corrupt, truncated or misnamed map gets its exit status and message with no
# output file left behind.
#   check_bake.sh RANGECAST WORKDIR [--backend B]
set -eu
RC=$1
WORK=$2
shift 2
BACKEND=${*:-}
. "$(dirname "$0")/common.sh"

run 0 "" "$RC" gen --sphere 10k --radius 20 -o sphere.ply
run 0 "" "$RC" gen --poses 20 --radius 10 --seed 5 -o poses.bin
run 0 "" "$RC" bake --map sphere.ply --out sphere.rcmap --threads 2
grep -q "sphere.rcmap: 9,996 triangles" out.txt || { cat out.txt; fail "bake summary"; }
grep -q "loads in" out.txt || fail "bake reports the load time"
size=$(wc -c <sphere.rcmap)
[ $((size % 64)) -eq 0 ] || fail "a baked map is a multiple of 64 bytes, not $size"
[ "$(head -c 6 sphere.rcmap | tail -c 5)" = "RCMAP" ] || fail "magic"
ls ./*.part* 2>/dev/null && fail "bake left a temporary file"

# the same ranges from the PLY map and from the baked one, and the same again
# on a second bake (the bytes are deterministic)
run 0 "" "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --threads 2 --ranges-out ply.f32 $BACKEND
grep -Eq '"baked_map_bytes":null[,}]' out.txt || fail "bench on a PLY map: baked_map_bytes is null"
run 0 "" "$RC" bench --map sphere.rcmap --poses poses.bin --repeat 1 --threads 2 --ranges-out baked.f32 $BACKEND
grep -Eq "\"baked_map_bytes\":$size[,}]" out.txt || { cat out.txt; fail "bench reports the baked map's bytes"; }
cmp ply.f32 baked.f32 || fail "a baked map changed the ranges"
# one pose a call (a robot's call) gives the same ranges as the batches
run 0 "" "$RC" bench --map sphere.rcmap --poses poses.bin --repeat 1 --threads 2 --poses-per-call 1 \
    --ranges-out one.f32 $BACKEND
grep -Eq '"poses_per_call":1[,}]' out.txt || { cat out.txt; fail "bench reports poses_per_call 1"; }
cmp ply.f32 one.f32 || fail "one pose a call changed the ranges"
# the map copied into the arena (the built-in backend renumbers the copy's
# vertices at commit) gives the same ranges, and bench says how it went in
run 0 "" "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --threads 2 --mesh copy --ranges-out copy.f32 $BACKEND
grep -Eq '"mesh":"copy"[,}]' out.txt || { cat out.txt; fail "bench reports mesh copy"; }
cmp ply.f32 copy.f32 || fail "a copied map changed the ranges"
run 2 "--mesh: expected reference or copy, got 'flash'" "$RC" bench --mesh flash
# the map cut into meshes of its own (a world of separate objects; 40 takes
# the built-in backend's walk of the top-level tree, 5 its packets mesh by
# mesh), referenced or copied: the same ranges, and bench says how many
for parts in 5 40; do
    run 0 "" "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --threads 2 --meshes $parts \
        --ranges-out parts.f32 $BACKEND
    grep -Eq "\"ranges_consistent\":true,.*\"mesh\":\"reference\",\"meshes\":$parts}" out.txt ||
        { cat out.txt; fail "bench reports --meshes $parts, its ranges consistent"; }
    cmp ply.f32 parts.f32 || fail "the map as $parts meshes changed the ranges"
done
run 0 "" "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --threads 2 --meshes 40 --mesh copy \
    --ranges-out parts.f32 $BACKEND
grep -Eq '"mesh":"copy","meshes":40}' out.txt || { cat out.txt; fail "bench reports --meshes 40 --mesh copy"; }
cmp ply.f32 parts.f32 || fail "the map as 40 copied meshes changed the ranges"
run 2 "--meshes: expected a count >= 1, got '0'" "$RC" bench --meshes 0
run 2 "--meshes 20000: the map has 9996 triangles" "$RC" bench --map sphere.ply --meshes 20000
run 2 "--meshes: sphere.rcmap is a baked map, which keeps the meshes it was baked with" \
    "$RC" bench --map sphere.rcmap --meshes 2
run 2 "--poses-per-call: expected a count >= 1, got '0'" "$RC" bench --poses-per-call 0
# an explicit --poses-per-call is taken as given, past the 128 MiB of ranges
# that size the default (82 D435 scans): a GPU wants 10,000 VLP-16 scans a call
run 0 "" "$RC" bench --triangles 1k --pose-count 83 --poses-per-call 83 --repeat 1 --threads 2 --sensor d435 $BACKEND
grep -Eq '"poses_per_call":83[,}]' out.txt || { cat out.txt; fail "an explicit --poses-per-call is taken as given"; }
# --results-on-device keeps the timed calls' ranges in Vulkan's device buffer
run 2 "--results-on-device needs --backend vulkan" "$RC" bench --results-on-device --backend bvh
if "$RC" help | grep -q "^Backends in this library:[^(]*vulkan"; then
    run 0 "" "$RC" bench --map sphere.rcmap --poses poses.bin --repeat 1 --threads 2 --backend vulkan \
        --results-on-device --ranges-out device.f32
    grep -Eq '"results_on_device":true[,}]' out.txt || { cat out.txt; fail "bench reports results_on_device"; }
    grep -q '"ranges_consistent":true' out.txt || { cat out.txt; fail "results on the device: ranges consistent"; }
    cmp ply.f32 device.f32 || fail "results on the device changed the ranges"
    # RANGECAST_LOG=info prints the library's notes: the device it chose
    run 0 "library note: vulkan: " env RANGECAST_LOG=info "$RC" bench --triangles 1k --pose-count 2 --repeat 1 \
        --backend vulkan
fi
# a short-range sensor on the standard sphere: every ray misses, and bench says why
run 0 "no ray returned: lds-01 reaches 3.5 m" "$RC" bench --triangles 1k --pose-count 2 --repeat 1 --sensor lds-01 $BACKEND
grep -Eq '"hit_fraction":0[,}]' out.txt || { cat out.txt; fail "lds-01 on the standard sphere returns nothing"; }
run 0 "" "$RC" bake --map sphere.ply --out again.rcmap --threads 1
cmp sphere.rcmap again.rcmap || fail "two bakes of one map differ"
# bench --help lists every key the JSON line has
run 0 "" "$RC" bench --map sphere.rcmap --poses poses.bin --repeat 1 --threads 1 $BACKEND
keys=$(tr ',{' '\n\n' <out.txt | sed -n 's/^"\([a-z_0-9]*\)":.*/\1/p')
"$RC" bench --help >help.txt
for k in $keys; do
    case $k in tool | version) continue ;; esac
    grep -qw "$k" help.txt || fail "bench --help does not list the JSON key $k"
done

# simulate and info read it
run 0 "" "$RC" simulate --map sphere.rcmap --pose 0,0,0 -o centre.pcd --ascii --fields range $BACKEND
grep -qx "POINTS 14400" centre.pcd || fail "simulate on a baked map: point count"
run 0 "" "$RC" info --map sphere.rcmap --backend bvh
grep -q "a baked map of" out.txt || fail "info says the map is baked"

# bad maps: each refused with its reason, nothing written
cp sphere.rcmap flipped.rcmap
printf '\377' | dd of=flipped.rcmap bs=1 seek=$((size / 2)) conv=notrunc 2>/dev/null
run 1 "checksum" "$RC" bench --map flipped.rcmap --poses poses.bin --repeat 1 --ranges-out bad.f32 $BACKEND
[ ! -e bad.f32 ] || fail "bench on a corrupt map wrote ranges"
head -c $((size - 64)) sphere.rcmap >short.rcmap
run 1 "truncated" "$RC" simulate --map short.rcmap --pose 0,0,0 -o bad.pcd $BACKEND
[ ! -e bad.pcd ] || fail "simulate on a truncated map wrote a cloud"
cp sphere.ply notbaked.rcmap
run 1 "not a baked map" "$RC" info --map notbaked.rcmap
run 2 ".rcmap" "$RC" bake --map sphere.ply --out sphere.bin
run 1 "No such file" "$RC" bake --map sphere.ply --out no/such/dir/x.rcmap
[ ! -e no ] || fail "bake made a folder"
run 1 "" "$RC" bake --map missing.ply --out x.rcmap
[ ! -e x.rcmap ] || fail "bake of a missing map wrote a file"
# a map of two meshes (a closed room and a pillar in it, baked with the
# Python binding: Scene.add_mesh twice, then Scene.bake): every command reads
# it as one map, and bench's float64 reference finds each hit's triangle by
# (geom id, prim id)
run 0 "" "$RC" bench --map "$DATA/room_pillar.rcmap" --pose-count 8 --repeat 1 --threads 2 $BACKEND
{ grep -q '"triangles":24,' out.txt && grep -q '"ranges_consistent":true' out.txt &&
    grep -Eq '"range_err_p999_m":[0-9.]+e-0[5-9],' out.txt; } || { cat out.txt; fail "bench on a two-mesh baked map"; }
run 0 "" "$RC" simulate --map "$DATA/room_pillar.rcmap" --pose 0,0,0 -o room.pcd --ascii $BACKEND
grep -qx "POINTS 14400" room.pcd || fail "two-mesh baked map: every VLP-16 ray hits the closed room"
awk 'f && $1 > 1.999 && $1 < 2.001 && $2 > -1 && $2 < 1 { pillar++ } /^DATA/ { f = 1 } END { exit pillar > 0 ? 0 : 1 }' \
    room.pcd || fail "two-mesh baked map: the pillar (geometry 1) is hit"
echo "check_bake: ok"

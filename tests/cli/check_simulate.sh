#!/bin/sh
# `rangecast gen` and `rangecast simulate` end to end, as a user runs them:
# the files they write (PLY map, raw poses, PCD and PLY clouds, PNG image) are
# read back and their contents checked against the closed 20 m sphere's
# geometry; every bad input gets its exit status and a message naming it, and
# leaves no output file behind.
#   check_simulate.sh RANGECAST WORKDIR [--backend B]
set -eu
RC=$1
WORK=$2
shift 2
BACKEND=${*:-}
. "$(dirname "$0")/common.sh"

run 0 "" "$RC" gen --sphere 1k --radius 20 -o sphere.ply
run 0 "" "$RC" gen --poses 3 --radius 10 --seed 7 -o poses.bin
[ "$(wc -c <poses.bin)" -eq 84 ] || fail "3 poses are not 84 bytes"

# One VLP-16 scan from the centre, sensor frame, ascii PCD with range and ring.
# Every ray meets the sphere; the facets lie between the inscribed radius of the
# coarse 1k sphere (above 19.5 m) and 20 m; |point| is the range; ring is the
# row, 900 points each.
run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o centre.pcd --ascii --fields range,ring $BACKEND
grep -qx "FIELDS x y z range ring" centre.pcd || fail "PCD fields"
grep -qx "POINTS 14400" centre.pcd || fail "PCD point count"
grep -qx "DATA ascii" centre.pcd || fail "PCD data line"
awk 'f {
        n++
        r = sqrt($1 * $1 + $2 * $2 + $3 * $3)
        if ($4 < 19.5 || $4 > 20.0001) { print "range " $4 " off the sphere"; bad = 1 }
        if (r - $4 > 1e-4 || $4 - r > 1e-4) { print "|point| " r " vs range " $4; bad = 1 }
        if ($5 < 0 || $5 > 15) { print "ring " $5; bad = 1 }
        ring[$5]++
        # row 0 looks 15 degrees down, row 15 15 degrees up
        if ($5 == 0 && $3 > -0.25 * r) { print "row 0 not looking down: z " $3; bad = 1 }
        if ($5 == 15 && $3 < 0.25 * r) { print "row 15 not looking up: z " $3; bad = 1 }
     }
     /^DATA/ { f = 1 }
     END {
        if (n != 14400) { print "records: " n; bad = 1 }
        for (k = 0; k < 16; k++) if (ring[k] != 900) { print "ring " k ": " ring[k] " points"; bad = 1 }
        exit bad
     }' centre.pcd || fail "centre.pcd contents"

# Noise (rc_sensor_set_noise through --noise): the same scan with 5 cm of
# range noise, point for point against the clean one (the residuals' mean near
# 0 and deviation near 0.05, |point| still the range); the same seed gives
# the same file, another seed another; dropout 0.1 keeps about 90% of the
# returns.
run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o noisy.pcd --ascii --fields range,ring --noise 0.05 \
    --seed 3 $BACKEND
sed -n '/^DATA/,$p' centre.pcd | tail -n +2 >clean.txt
sed -n '/^DATA/,$p' noisy.pcd | tail -n +2 >noisy.txt
paste -d ' ' clean.txt noisy.txt | awk '{
        d = $9 - $4; n++; s += d; s2 += d * d
        r = sqrt($6 * $6 + $7 * $7 + $8 * $8)
        if (r - $9 > 1e-4 || $9 - r > 1e-4) { print "noisy |point| " r " vs range " $9; bad = 1 }
     }
     END {
        m = s / n; sd = sqrt(s2 / n - m * m)
        if (n != 14400 || m > 0.002 || m < -0.002 || sd < 0.047 || sd > 0.053) {
            print "noise residuals: n " n " mean " m " sd " sd; bad = 1
        }
        exit bad
     }' || fail "noisy.pcd against centre.pcd"
run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o noisy2.pcd --ascii --fields range,ring --noise 0.05 \
    --seed 3 $BACKEND
cmp -s noisy.pcd noisy2.pcd || fail "the same seed gave another cloud"
run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o noisy3.pcd --ascii --fields range,ring --noise 0.05 \
    --seed 4 $BACKEND
cmp -s noisy.pcd noisy3.pcd && fail "another seed gave the same cloud"
run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o dropped.pcd --ascii --dropout 0.1 $BACKEND
kept=$(sed -n 's/^POINTS //p' dropped.pcd)
[ "$kept" -gt 12780 ] && [ "$kept" -lt 13140 ] || fail "dropout 0.1 kept $kept of 14400 returns"

# A large map's commit shows its progress on a terminal only: none when
# stderr is a file; through script(1), which gives the program a terminal, the
# build counts to 100%.
run 0 "" "$RC" gen --sphere 600k -o big.ply
run 0 "" "$RC" simulate --map big.ply --pose 0,0,0 -o big_scan.ply $BACKEND
! grep -q "build" err.txt || fail "progress printed to a log"
if command -v script >/dev/null 2>&1; then
    script -qc "'$RC' simulate --map big.ply --pose 0,0,0 -o big_scan.ply $BACKEND" /dev/null >tty.txt 2>&1 ||
        { cat tty.txt >&2; fail "simulate on a terminal"; }
    grep -q "build 100%" tty.txt || { cat tty.txt >&2; fail "no progress on a terminal"; }
fi

# The sensor turned 90 degrees about z (qz = qw = sqrt(1/2)) and moved: in the
# map frame every point is still on the sphere.
run 0 "" "$RC" simulate --map sphere.ply --pose 3,-2,1,0,0,0.70710678,0.70710678 --frame map -o moved.pcd \
    --ascii $BACKEND
awk 'f { n++; r = sqrt($1 * $1 + $2 * $2 + $3 * $3); if (r < 19.5 || r > 20.0001) { print "|p| " r; bad = 1 } }
     /^DATA/ { f = 1 }
     END { if (n != 14400) { print "records: " n; bad = 1 } exit bad }' moved.pcd || fail "moved.pcd contents"

# Three poses from the file, binary PLY: 3 x 14,400 records of x y z range.
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o three.ply --fields range $BACKEND
grep -q "^format binary_little_endian 1.0" three.ply || fail "PLY format line"
grep -q "^element vertex 43200" three.ply || fail "PLY vertex count"
header=$(awk '{ n += length($0) + 1 } /^end_header/ { print n; exit }' three.ply)
[ "$(wc -c <three.ply)" -eq $((header + 43200 * 16)) ] || fail "three.ply is not header + 43,200 x 16 bytes"
# The same poses a call at a time, or two (--poses-per-call): the cloud goes
# to the file a batch at a time, through a body file beside it that is gone
# afterwards, and the files are the same byte for byte.
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o three1.ply --fields range --poses-per-call 1 $BACKEND
cmp three.ply three1.ply || fail "three.ply written a scan at a time differs"
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o three2.pcd --ascii --fields range,ring $BACKEND
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o three2b.pcd --ascii --fields range,ring \
    --poses-per-call 2 $BACKEND
cmp three2.pcd three2b.pcd || fail "three2.pcd written two scans at a time differs"
ls ./*.partial >/dev/null 2>&1 && fail "a body file was left behind: $(ls ./*.partial)"
# A file a scan (-o with one %d or %0Nd): each holds its scan's records, the
# slice of three.ply's; only as many files as poses; other '%' refused.
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o 'scan_%02d.ply' --fields range --poses-per-call 2 \
    $BACKEND
for k in 0 1 2; do
    grep -q "^element vertex 14400" "scan_0$k.ply" || fail "scan_0$k.ply: PLY vertex count"
    h=$(awk '{ n += length($0) + 1 } /^end_header/ { print n; exit }' "scan_0$k.ply")
    tail -c +$((h + 1)) "scan_0$k.ply" >got.bin
    tail -c +$((header + 1 + k * 14400 * 16)) three.ply | head -c $((14400 * 16)) >want.bin
    cmp got.bin want.bin || fail "scan_0$k.ply is not scan $k of three.ply"
done
[ ! -e scan_03.ply ] || fail "a fourth scan file for three poses"
run 2 "one %d or %0Nd" "$RC" simulate --map sphere.ply --pose 0,0,0 -o 'bad_%s.pcd'
# The same poses as a TUM trajectory (gen writes one for .tum; lines
# 'timestamp x y z qx qy qz qw'): the same cloud. A bad line is named.
run 0 "" "$RC" gen --poses 3 --radius 10 --seed 7 -o poses.tum
[ "$(grep -vc '^#' poses.tum)" -eq 3 ] || fail "poses.tum does not hold 3 poses"
run 0 "" "$RC" simulate --map sphere.ply --poses poses.tum -o three_tum.ply --fields range $BACKEND
cmp three.ply three_tum.ply || fail "the TUM trajectory's cloud differs from the raw poses'"
# The map copied into the arena (--mesh copy: its vertices renumbered in leaf
# order): the same cloud.
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o three_copy.ply --fields range --mesh copy $BACKEND
cmp three.ply three_copy.ply || fail "the copied map's cloud differs from the referenced map's"
run 2 "--mesh: expected reference or copy, got 'foo'" "$RC" simulate --map sphere.ply --pose 0,0,0 -o r.pcd --mesh foo
printf '0.0 1 2 3 0 0 0 1\n0.1 1 2 3 0 0 1\n' >short.tum
run 1 "short.tum:2: 7 numbers" "$RC" simulate --map sphere.ply --poses short.tum -o q.pcd

# bench on the same files: --ranges-out holds float32 [pose][row][column]
# (3 x 16 x 900), every range between the nearest and farthest the sphere can
# be from a pose inside the 10 m ball; the backend under test on 2 threads
# gives the bits of the built-in backend on 1.
run 0 '' "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --threads 2 --ranges-out ranges.bin $BACKEND
grep -q '"poses":3,' out.txt || fail "bench JSON: poses"
grep -q '"hit_fraction":1,' out.txt || fail "bench JSON: hit_fraction"
grep -q '"ranges_consistent":true' out.txt || fail "bench JSON: ranges_consistent"
[ "$(wc -c <ranges.bin)" -eq $((3 * 14400 * 4)) ] || fail "ranges.bin is not 3 x 14,400 float32"
od -An -v -f ranges.bin | awk '{ for (i = 1; i <= NF; i++) { n++; if (!($i >= 9.5 && $i <= 30.0001)) bad++ } }
    END { if (n != 43200 || bad) { print n " ranges, " bad " out of [9.5, 30]"; exit 1 } }' || fail "ranges.bin values"
run 0 '' "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --threads 1 --ranges-out ref.bin --backend bvh
cmp ranges.bin ref.bin || fail "ranges differ from the built-in backend's on one thread"
# the first pose's first ray (row 0, column 0) is the range the simulate
# command's first point has at that pose
run 0 "" "$RC" simulate --map sphere.ply --poses poses.bin -o first.pcd --ascii --fields range $BACKEND
first=$(od -An -v -f -N 4 ranges.bin | tr -d ' ')
awk -v want="$first" 'f { d = $4 - want; if (d < 0) d = -d; exit !(d <= 1e-6 * want) } /^DATA/ { f = 1 }' first.pcd ||
    fail "simulate's first range is not bench's $first"

# Other mesh formats come through Assimp when the program has it: a 10 m cube
# as OBJ, seen from off-centre; in the map frame every point lies on a face.
if "$RC" help | grep -q "obj, stl"; then
    cat >cube.obj <<'OBJ'
v -5 -5 -5
v 5 -5 -5
v 5 5 -5
v -5 5 -5
v -5 -5 5
v 5 -5 5
v 5 5 5
v -5 5 5
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
OBJ
    run 0 "" "$RC" simulate --map cube.obj --pose 0.5,-1,0.25 --frame map --ascii -o cube.pcd $BACKEND
    awk 'function abs(v) { return v < 0 ? -v : v }
         f { n++; m = abs($1); if (abs($2) > m) m = abs($2); if (abs($3) > m) m = abs($3)
             if (abs(m - 5) > 1e-4) { print "point " $1 " " $2 " " $3 " off the cube"; bad = 1 } }
         /^DATA/ { f = 1 }
         END { if (n != 14400) { print "records: " n; bad = 1 } exit bad }' cube.pcd || fail "cube.pcd contents"
    echo "not a mesh" >bad.obj
    run 1 "bad.obj" "$RC" simulate --map bad.obj --pose 0,0,0 -o i.pcd
    [ ! -e i.pcd ] || fail "i.pcd was written by a failed run"
fi

# lod (meshoptimizer): the level it says it wrote is the file it wrote, and
# coarser than the map. Skipped, with its message, in a build without it.
set +e
"$RC" lod --map sphere.ply -o lod.ply --pose-count 4 $BACKEND >lod.txt 2>&1
st=$?
set -e
if [ "$st" -ne 0 ]; then
    grep -q "built without meshoptimizer" lod.txt || { cat lod.txt >&2; fail "lod exited $st"; }
else
    lod_tris=$(sed -n 's/^wrote level [0-9]* (\([0-9]*\) triangles).*/\1/p' lod.txt)
    [ -n "$lod_tris" ] && [ "$lod_tris" -lt 990 ] || fail "lod did not report a coarser level"
    run 0 "" "$RC" info --map lod.ply
    grep -q "^triangles *$lod_tris " out.txt || fail "lod.ply does not hold the $lod_tris triangles lod reported"
fi

# A range image when the program has PNG.
if has_png; then
    run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o img.pcd --image range.png $BACKEND
    is_png range.png
fi

# Bad input: exit 1 for files, 2 for arguments; nothing written.
run 1 "nope.ply" "$RC" simulate --map nope.ply --pose 0,0,0 -o a.pcd
head -c 27 poses.bin >short.bin
run 1 "not a multiple of 28" "$RC" simulate --map sphere.ply --poses short.bin -o b.pcd
printf 'ply\nformat ascii 1.0\nelement vertex 3\nend_header\n' >broken.ply
run 1 "broken.ply" "$RC" simulate --map broken.ply --pose 0,0,0 -o c.pcd
run 2 "must be .ply or .pcd" "$RC" simulate --map sphere.ply --pose 0,0,0 -o d.xyz
run 2 "unknown sensor 'foo'" "$RC" simulate --map sphere.ply --pose 0,0,0 --sensor foo -o e.pcd
run 2 "--pose" "$RC" simulate --map sphere.ply --pose 0,0,nan -o f.pcd
run 2 "norm 0" "$RC" simulate --map sphere.ply --pose 0,0,0,0,0,0,0 -o g.pcd
run 1 "no_dir" "$RC" simulate --map sphere.ply --pose 0,0,0 -o no_dir/h.pcd
# a context the library refuses: its own reason, not just the status
if "$RC" help | grep -q "Backends in this library:[^(]*vulkan"; then
    RANGECAST_VULKAN_DEVICE=no-such-gpu run 1 "rc_context_create failed: RC_ERR_UNSUPPORTED.*: vulkan" \
        "$RC" simulate --map sphere.ply --pose 0,0,0 -o l.pcd --backend vulkan
fi
run 2 "noise->dropout is 1.5" "$RC" simulate --map sphere.ply --pose 0,0,0 -o i.pcd --dropout 1.5
run 2 "noise->sigma is -1" "$RC" simulate --map sphere.ply --pose 0,0,0 -o j.pcd --noise -1
run 2 "--seed: expected a decimal" "$RC" simulate --map sphere.ply --pose 0,0,0 -o k.pcd --seed -1
run 2 "--poses-per-call: expected a count >= 1, got '0'" "$RC" simulate --map sphere.ply --pose 0,0,0 -o p.pcd \
    --poses-per-call 0
# A write that fails (a full disk): exit 1 with the message; a device at the
# path is left alone.
if [ -c /dev/full ]; then
    ln -s /dev/full full.pcd
    run 1 "full.pcd: write error" "$RC" simulate --map sphere.ply --pose 0,0,0 -o full.pcd
    [ -c /dev/full ] || fail "/dev/full was removed"
    # the image is written before the cloud fails: the failed run removes it
    run 1 "full.pcd: write error" "$RC" simulate --map sphere.ply --pose 0,0,0 -o full.pcd --image full.png
    [ ! -e full.png ] && [ ! -e full.ppm ] || fail "a failed run left its range image"
fi
# A write that fails halfway (the file size limit, with SIGXFSZ ignored so
# the write returns EFBIG): exit 1 and no half-written file left behind.
limited() {
    (trap '' XFSZ; ulimit -f 8; exec "$@")
}
run 1 "m.ply: write error" limited "$RC" simulate --map sphere.ply --pose 0,0,0 -o m.ply
run 1 "o.p" limited "$RC" simulate --map sphere.ply --pose 0,0,0 -o o.ply --image o.png
[ ! -e o.png ] && [ ! -e o.ppm ] || fail "a half-written range image was left behind"
run 1 "n.bin: write error" limited "$RC" bench --map sphere.ply --poses poses.bin --repeat 1 --ranges-out n.bin \
    $BACKEND
for f in a.pcd b.pcd c.pcd d.xyz e.pcd f.pcd g.pcd i.pcd j.pcd k.pcd l.pcd m.ply n.bin o.ply p.pcd q.pcd r.pcd; do
    [ ! -e "$f" ] || fail "$f was written by a failed run"
    [ ! -e "$f.body.partial" ] || fail "a failed run left $f.body.partial"
done
[ ! -e full.pcd.body.partial ] || fail "a failed run left full.pcd.body.partial"
# An Ouster unit from its metadata (--sensor ouster:FILE, rc_ouster_rays): 16
# beams x 512 measurement ids from the sphere's centre. Every point lies on the
# sphere (|point| is measured from the sensor origin) and its range, measured
# from its beam origin 4 cm off that origin, within 4 cm of |point|; beam 0
# (ring 0) looks 15 degrees up. Bad metadata: exit 1 naming the problem.
if "$RC" simulate --map sphere.ply --pose 0,0,0 -o ouster.pcd --ascii --fields range,ring \
    --sensor "ouster:$DATA/ouster_os1_16.json" $BACKEND >out.txt 2>err.txt; then
    grep -qx "POINTS 8192" ouster.pcd || fail "Ouster PCD point count"
    awk 'f {
            n++
            r = sqrt($1 * $1 + $2 * $2 + $3 * $3)
            if (r < 19.5 || r > 20.0001) { print "|point| " r " off the sphere"; bad = 1 }
            if (r - $4 > 0.04 || $4 - r > 0.04) { print "range " $4 " against |point| " r; bad = 1 }
            if ($5 == 0 && $3 < 0.2 * r) { print "beam 0 not looking up: z " $3; bad = 1 }
            ring[$5]++
         }
         /^DATA/ { f = 1 }
         END {
            for (k = 0; k < 16; k++) if (ring[k] != 512) { print "ring " k ": " ring[k] " points"; bad = 1 }
            exit bad
         }' ouster.pcd || fail "ouster.pcd contents"
    # the flat legacy layout: two level beams, 4 columns, no beam offset, the
    # lidar frame as the sensor frame: every point 20 m away in the x-y plane
    cat >legacy.json <<'EOF'
{"beam_altitude_angles": [0.0, 0.0], "beam_azimuth_angles": [0.0, 45.0], "lidar_mode": "4x10",
 "lidar_origin_to_beam_origin_mm": 0.0, "lidar_to_sensor_transform": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}
EOF
    run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o legacy.pcd --ascii --fields range,ring \
        --sensor ouster:legacy.json $BACKEND
    grep -qx "POINTS 8" legacy.pcd || fail "legacy Ouster metadata: point count"
    awk 'f { if ($3 > 1e-4 || $3 < -1e-4 || $4 < 19.5 || $4 > 20.0001) { print "legacy point " $0; bad = 1 } }
         /^DATA/ { f = 1 } END { exit bad }' legacy.pcd || fail "legacy.pcd contents"
    # the frame: column_window [3, 0] wraps past the last column (ids 3 and 0
    # measured, 1 and 2 not), pixel_shift_by_row destaggers --image
    cat >window.json <<'EOF'
{"beam_altitude_angles": [0.0, 0.0], "beam_azimuth_angles": [0.0, 45.0], "lidar_mode": "4x10",
 "column_window": [3, 0], "pixel_shift_by_row": [1, -1]}
EOF
    run 0 "" "$RC" simulate --map sphere.ply --pose 0,0,0 -o window.pcd --ascii --fields range,ring \
        --sensor ouster:window.json --image window.png $BACKEND
    grep -qx "POINTS 4" window.pcd || fail "Ouster column_window: point count"
    [ -s window.png ] || [ -s window.pgm ] || [ -s window.ppm ] || fail "Ouster --image with pixel_shift_by_row"
    sed 's/\[1, -1\]/[1]/' window.json >short_shift.json
    run 1 "pixel_shift_by_row must be one integer a beam" "$RC" simulate --map sphere.ply --pose 0,0,0 \
        -o s.pcd --sensor ouster:short_shift.json
    sed 's/\[1, -1\]/[1e300, 2]/' window.json >huge_shift.json
    run 1 "pixel_shift_by_row must be one integer a beam" "$RC" simulate --map sphere.ply --pose 0,0,0 \
        -o s.pcd --sensor ouster:huge_shift.json
    sed 's/\[3, 0\]/[3, 4]/' window.json >wide_window.json
    run 1 "column_window must be two column indices" "$RC" simulate --map sphere.ply --pose 0,0,0 \
        -o w.pcd --sensor ouster:wide_window.json
    [ ! -e s.pcd ] && [ ! -e w.pcd ] || fail "a run on a bad Ouster frame wrote a cloud"
    echo '{"lidar_mode": "512x10"}' >no_beams.json
    run 1 "beam_altitude_angles" "$RC" simulate --map sphere.ply --pose 0,0,0 -o p.pcd --sensor ouster:no_beams.json
    echo '[1, 2]' >array.json
    run 1 "not a JSON object" "$RC" simulate --map sphere.ply --pose 0,0,0 -o q.pcd --sensor ouster:array.json
    run 1 "missing.json: No such file" "$RC" bench --triangles 1k --pose-count 1 --sensor ouster:missing.json
    [ ! -e p.pcd ] && [ ! -e q.pcd ] || fail "a run on bad Ouster metadata wrote a cloud"
else
    grep -q "without cJSON" err.txt || { cat err.txt >&2; fail "simulate --sensor ouster:FILE"; }
    echo "check_simulate: this rangecast has no cJSON: the Ouster checks are skipped"
fi
echo "check_simulate: all checks passed"

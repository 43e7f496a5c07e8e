#!/bin/sh
# The README's first command runs `rangecast demo`: it must keep writing the
# map, the clouds and the images it announces, with the counts it prints, and
# the next step it suggests must work on its map.
#   check_demo.sh RANGECAST WORKDIR
set -eu
RC=$1
WORK=$2
. "$(dirname "$0")/common.sh"

run 0 "" "$RC" demo --out out
# twice: a second run overwrites its own files
run 0 "" "$RC" demo --out out
cp out.txt demo.txt
for f in demo_map.ply vlp16_scan.ply vlp16_scan.pcd d435_cloud.ply; do
    [ -s "out/$f" ] || fail "out/$f missing or empty"
    grep -q "out/$f" demo.txt || fail "demo does not announce out/$f"
done
if has_png; then
    is_png out/vlp16_range.png
    is_png out/d435_depth.png
fi

# The VLP-16 cloud holds the returns the demo reports: x y z range intensity
# (float32) and ring (uint16), 22 bytes a point after the header.
returns=$(sed -n 's/.*VLP-16.*: \([0-9,]*\) returns.*/\1/p' demo.txt | tr -d ,)
[ -n "$returns" ] || fail "demo did not print the VLP-16 returns"
grep -qx "POINTS $returns" out/vlp16_scan.pcd || fail "vlp16_scan.pcd does not hold $returns points"
grep -qx "FIELDS x y z range intensity ring" out/vlp16_scan.pcd || fail "vlp16_scan.pcd fields"
header=$(awk '{ n += length($0) + 1 } /^DATA/ { print n; exit }' out/vlp16_scan.pcd)
[ "$(wc -c <out/vlp16_scan.pcd)" -eq $((header + returns * 22)) ] || fail "vlp16_scan.pcd size"
grep -q "^element vertex $returns\$" out/vlp16_scan.ply || fail "vlp16_scan.ply does not hold $returns points"

# The map the demo wrote is the one it traced: info reads the triangle count back.
tris=$(sed -n 's/.*warehouse.*, \([0-9,]*\) triangles.*/\1/p' demo.txt)
[ -n "$tris" ] || fail "demo did not print the map's triangles"
run 0 "" "$RC" info --map out/demo_map.ply
grep -q "^triangles *$tris " out.txt || fail "info reads other than $tris triangles"

# The next step the demo suggests.
run 0 "" "$RC" simulate --map out/demo_map.ply --pose 0,0,1 --sensor os1-64 -o os1.ply
[ -s os1.ply ] || fail "os1.ply missing"
echo "check_demo: all checks passed"

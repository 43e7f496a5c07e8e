#!/bin/sh
# The README's first command runs `rangecast demo`: it must keep writing the
# map, the clouds and the images it announces, with the counts it prints, and
# the next step it suggests must work on its map.
#   check_demo.sh RANGECAST WORKDIR
set -eu
RC=$1
WORK=$2
rm -rf "$WORK"
mkdir -p "$WORK"
cd "$WORK"

fail() {
    echo "FAIL: $*" >&2
    exit 1
}

"$RC" demo --out out >demo.txt 2>&1 || { cat demo.txt >&2; fail "demo exited $?"; }
# twice: a second run overwrites its own files
"$RC" demo --out out >demo.txt 2>&1 || { cat demo.txt >&2; fail "second demo run failed"; }
for f in demo_map.ply vlp16_scan.ply vlp16_scan.pcd d435_cloud.ply; do
    [ -s "out/$f" ] || fail "out/$f missing or empty"
    grep -q "out/$f" demo.txt || fail "demo does not announce out/$f"
done
if "$RC" help | grep -q "Images: PNG"; then
    for f in vlp16_range.png d435_depth.png; do
        [ "$(head -c 4 "out/$f" | od -An -c | tr -d ' ')" = "211PNG" ] || fail "out/$f is not a PNG"
    done
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
"$RC" info --map out/demo_map.ply >info.txt 2>&1 || { cat info.txt >&2; fail "info on the demo map"; }
grep -q "^triangles *$tris " info.txt || fail "info reads other than $tris triangles"

# The next step the demo suggests.
"$RC" simulate --map out/demo_map.ply --pose 0,0,1 --sensor os1-64 -o os1.ply >sim.txt 2>&1 ||
    { cat sim.txt >&2; fail "the suggested simulate command"; }
[ -s os1.ply ] || fail "os1.ply missing"
echo "check_demo: all checks passed"

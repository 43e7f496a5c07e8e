#!/bin/sh
# The report commands end to end: `rangecast accuracy` (its JSON line and its
# table against each other and against the closed 20 m sphere: every ray
# returns, no disagreement, p99.9 error under 5 um, incidence bins that add up),
# `rangecast stability` (a row per case in the text and the Markdown table,
# the same figures in both, the exit status the wrong counts call for) and
# `rangecast info` (the counts and bounds of the sphere `gen` wrote, the
# arena and scene bytes of the backend). Every bad input gets its exit status
# and a message naming it, and prints nothing on stdout.
#   check_reports.sh RANGECAST WORKDIR [--backend B]
set -eu
RC=$1
WORK=$2
shift 2
BACKEND=${*:---backend auto}
. "$(dirname "$0")/common.sh"

# The backend a run must report: the one asked for, or what auto picks (the
# built-in BVH, in every build).
backend=$(echo "$BACKEND" | sed -n 's/^--backend[ =]\([a-z]*\)$/\1/p')
if [ -z "$backend" ] || [ "$backend" = auto ]; then backend=bvh; fi
case $backend in bvh | embree | vulkan) ;; *) fail "unexpected backend '$backend'" ;; esac

# no output on stdout (the bad-input runs)
quiet() {
    [ ! -s out.txt ] || { cat out.txt >&2; fail "$1 printed on stdout"; }
}

run 0 "" "$RC" gen --sphere 1k --radius 20 -o sphere.ply
tris=$(sed -n 's/^sphere.ply: UV sphere, \([0-9]*\) triangles, \([0-9]*\) vertices$/\1/p' out.txt)
verts=$(sed -n 's/^sphere.ply: UV sphere, \([0-9]*\) triangles, \([0-9]*\) vertices$/\2/p' out.txt)
[ -n "$tris" ] && [ -n "$verts" ] || fail "gen did not print the sphere's triangles and vertices"
run 0 "" "$RC" gen --poses 3 --radius 10 --seed 7 -o poses.bin

# ---- accuracy -------------------------------------------------------------
run 0 "" "$RC" accuracy --help
cp out.txt acc_help.txt
grep -q "^Usage: rangecast accuracy" acc_help.txt || fail "accuracy --help: no usage line"

# check_acc FILE BACKEND SENSOR MAP TRIANGLES POSES RAYS_PER_SCAN RETURNS
# (RETURNS: "all" every ray returns, "none" none does): the JSON line in FILE
# holds the keys the help lists and no others, and figures that agree.
check_acc() {
    python3 - "$@" <<'PY' || fail "accuracy JSON ($1): see above"
import json, math, re, sys
path, backend, sensor, mapname, tris, poses, per_scan, returns = sys.argv[1:]
tris, poses, per_scan = int(tris), int(poses), int(per_scan)
bad = []
def check(cond, what):
    if not cond:
        bad.append(what)
lines = open(path).read().splitlines()
if len(lines) != 1:
    sys.exit("%s: %d lines, expected one JSON line" % (path, len(lines)))
d = json.loads(lines[0])
helptext = open("acc_help.txt").read()
m = re.search(r"JSON keys:(.*?)\n\S+:", helptext, re.S)
check(m is not None, "--help lists the JSON keys")
if m:
    words = re.findall(r"[a-z_0-9]+", m.group(1).replace("Statistics of no rays are null", ""))
    bin_keys = set(re.findall(r"[a-z_0-9]+", m.group(1).split("[", 1)[1].split("]", 1)[0]))
    top_keys = set(words) - bin_keys
    check(set(d) == top_keys, "keys %s, --help lists %s" % (sorted(d), sorted(top_keys)))
    for b in d.get("by_incidence", []):
        check(set(b) == bin_keys, "bin keys %s, --help lists %s" % (sorted(b), sorted(bin_keys)))
check(d["tool"] == "rangecast accuracy", "tool %r" % d["tool"])
check(d["backend"] == backend, "backend %r, expected %r" % (d["backend"], backend))
check(d["backend"] in ("bvh", "embree", "vulkan"), "unknown backend %r" % d["backend"])
check(d["sensor"] == sensor, "sensor %r" % d["sensor"])
check(d["map"] == mapname, "map %r, expected %r" % (d["map"], mapname))
check(d["triangles"] == tris, "triangles %r, expected %d" % (d["triangles"], tris))
check(d["poses"] == poses, "poses %r, expected %d" % (d["poses"], poses))
check(isinstance(d["threads"], int) and d["threads"] >= 1, "threads %r" % d["threads"])
rays = poses * per_scan
check(d["rays"] == rays, "rays %r, expected %d x %d" % (d["rays"], poses, per_scan))
check(d["disagree"] == 0 and d["disagree_rate"] == 0, "disagree %r (rate %r)" % (d["disagree"], d["disagree_rate"]))
check(d["nan_outputs"] == 0, "nan_outputs %r" % d["nan_outputs"])
n = rays if returns == "all" else 0
check(d["ref_returns"] == n and d["lib_returns"] == n and d["compared"] == n,
      "returns ref %r lib %r compared %r, expected %d" % (d["ref_returns"], d["lib_returns"], d["compared"], n))
check(isinstance(d["scans_per_s"], (int, float)) and d["scans_per_s"] > 0, "scans_per_s %r" % d["scans_per_s"])
for k in ("reference_build_s", "compare_s"):
    check(isinstance(d[k], (int, float)) and d[k] >= 0, "%s %r" % (k, d[k]))
stats = [d["range_err_mean_m"], d["range_err_p99_m"], d["range_err_p999_m"], d["range_err_max_m"]]
if n:
    check(all(isinstance(v, (int, float)) for v in stats), "range errors %r" % stats)
    if not bad:
        check(0 <= stats[0] <= stats[3] and 0 <= stats[1] <= stats[2] <= stats[3], "mean/p99/p99.9/max %r" % stats)
        check(stats[2] < 5e-6, "range_err_p999_m %r is not under 5e-6 m" % stats[2])
else:
    check(stats == [None] * 4, "range errors of no rays %r, expected null" % stats)
bins = d["by_incidence"]
check([(b["deg_lo"], b["deg_hi"]) for b in bins] == [(0, 30), (30, 60), (60, 80), (80, 89), (89, 90)],
      "incidence bins %r" % [(b["deg_lo"], b["deg_hi"]) for b in bins])
check(sum(b["n"] for b in bins) == d["compared"],
      "bins hold %d rays, compared %r" % (sum(b["n"] for b in bins), d["compared"]))
for b in bins:
    s = [b["mean_m"], b["p999_m"], b["max_m"]]
    if b["n"] == 0:
        check(s == [None] * 3, "empty bin %r-%r: %r" % (b["deg_lo"], b["deg_hi"], s))
    else:
        check(all(isinstance(v, (int, float)) for v in s) and 0 <= s[0] <= s[2] and s[1] <= s[2]
              and s[2] <= d["range_err_max_m"], "bin %r-%r: %r" % (b["deg_lo"], b["deg_hi"], s))
if n and not bad:
    check(max(b["max_m"] for b in bins if b["n"]) == d["range_err_max_m"], "no bin holds the largest error")
if bad:
    print(lines[0], file=sys.stderr)
    sys.exit("\n".join(bad))
PY
}

# The built-in 1k sphere, 3 random poses, VLP-16 (16 x 900 rays a scan): from
# inside the closed sphere every ray returns.
run 0 "" "$RC" accuracy --triangles 1k --pose-count 3 --json $BACKEND
cp out.txt acc.json
check_acc acc.json "$backend" vlp16 uv_sphere_r20 "$tris" 3 14400 all

# The table of the same run (same seed, same poses) prints the same figures.
run 0 "" "$RC" accuracy --triangles 1k --pose-count 3 $BACKEND
cp out.txt acc.txt
grep -q "^rangecast accuracy: $backend, [0-9]* threads, vlp16, UV sphere r=20 m ($tris triangles), 3 poses, 43200 rays\$" \
    acc.txt || { cat acc.txt >&2; fail "accuracy table: header line"; }
grep -q "^disagreements (return / +inf / -inf): 0 of 43200 rays (0%), NaN ranges: 0\$" acc.txt ||
    fail "accuracy table: disagreements line"
grep -q "^returns: reference 43200, library 43200\$" acc.txt || fail "accuracy table: returns line"
python3 - <<'PY' || fail "accuracy table and JSON differ"
import json, sys
d = json.loads(open("acc.json").read())
rows = {}
for line in open("acc.txt"):
    f = line.split()
    if f and f[0] == "all":
        rows["all"] = f[1:]
    elif len(f) == 7 and f[1] == "deg":
        rows[f[0]] = f[2:]
g = lambda v: "nan" if v is None else "%.3g" % v
want = {"all": [str(d["compared"]), g(d["range_err_mean_m"]), g(d["range_err_p99_m"]),
                g(d["range_err_p999_m"]), g(d["range_err_max_m"])]}
for b in d["by_incidence"]:
    lab = "%g-%g" % (b["deg_lo"], b["deg_hi"])
    if lab not in rows:
        sys.exit("table lacks the row %s deg" % lab)
    r = rows[lab]
    if [r[0], r[1], r[3], r[4]] != [str(b["n"]), g(b["mean_m"]), g(b["p999_m"]), g(b["max_m"])]:
        sys.exit("row %s deg: %s, JSON %r" % (lab, r, b))
if rows.get("all") != want["all"]:
    sys.exit("row all: %s, JSON %s" % (rows.get("all"), want["all"]))
if len(rows) != 6:
    sys.exit("table rows %s" % sorted(rows))
PY

# The map and poses gen wrote (the path is the map's name in the JSON).
run 0 "" "$RC" accuracy --map sphere.ply --poses poses.bin --json $BACKEND
cp out.txt acc_files.json
check_acc acc_files.json "$backend" vlp16 sphere.ply "$tris" 3 14400 all
# --pose-count has no say over the poses a file holds
run 0 "" "$RC" accuracy --map sphere.ply --poses poses.bin --pose-count 5 --json $BACKEND
cp out.txt acc_files5.json
check_acc acc_files5.json "$backend" vlp16 sphere.ply "$tris" 3 14400 all

# Other sensors: a Livox Mid-40 (10,000 rays a scan) sees the sphere; a D435
# (407,040 rays, 10 m at most) from inside it sees nothing: no returns, the
# statistics of no rays are null, and no ray disagrees.
run 0 "" "$RC" accuracy --triangles 1k --pose-count 1 --sensor livox-mid40 --json $BACKEND
cp out.txt acc_livox.json
check_acc acc_livox.json "$backend" livox-mid40 uv_sphere_r20 "$tris" 1 10000 all
run 0 "" "$RC" accuracy --map sphere.ply --pose-count 1 --sensor d435 --json $BACKEND
cp out.txt acc_d435.json
check_acc acc_d435.json "$backend" d435 sphere.ply "$tris" 1 407040 none

# Bad input: exit 2 for arguments, 1 for files; nothing on stdout.
run 2 "unknown argument '--bogus'" "$RC" accuracy --triangles 1k --pose-count 1 --bogus
quiet "accuracy --bogus"
run 2 "option --pose-count needs a value" "$RC" accuracy --triangles 1k --pose-count
quiet "accuracy --pose-count"
run 2 "--pose-count: expected a count >= 1, got '0'" "$RC" accuracy --triangles 1k --pose-count 0
quiet "accuracy --pose-count 0"
run 2 "unknown sensor 'nosuch'" "$RC" accuracy --triangles 1k --pose-count 1 --sensor nosuch
quiet "accuracy --sensor nosuch"
run 2 "unknown backend 'nosuch'" "$RC" accuracy --triangles 1k --pose-count 1 --backend nosuch
quiet "accuracy --backend nosuch"
run 2 "--triangles: expected 8 .. 4G, got '7'" "$RC" accuracy --triangles 7 --pose-count 1
quiet "accuracy --triangles 7"
run 2 "--threads: expected 0..[0-9]*, got 'many'" "$RC" accuracy --triangles 1k --pose-count 1 --threads many
quiet "accuracy --threads many"
run 1 "nope.ply: No such file" "$RC" accuracy --map nope.ply --pose-count 1 $BACKEND
quiet "accuracy --map nope.ply"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nend_header\n' >broken.ply
run 1 "broken.ply" "$RC" accuracy --map broken.ply --pose-count 1 $BACKEND
quiet "accuracy --map broken.ply"
head -c 27 poses.bin >short.bin
run 1 "short.bin: size 27 bytes is not a multiple of 28" "$RC" accuracy --map sphere.ply --poses short.bin $BACKEND
quiet "accuracy --poses short.bin"
: >empty.bin
run 1 "empty.bin: empty pose file" "$RC" accuracy --map sphere.ply --poses empty.bin $BACKEND
quiet "accuracy --poses empty.bin"

# ---- stability ------------------------------------------------------------
# check_stab TEXT MARKDOWN STATUS BACKEND: a row per case in both tables (the
# cases the Markdown describes), one column pair per backend, the same figures
# in both, every case with rays, a detail line per failing cell, and status 1
# exactly when a ray is wrong.
check_stab() {
    python3 - "$@" <<'PY' || fail "stability tables ($1, $2): see above"
import re, sys
text, md, status, backend = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
tl = open(text).read().splitlines()
ml = open(md).read().splitlines()
if tl[0].split() != ["case", backend, "wrong/rays", "max", "err", "tolerance"]:
    sys.exit("text header %r" % tl[0])
if ml[0] != "| case | %s: wrong / rays | %s: max error [m] | tolerance |" % (backend, backend):
    sys.exit("Markdown header %r" % ml[0])
if ml[1] != "|---|---:|---:|---|":
    sys.exit("Markdown separator %r" % ml[1])
about = [m.group(1) for m in (re.match(r"- \*\*([a-z_]+)\*\*: .+\.$", l) for l in ml) if m]
if len(about) < 8 or "grazing" not in about or "coplanar" not in about:
    sys.exit("Markdown case list %r" % about)
rows_t, rows_m = {}, {}
for l in tl[1:1 + len(about)]:
    m = re.match(r"(\S+) +(\d+) / (\d+) +(\S+)  (\S+ m \+ \S+ x range)$", l)
    if not m:
        sys.exit("text row %r" % l)
    rows_t[m.group(1)] = m.groups()[1:]
for l in ml[2:2 + len(about)]:
    m = re.match(r"\| (\S+) \| (\d+) / (\d+) \| (\S+) \| (\S+ m \+ \S+ x range) \|$", l)
    if not m:
        sys.exit("Markdown row %r" % l)
    rows_m[m.group(1)] = m.groups()[1:]
if list(rows_t) != about or list(rows_m) != about:
    sys.exit("cases: text %r, Markdown %r, described %r" % (list(rows_t), list(rows_m), about))
if rows_t != rows_m:
    sys.exit("text %r, Markdown %r" % (rows_t, rows_m))
failing = sorted(c for c, r in rows_t.items() if int(r[0]) > 0)
for c, r in rows_t.items():
    if int(r[1]) == 0 or int(r[0]) > int(r[1]):
        sys.exit("case %s: %s / %s" % (c, r[0], r[1]))
detail = sorted(m.group(1) for m in (re.match(re.escape(backend) + r"/(\S+): \d+ wrong \(", l)
                                     for l in tl[1 + len(about):]) if m)
if detail != failing or len(tl) != 1 + len(about) + len(failing):
    sys.exit("failing cases %r, detail lines for %r (%d lines)" % (failing, detail, len(tl)))
if status != (1 if failing else 0):
    sys.exit("exit status %d with failing cases %r" % (status, failing))
PY
}

# The built-in BVH has no wrong ray (docs/stability.md).
run 0 "" "$RC" stability --quick --backend bvh
cp out.txt stab.txt
run 0 "" "$RC" stability --quick --backend bvh --markdown
cp out.txt stab.md
check_stab stab.txt stab.md 0 bvh

# The backend under test, named as what it resolves to (auto: the one picked);
# it may have the wrong rays docs/stability.md lists, and exits 1 for them.
set +e
"$RC" stability --quick $BACKEND >stab_b.txt 2>err.txt
st=$?
set -e
[ "$st" -le 1 ] || { cat err.txt >&2; fail "stability $BACKEND exited $st"; }
[ ! -s err.txt ] || { cat err.txt >&2; fail "stability $BACKEND: a case failed to run"; }
set +e
"$RC" stability --quick --markdown $BACKEND >stab_b.md 2>err.txt
st_md=$?
set -e
[ "$st_md" -eq "$st" ] || fail "stability exits $st, with --markdown $st_md"
check_stab stab_b.txt stab_b.md "$st" "$backend"

run 2 "unknown backend 'nosuch'" "$RC" stability --quick --backend nosuch
quiet "stability --backend nosuch"
run 2 "unknown backend 'nosuch'" "$RC" stability --quick --backend bvh,nosuch
quiet "stability --backend bvh,nosuch"
run 2 "at most 4 backends" "$RC" stability --quick --backend bvh,bvh,bvh,bvh,bvh
quiet "stability --backend x5"
run 2 "--backend: expected a list of backends" "$RC" stability --quick --backend=
quiet "stability --backend="
run 2 "option --backend needs a value" "$RC" stability --quick --backend
quiet "stability --backend"
run 2 "unknown argument '--bogus'" "$RC" stability --quick --bogus
quiet "stability --bogus"
run 2 "--threads: expected 0..[0-9]*, got 'x'" "$RC" stability --quick --threads x
quiet "stability --threads x"

# ---- info -----------------------------------------------------------------
# The sphere gen wrote: its counts, bounds within the 20 m sphere and outside
# the 1k sphere's inscribed radius (above 19.5 m), the size the bounds span; one
# row for the backend with positive arena and scene bytes, the scene within
# the arena, and bytes/tri what the row's bytes make.
run 0 "" "$RC" info --map sphere.ply $BACKEND
cp out.txt info.txt
grep -q "^map  *sphere.ply (loaded in [0-9.]* s)\$" info.txt || fail "info: map line"
grep -q "^triangles  *$tris (0 degenerate)\$" info.txt || fail "info: not $tris triangles, none degenerate"
bytes=$(((verts + tris) * 12))
grep -q "^vertices  *$verts ([0-9.]* [KM]*i*B as float32 + indices" info.txt || fail "info: not $verts vertices"
python3 - "$tris" "$backend" "$bytes" <<'PY' || { cat info.txt >&2; fail "info figures"; }
import re, sys
tris, backend, mesh_bytes = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
t = open("info.txt").read()
m = re.search(r"^vertices +[\d,]+ \(([\d.]+) (B|KiB|MiB) as", t, re.M)
scale = {"B": 1, "KiB": 1024, "MiB": 1 << 20}[m.group(2)]
if abs(float(m.group(1)) * scale - mesh_bytes) > 0.05 * scale:
    sys.exit("vertices: %s %s, expected %d B" % (m.group(1), m.group(2), mesh_bytes))
num = r"(-?[\d.]+)"
m = re.search(r"^bounds +x %s \.\. %s, y %s \.\. %s, z %s \.\. %s m \(size %s x %s x %s\)$" % ((num,) * 9), t, re.M)
if not m:
    sys.exit("no bounds line")
v = [float(x) for x in m.groups()]
for k in range(3):
    lo, hi, size = v[2 * k], v[2 * k + 1], v[6 + k]
    if not (-20.0005 <= lo <= -19.5 and 19.5 <= hi <= 20.0005):
        sys.exit("bounds %s .. %s are not about +-20" % (lo, hi))
    if abs(size - (hi - lo)) > 0.0015:
        sys.exit("size %s is not %s - %s" % (size, hi, lo))
if "beyond 10 km" in t:
    sys.exit("a far-coordinates note for a 20 m sphere")
rows = re.findall(r"^(\w+) +([\d,]+) +([\d,]+) +([\d,]+) +([\d.]+) +([\d.]+)$", t, re.M)
if [r[0] for r in rows] != [backend]:
    sys.exit("backend rows %r, expected %s" % ([r[0] for r in rows], backend))
arena, scene, outside = (int(x.replace(",", "")) for x in rows[0][1:4])
per_tri = float(rows[0][4])
if not (0 < scene <= arena):
    sys.exit("arena bytes %d, scene bytes %d" % (arena, scene))
if abs(per_tri - (scene + outside) / tris) > 0.051:
    sys.exit("bytes/tri %s, (%d + %d) / %d" % (per_tri, scene, outside, tris))
PY

# A broken mesh: 3 triangles, one on a line (the others with normals off the
# axes and along z); info counts it.
cat >degen.ply <<'PLY'
ply
format ascii 1.0
element vertex 5
property float x
property float y
property float z
element face 3
property list uchar int vertex_indices
end_header
0 0 0
1 1 1
2 2 2
1 0 0
0 1 0
3 0 1 2
3 0 1 3
3 0 3 4
PLY
run 0 "" "$RC" info --map degen.ply --backend bvh
grep -q "^triangles  *3 (1 degenerate)\$" out.txt || { cat out.txt >&2; fail "info degen.ply: triangles"; }
grep -q "^vertices  *5 (96 B as" out.txt || fail "info degen.ply: vertices"
grep -q "^bounds  *x 0.000 .. 2.000, y 0.000 .. 2.000, z 0.000 .. 2.000 m (size 2.000 x 2.000 x 2.000)\$" out.txt ||
    fail "info degen.ply: bounds"
# Far from the origin: the float32 note.
awk 'v > 0 { $1 += 20000; v-- } { print } /^end_header/ { v = 5 }' degen.ply >far.ply
run 0 "" "$RC" info --map far.ply --backend bvh
grep -q "^bounds  *x 20000.000 .. 20002.000," out.txt || { cat out.txt >&2; fail "info far.ply: bounds"; }
grep -q "coordinates beyond 10 km" out.txt || fail "info far.ply: no far-coordinates note"

run 1 "nope.ply: No such file" "$RC" info --map nope.ply
quiet "info --map nope.ply"
run 1 "broken.ply" "$RC" info --map broken.ply
quiet "info --map broken.ply"
head -n 14 degen.ply | sed 's/^element face 3$/element face 0/' >noface.ply
run 1 "noface.ply: no triangles" "$RC" info --map noface.ply
quiet "info --map noface.ply"
run 2 "--map FILE is required" "$RC" info
quiet "info"
run 2 "option --map needs a value" "$RC" info --map
quiet "info --map"
run 2 "unknown argument '--bogus'" "$RC" info --map sphere.ply --bogus
quiet "info --bogus"
run 2 "unknown backend 'nosuch'" "$RC" info --map sphere.ply --backend nosuch
quiet "info --backend nosuch"
echo "check_reports: all checks passed"

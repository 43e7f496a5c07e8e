#!/usr/bin/env python3
"""Runs `rangecast bench` over map sizes and backends, alternating backends
within each size (A B A B ...) so machine noise hits all of them alike, and
prints a markdown table of medians with the JSON lines behind it.

  tools/bench-report.py --rangecast build/tools/rangecast --sizes 1k,10k,100k,1M \
      --backends bvh,embree,embree-single --threads 2 --rounds 3 --pose-count 1000
"""
import argparse
import json
import platform
import statistics
import subprocess
import sys


def run(exe, backend, size, args):
    cmd = [exe, "bench", "--backend", backend, "--triangles", size, "--threads", str(args.threads),
           "--repeat", str(args.repeat), "--pose-count", str(args.pose_count), "--sensor", args.sensor]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rangecast", default="build/tools/rangecast")
    ap.add_argument("--sizes", default="1k,10k,100k,1M")
    ap.add_argument("--backends", default="bvh")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--pose-count", type=int, default=1000)
    ap.add_argument("--sensor", default="vlp16")
    ap.add_argument("--json-out", help="also write every JSON line here")
    args = ap.parse_args()
    backends = args.backends.split(",")
    rows = []
    lines = []
    for size in args.sizes.split(","):
        samples = {b: [] for b in backends}
        for _ in range(args.rounds):
            for b in backends:
                j = run(args.rangecast, b, size, args)
                samples[b].append(j)
                lines.append(json.dumps(j))
                print(f"{size:>5} {b:>13}: {j['scans_per_s']:.1f} scans/s", file=sys.stderr)
        for b in backends:
            js = samples[b]
            med = statistics.median(x["scans_per_s"] for x in js)
            last = js[-1]
            rows.append((size, b, last["triangles"], med, statistics.median(x["build_s"] for x in js),
                         last.get("bytes_per_triangle"), last.get("total_bytes_per_triangle"),
                         last.get("range_err_mean_m"), last.get("range_err_p999_m"), last.get("hit_mismatch")))
    print(f"Machine: {platform.machine()}, {platform.processor() or 'cpu'}; "
          f"{args.threads} threads, sensor {args.sensor}, {args.pose_count} poses, median of {args.rounds} "
          f"alternating rounds.\n")
    print("| map | backend | triangles | scans/s | build s | arena B/tri | total B/tri | mean err m | p99.9 err m | hit mismatch |")
    print("|---|---|---|---|---|---|---|---|---|---|")

    def f(v, fmt):
        return "—" if v is None else format(v, fmt)
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.1f} | {r[4]:.3f} | {f(r[5], '.1f')} | {f(r[6], '.1f')} | "
              f"{f(r[7], '.2e')} | {f(r[8], '.2e')} | {f(r[9], 'd') if isinstance(r[9], int) else '—'} |")
    if args.json_out:
        with open(args.json_out, "w") as fh:
            fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Compares builds of `rangecast` on one workload: each round runs every
binary once, one after the other, pinned to one core with one thread (the
order reversed every other round, so a drift of the machine hits all alike),
and prints each binary's median scans/s and its ratio to the first's.

On a shared VM a single pair of runs swings by several per cent; the median
of eight or more rounds resolves about 2%. Instruction counts (callgrind)
resolve far less, but do not show what waits on memory.

  tools/bench-ab.py --size 100k --rounds 8 before/build/tools/rangecast \
      build/tools/rangecast
"""
import argparse
import json
import statistics
import subprocess


def run(exe, args):
    cmd = ["taskset", "-c", str(args.core), exe, "bench", "--backend", args.backend, "--triangles", args.size,
           "--threads", "1", "--repeat", str(args.repeat), "--pose-count", str(args.pose_count),
           "--sensor", args.sensor]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])["scans_per_s"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binaries", nargs="+", help="rangecast executables; the first is the reference")
    ap.add_argument("--size", default="100k", help="sphere size, as bench's --triangles")
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--pose-count", type=int, default=300)
    ap.add_argument("--sensor", default="vlp16")
    ap.add_argument("--backend", default="bvh")
    ap.add_argument("--core", type=int, default=0, help="CPU the runs are pinned to")
    args = ap.parse_args()
    samples = {b: [] for b in args.binaries}
    for r in range(args.rounds):
        for exe in args.binaries if r % 2 == 0 else reversed(args.binaries):
            samples[exe].append(run(exe, args))
    ref = statistics.median(samples[args.binaries[0]])
    print("| binary | median scans/s | ratio | rounds |")
    print("|---|---|---|---|")
    for exe in args.binaries:
        med = statistics.median(samples[exe])
        rounds = ", ".join(f"{x:.0f}" for x in samples[exe])
        print(f"| {exe} | {med:.1f} | {med / ref:.3f} | {rounds} |")


if __name__ == "__main__":
    main()

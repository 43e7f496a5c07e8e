"""Scans per second of a VLP-16 inside a UV sphere of radius 20 m, through
the Python binding, to show what calling from Python costs. Prints one JSON
line. For `rangecast bench`'s exact workload, hand it the files `rangecast
gen` writes:

    rangecast gen --sphere 1M -o sphere.ply && rangecast gen --poses 200 -o poses.bin
    PYTHONPATH=bindings/python python3 bindings/python/examples/scan_rate.py \
        --map sphere.ply --poses-file poses.bin --threads 2
"""

import argparse
import json
import math
import time

import numpy as np

import rangecast


def uv_sphere(radius, triangles):
    """A UV sphere of about `triangles` triangles (rings x 2 * rings grid)."""
    rings = max(3, int(round(math.sqrt(triangles / 4.0))))
    segs = 2 * rings
    phi = -math.pi / 2 + math.pi * np.arange(1, rings) / rings
    th = 2 * math.pi * np.arange(segs) / segs
    P, T = np.meshgrid(phi, th, indexing="ij")
    ring = np.stack([np.cos(P) * np.cos(T), np.cos(P) * np.sin(T), np.sin(P)], -1).reshape(-1, 3)
    v = np.concatenate([[[0, 0, -1]], ring, [[0, 0, 1]]]) * radius
    j = np.arange(segs)
    j1 = (j + 1) % segs
    tris = [np.stack([np.zeros(segs, int), 1 + j1, 1 + j], 1)]
    for i in range(rings - 2):
        a, b = 1 + i * segs, 1 + (i + 1) * segs
        tris += [np.stack([a + j, a + j1, b + j1], 1), np.stack([a + j, b + j1, b + j], 1)]
    last, top = 1 + (rings - 2) * segs, len(v) - 1
    tris.append(np.stack([last + j, last + j1, np.full(segs, top)], 1))
    return v.astype(np.float32), np.concatenate(tris).astype(np.uint32)


def read_gen_ply(path):
    """The binary little-endian PLY `rangecast gen` writes: float x y z
    vertices, faces as a uchar count 3 and three int32 indices."""
    with open(path, "rb") as f:
        header = []
        while not header or header[-1] != "end_header":
            header.append(f.readline().decode("ascii").strip())
        counts = {w[1]: int(w[2]) for w in (ln.split() for ln in header) if w[0] == "element"}
        if "format binary_little_endian 1.0" not in header or header.count("property float x") != 1:
            raise SystemExit("%s: not a PLY as rangecast gen writes it" % path)
        v = np.fromfile(f, dtype="<f4", count=3 * counts["vertex"]).reshape(-1, 3)
        faces = np.fromfile(f, dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]), count=counts["face"])
    if (faces["n"] != 3).any():
        raise SystemExit("%s: faces must be triangles" % path)
    return v, faces["i"].astype(np.uint32)


def random_poses(n, radius, seed):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d *= (radius * rng.uniform(size=(n, 1)) ** (1 / 3)) / np.linalg.norm(d, axis=1, keepdims=True)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.concatenate([d, q], 1).astype(np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--triangles", type=int, default=1000000)
    ap.add_argument("--map", help="a PLY from rangecast gen (else a sphere made here)")
    ap.add_argument("--poses-file", help="raw float32 poses from rangecast gen (else random ones)")
    ap.add_argument("--poses", type=int, default=200)
    ap.add_argument("--batch", type=int, default=200, help="poses per simulate call")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--backend", default="bvh")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--copy", action="store_true", help="copy the mesh into the arena (else referenced)")
    a = ap.parse_args()
    v, t = read_gen_ply(a.map) if a.map else uv_sphere(20.0, a.triangles)
    if a.poses_file:
        poses = np.fromfile(a.poses_file, dtype="<f4").reshape(-1, 7)
        a.poses = len(poses)
        a.batch = min(a.batch, a.poses)
    else:
        poses = random_poses(a.poses, 10.0, 1)
    with rangecast.Context(backend=a.backend, threads=a.threads, arena_bytes=int(len(t) * 80 + (64 << 20))) as ctx:
        t0 = time.perf_counter()
        scene = ctx.mesh_scene(v, t, copy=a.copy)
        build_s = time.perf_counter() - t0
        lidar = ctx.preset_sensor("vlp16")
        out = {"ranges": np.empty((a.batch, 16, 900), np.float32)}
        best = 0.0
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            for k in range(0, a.poses, a.batch):
                chunk = poses[k:k + a.batch]
                if len(chunk) != a.batch:
                    out = {"ranges": np.empty((len(chunk), 16, 900), np.float32)}
                ctx.simulate(scene, lidar, chunk, ("ranges",), out=out)
            best = max(best, a.poses / (time.perf_counter() - t0))
        print(json.dumps({"tool": "scan_rate.py", "backend": ctx.backend, "threads": ctx.threads,
                          "triangles": int(len(t)), "poses": a.poses, "batch": a.batch, "build_s": round(build_s, 3),
                          "scans_per_s": round(best, 1), "finite_fraction":
                          float(np.isfinite(out["ranges"]).mean())}))


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""SciPy peer for voxfield's field benchmark: the same .npy inputs through scipy.ndimage's exact
Euclidean transform and its taxicab / chessboard chamfer transforms (both exact on a grid), one
thread, median of N runs after a warm-up. Appends JSON records like voxfield-bench-field's."""
import argparse, json, os, statistics, time

import numpy as np
from scipy import ndimage as nd

ap = argparse.ArgumentParser()
ap.add_argument("inputs", nargs="+", help=".npy volumes (non-zero = solid); the stem names the input")
ap.add_argument("--runs", type=int, default=5)
ap.add_argument("--metrics", default="manhattan,chebyshev,euclidean")
ap.add_argument("--json", help="append one JSON record per line")
args = ap.parse_args()

transforms = {
    "euclidean": lambda air: nd.distance_transform_edt(air),
    "manhattan": lambda air: nd.distance_transform_cdt(air, metric="taxicab"),
    "chebyshev": lambda air: nd.distance_transform_cdt(air, metric="chessboard"),
}
out = open(args.json, "a") if args.json else None
print("%-26s %-10s %4s %9s %9s %9s %10s" % ("input", "metric", "thr", "median", "min", "max", "Mvox/s"))
for path in args.inputs:
    air = np.load(path) == 0
    name = os.path.splitext(os.path.basename(path))[0]
    for metric in args.metrics.split(","):
        fn = transforms[metric]
        fn(air)  # warm-up
        times = []
        for _ in range(args.runs):
            t0 = time.perf_counter()
            fn(air)
            times.append((time.perf_counter() - t0) * 1e3)
        med = statistics.median(times)
        print("%-26s %-10s %4d %9.1f %9.1f %9.1f %10.1f" % (name, metric, 1, med, min(times), max(times), air.size / (med * 1e3)), flush=True)
        if out:
            out.write(json.dumps({"tool": "scipy", "input": name, "metric": metric, "threads": 1, "voxels": air.size,
                                  "median_ms": med, "min_ms": min(times), "max_ms": max(times), "runs": args.runs}) + "\n")

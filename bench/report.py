#!/usr/bin/python3
"""Turns the JSON records of one benchmark run (voxfield-bench-field, scipy_peer.py, openvdb_peer)
into the Markdown tables of docs/benchmarks.md and a throughput plot. Ratios compare tools measured
in the same run, as BENCHMARKS.md asks."""
import argparse, collections, json

ap = argparse.ArgumentParser()
ap.add_argument("records")
ap.add_argument("--plot", help="PNG to write")
args = ap.parse_args()

rows = [json.loads(line) for line in open(args.records) if line.strip()]
vf = {(r["input"], r["metric"], r["threads"]): r for r in rows if r["tool"] == "voxfield"}
sp = {(r["input"], r["metric"]): r for r in rows if r["tool"] == "scipy"}
ov = collections.defaultdict(dict)
for r in rows:
    if r["tool"] == "openvdb":
        ov[r["input"]][r["metric"]] = r

inputs = list(dict.fromkeys(r["input"] for r in rows if r["tool"] == "voxfield"))
metrics = ["manhattan", "chebyshev", "euclidean"]
print("| input | metric | voxfield 1 thread ms | voxfield 2 threads ms | Mvox/s (2 threads) | extra bytes/voxel | scipy 1 thread ms | scipy / voxfield (1 thread each) |")
print("|---|---|---|---|---|---|---|---|")
for i in inputs:
    for m in metrics:
        one, two = vf.get((i, m, 1)), vf.get((i, m, 2))
        if not one and not two:
            continue
        s = sp.get((i, m))
        cell = lambda r: "%.1f (%.1f–%.1f)" % (r["median_ms"], r["min_ms"], r["max_ms"]) if r else "—"
        mvox = "%.0f" % (two["voxels"] / (two["median_ms"] * 1e3)) if two else "—"
        extra = "%.2f" % max(r["extra_bytes_per_voxel"] for r in (one, two) if r)
        ratio = "%.1f×" % (s["median_ms"] / one["median_ms"]) if s and one else "—"
        print("| %s | %s | %s | %s | %s | %s | %s | %s |" % (i, m, cell(one), cell(two), mvox, extra, cell(s), ratio))
if ov:
    print()
    print("| input | OpenVDB topologyToLevelSet (hw 3), 2 threads ms | OpenVDB fogToSdf, 2 threads ms | fogToSdf max error (voxels) | voxfield exact Euclidean (unsigned), 2 threads ms | fogToSdf / voxfield |")
    print("|---|---|---|---|---|---|")
    for i, d in ov.items():
        band, full = d.get("topologyToLevelSet-hw3"), d.get("fogToSdf")
        e2 = vf.get((i, "euclidean", 2))
        print("| %s | %.1f | %.1f | %.2f | %s | %s |" % (i, band["median_ms"], full["median_ms"], full["max_error"],
              "%.1f" % e2["median_ms"] if e2 else "—", "%.1f×" % (full["median_ms"] / e2["median_ms"]) if e2 else "—"))

if args.plot:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    labels, series = [], collections.defaultdict(list)
    for i in inputs:
        for m in metrics:
            if (i, m, 1) not in vf:
                continue
            labels.append("%s\n%s" % (i, m))
            for name, r in (("voxfield, 1 thread", vf.get((i, m, 1))), ("voxfield, 2 threads", vf.get((i, m, 2))),
                            ("scipy, 1 thread", sp.get((i, m)))):
                series[name].append(r["voxels"] / (r["median_ms"] * 1e3) if r else 0)
    fig, ax = plt.subplots(figsize=(max(8, len(labels) * 0.9), 4.5))
    width = 0.8 / len(series)
    for k, (name, vals) in enumerate(series.items()):
        ax.bar([x + k * width for x in range(len(labels))], vals, width, label=name)
    ax.set_xticks([x + width * (len(series) - 1) / 2 for x in range(len(labels))])
    ax.set_xticklabels(labels, fontsize=7, rotation=45, ha="right")
    ax.set_yscale("log")
    ax.set_ylabel("million voxels per second (log)")
    ax.set_title("Exact distance transforms, same inputs, same run")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.plot, dpi=110)

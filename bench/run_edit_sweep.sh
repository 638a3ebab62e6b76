#!/usr/bin/env bash
# The dissertation's figures for dynamic fields: the seeded edit stream (radius 1 .. chunk edge - 1,
# Manhattan clamp 16, u8) swept over world sizes and chunk edges. Writes a CSV summary and a PNG
# plot of per-edit latency to bench/results/edit-sweep-DATE/.
# Usage: bash bench/run_edit_sweep.sh [EDITS] [SIZES] [CHUNKS]   (defaults: 200 "64 128 256 512" "8 16 32 64 128")
set -euo pipefail
cd "$(dirname "$0")/.."
edits=${1:-200}
sizes=${2:-"64 128 256 512"}
chunks=${3:-"8 16 32 64 128"}
source bench/common.sh
bench_prepare --peers
bench_results edit-sweep
for n in $sizes; do
  for c in $chunks; do
    [ "$c" -le "$n" ] || continue
    build/release/bin/voxfield bench edits --world "$n" --chunk "$c" --edits "$edits" --metric manhattan \
      --max-distance 16 --storage u8 --json "$out/w$n-c$c.json" | sed -n 2p | sed "s/^/world $n chunk $c: /"
  done
done
/usr/bin/python3 - "$out" <<'PY'
import glob, json, os, sys
out = sys.argv[1]
rows = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(out, "w*-c*.json")))]
with open(os.path.join(out, "summary.csv"), "w") as f:
    f.write("world,chunk,radius_max,edits,p50_ms,mean_ms,ci95_ms,p99_ms,max_ms,mean_voxels_recomputed,world_bytes_per_voxel,field_bytes_per_voxel\n")
    for r in rows:
        l = r["latency_ms"]
        f.write("%d,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.0f,%.3f,%.3f\n" % (r["world"], r["chunk"], r["radius_max"], r["edits"],
                l["median"], l["mean"], l["ci95"], l["p99"], l["max"], r["mean_voxels_recomputed"],
                r["world_bytes_per_voxel"], r["field_bytes_per_voxel"]))
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
for chunk in sorted({r["chunk"] for r in rows}):
    sel = sorted((r for r in rows if r["chunk"] == chunk), key=lambda r: r["world"])
    xs = [r["world"] for r in sel]
    axes[0].errorbar(xs, [r["latency_ms"]["mean"] for r in sel], yerr=[r["latency_ms"]["ci95"] for r in sel],
                     marker="o", capsize=3, label="chunk %d (r 1..%d)" % (chunk, chunk - 1))
    axes[1].plot(xs, [r["latency_ms"]["p99"] for r in sel], marker="o", label="chunk %d" % chunk)
for ax, title in zip(axes, ["mean latency per edit (95% CI)", "p99 latency per edit"]):
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("world edge (voxels)")
    ax.set_ylabel("ms (edit + exact update)")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize=7)
fig.suptitle("Seeded sphere edits (dissertation's stream), Manhattan clamp 16, u8 field, 2 threads")
fig.tight_layout()
fig.savefig(os.path.join(out, "edit-sweep.png"), dpi=110)
PY
echo "results in $out"

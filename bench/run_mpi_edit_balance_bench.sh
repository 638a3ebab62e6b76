#!/usr/bin/env bash
# voxfield-mpi edit with its slabs cut by volume, by content and by the script's edits: 400
# radius-4 spheres placed and carved on the surface of the SIZE^3 terrain (where a world's edits
# land), clamp 16, chunks of 16, on 2 and 4 ranks of one thread (4 oversubscribe this machine's 2
# cores), beside one process (voxfield edit, 2 threads); every field must equal one process's byte
# for byte. Per edit, the slowest rank's time (p50 / p99, and their sum: the stream if the ranks
# waited for each other after every edit); the stream as it runs (the ranks go through the script
# without waiting: the rank with the most work's total); the one-time load and build; the cuts. JSON per run and a markdown table
# into bench/results/mpi-edit-balance-DATE/.
# Best of REPEAT runs per row (by the stream's time).
# Usage: bash bench/run_mpi_edit_balance_bench.sh [REPEAT] [SIZE]   (defaults 3 and 256)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mpi-edit-balance
repeat=${1:-3}
size=${2:-256}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
B=build/release/bin
"$B/voxfield" generate terrain --size "$size" -o "$out/terrain.npy" 2>/dev/null
# Edits centred on the surface: the highest solid voxel of random columns.
/usr/bin/python3 - "$out/terrain.npy" "$out/edits.jsonl" <<'PY'
import json, sys
import numpy as np
a = np.load(sys.argv[1])
rng = np.random.default_rng(4)
solid = a != 0
top = np.where(solid.any(axis=2), a.shape[2] - 1 - np.argmax(solid[:, :, ::-1], axis=2), 0)
with open(sys.argv[2], "w") as f:
    for i in range(400):
        x, y = (int(v) for v in rng.integers(0, a.shape[0], 2))
        e = {"op": "place" if i % 2 else "carve", "shape": "sphere",
             "center": [x, y, int(top[x, y])], "radius": 4}
        if i % 2:
            e["material"] = 2
        f.write(json.dumps(e) + "\n")
PY
opts="--metric euclidean --max-distance 16 --chunk 16"
# shellcheck disable=SC2086
"$B/voxfield" edit "$out/terrain.npy" -e "$out/edits.jsonl" -o "$out/one.npy" $opts --threads 2 \
  --stats "$out/one.json" 2>/dev/null
for r in $(seq 1 "$repeat"); do
  for n in 2 4; do
    for balance in volume content edits; do
      # shellcheck disable=SC2086
      mpirun --oversubscribe -np "$n" "$B/voxfield-mpi" edit "$out/terrain.npy" -e "$out/edits.jsonl" \
        -o "$out/mpi.npy" $opts --threads 1 --balance "$balance" --stats "$out/mpi-$n-$balance-$r.json" 2>/dev/null
      cmp "$out/one.npy" "$out/mpi.npy"
    done
  done
done
rm -f "$out/terrain.npy" "$out/one.npy" "$out/mpi.npy"
/usr/bin/python3 - "$out" <<'PY' | tee "$out/table.md"
import glob, json, sys
out = sys.argv[1]
one = json.load(open(out + "/one.json"))
print("| run | slabs (z cuts) | stream ms | p50 ms | p99 ms | sum of slowest ms | load ms | build ms | ranks an edit reached (mean) |")
print("|---|---|---|---|---|---|---|---|---|")
print("| voxfield edit, one process, 2 threads | — | %.0f | %.3f | %.3f | %.0f | — | %.0f | — |" % (
    one["total_ms"], one["p50_ms"], one["p99_ms"], one["total_ms"], one["build_ms"]))
for n in (2, 4):
    for balance in ("volume", "content", "edits"):
        runs = [json.load(open(f)) for f in glob.glob("%s/mpi-%d-%s-*.json" % (out, n, balance))]
        j = min(runs, key=lambda r: r["stream_ms"])
        print("| %d ranks, by %s | %s | %.0f | %.3f | %.3f | %.0f | %.0f | %.0f | %.2f |" % (
            n, balance, " ".join(str(z) for z in j["slabs"]), j["stream_ms"], j["p50_ms"],
            j["p99_ms"], j["total_ms"], j["load_ms"], j["build_ms"], j["ranks_reached_per_edit"]))
PY

#!/usr/bin/env bash
# voxfield-mpi: strong and weak scaling of exact fields over MPI ranks on this machine, the bytes
# exchanged against the algorithm's payload (16 bytes per column and rank boundary), and a volume
# larger than any one rank may hold. Worlds of random spheres are generated slab by slab
# (voxfield-mpi bench), so no rank ever holds more than its slab. This machine has 2 cores: 4
# ranks oversubscribe them (Open MPI's --oversubscribe), so past 2 ranks the figures show the
# overhead of more ranks, not more speed. Each rank is bound to a core (Open MPI's default) and
# runs one thread; "1 rank x 2 threads" (--bind-to none) is the single-process baseline.
# Then scripted edits through voxfield edit and voxfield-mpi edit (identical files, per-edit
# latency of the slowest rank). JSON lines per run and markdown tables into bench/results/mpi-DATE/.
# Usage: bash bench/run_mpi_bench.sh [REPEAT] [BIG_EDGE]   (defaults 3 and 1536)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mpi
repeat=${1:-3}
big=${2:-1536}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
M="mpirun --oversubscribe"
B=build/release/bin/voxfield-mpi
field="--metric euclidean --signed --chunk 32"
run() {  # run LABEL RANKS MPIRUN-ARGS -- BENCH-ARGS
  local label=$1 n=$2
  shift 2
  local margs=()
  while [ "$1" != "--" ]; do margs+=("$1"); shift; done
  shift
  # shellcheck disable=SC2086
  $M -np "$n" "${margs[@]}" $B bench "$@" --repeat "$repeat" | sed "s/^{/{\"label\":\"$label\",/" | tee -a "$out/runs.jsonl"
}
for s in 256 512; do
  run "strong $s^3, 1 rank x 2 threads" 1 --bind-to none -- --size $s,$s,$s --spheres 400 $field --threads 2
  for n in 1 2 4; do
    run "strong $s^3, $n ranks x 1 thread" "$n" -- --size $s,$s,$s --spheres 400 $field --threads 1
  done
done
for n in 1 2 4; do
  z=$((128 * n))
  run "weak 256x256x$z, $n ranks" "$n" -- --size 256,256,$z --spheres $((100 * n)) $field --threads 1
done
# u8 storage (quarter voxels up to 63.75): the big volume's field is 1 byte per voxel. Each rank is
# capped below what the whole field alone would take.
bytes=$((big * big * big))
cap=$((bytes / 4 + bytes / 8))
$M -np 4 $B --memory-limit "$cap" bench --size $big,$big,$big --spheres 2000 --metric euclidean --chunk 32 \
  --storage u8 --threads 1 --repeat 1 | sed "s/^{/{\"label\":\"big $big^3 u8, 4 ranks, memory limit $cap bytes per rank\",/" | tee -a "$out/runs.jsonl"
# Edits: 400 radius-4 spheres placed and carved on the 256^3 terrain, clamp 16, through voxfield
# edit (one process, 2 threads) and voxfield-mpi edit (1, 2, 4 ranks of one thread); the files
# must be identical.
build/release/bin/voxfield generate terrain --size 256 -o "$out/terrain.npy" 2>/dev/null
/usr/bin/python3 - "$out/edits.jsonl" <<'PY'
import json, sys
import numpy as np
rng = np.random.default_rng(4)
with open(sys.argv[1], "w") as f:
    for i in range(400):
        e = {"op": "place" if i % 2 else "carve", "shape": "sphere",
             "center": [int(v) for v in rng.integers(0, 256, 3)], "radius": 4}
        if i % 2:
            e["material"] = 2
        f.write(json.dumps(e) + "\n")
PY
edit_opts="--metric euclidean --max-distance 16 --chunk 16"
# shellcheck disable=SC2086
build/release/bin/voxfield edit "$out/terrain.npy" -e "$out/edits.jsonl" -o "$out/edit-one.npy" \
  $edit_opts --threads 2 --stats "$out/edit-one.json" 2>/dev/null
for n in 1 2 4; do
  # shellcheck disable=SC2086
  $M -np "$n" $B edit "$out/terrain.npy" -e "$out/edits.jsonl" -o "$out/edit-$n.npy" $edit_opts \
    --threads 1 --stats "$out/edit-$n.json" 2>/dev/null
  cmp "$out/edit-one.npy" "$out/edit-$n.npy"
  rm -f "$out/edit-$n.npy"
done
rm -f "$out/edit-one.npy" "$out/terrain.npy"
/usr/bin/python3 - "$out" <<'PY' | tee "$out/edits.md"
import json, sys
out = sys.argv[1]
print("| edits, 256^3 terrain, clamp 16 | p50 ms | p99 ms | total ms | build ms | ranks an edit reached (mean) | ghost slices |")
print("|---|---|---|---|---|---|---|")
one = json.load(open(out + "/edit-one.json"))
print("| one process (voxfield edit, 2 threads) | %.3f | %.3f | %.0f | %.0f | — | — |" % (
    one["p50_ms"], one["p99_ms"], one["total_ms"], one["build_ms"]))
for n in (1, 2, 4):
    j = json.load(open("%s/edit-%d.json" % (out, n)))
    print("| %d rank%s (voxfield-mpi edit, 1 thread each) | %.3f | %.3f | %.0f | %.0f | %.2f | %d |" % (
        n, "" if n == 1 else "s", j["p50_ms"], j["p99_ms"], j["total_ms"], j["build_ms"],
        j["ranks_reached_per_edit"], j["ghost_slices"]))
PY
/usr/bin/python3 - "$out" <<'PY' | tee "$out/table.md"
import json, sys
runs = [json.loads(l) for l in open(sys.argv[1] + "/runs.jsonl")]
print("| run | ranks | best ms | Mvox/s | compute ms (slowest rank) | exchange ms (slowest) | bytes sent, all ranks | payload 16 B x columns x (ranks-1) | peak RSS per rank, MB |")
print("|---|---|---|---|---|---|---|---|---|")
seen = {}
for r in runs:
    seen.setdefault(r["label"], []).append(r)
for label, rs in seen.items():
    b = min(rs, key=lambda r: r["ms"])
    x = b["exchange"]
    d = b["dims"]
    payload = 16 * d[0] * d[1] * (b["ranks"] - 1)
    print("| %s | %d | %.0f | %.0f | %.0f | %.1f | %d | %d | %.0f |" % (
        label, b["ranks"], b["ms"], b["mvox_per_s"], x["compute_ms_max"], x["exchange_ms_max"],
        x["bytes_sent_total"], payload, b["peak_rss_mb_max"]))
PY

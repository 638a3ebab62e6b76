#!/usr/bin/env bash
# voxfield-mpi: strong and weak scaling of exact fields over MPI ranks on this machine, the bytes
# exchanged against the algorithm's payload (16 bytes per column and rank boundary), and a volume
# larger than any one rank may hold. Worlds of random spheres are generated slab by slab
# (voxfield-mpi bench), so no rank ever holds more than its slab. This machine has 2 cores: 4
# ranks oversubscribe them (Open MPI's --oversubscribe), so past 2 ranks the figures show the
# overhead of more ranks, not more speed. Each rank is bound to a core (Open MPI's default) and
# runs one thread; "1 rank x 2 threads" (--bind-to none) is the single-process baseline.
# JSON lines per run and a markdown table into bench/results/mpi-DATE/.
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

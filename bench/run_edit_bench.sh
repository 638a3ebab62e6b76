#!/usr/bin/env bash
# Incremental-update latency (the editable-worlds issue's targets): the r = 4 sphere stream with a
# Euclidean clamp of 16 at 128^3 / 256^3 / 512^3 (three runs each: p99 moves +-15 % run to run on
# these machines) and once at 1024^3, the dissertation's stream at 1024^3, and dynamicEDT3D on identical edits in the
# same process (r = 4 and r = 8). Raw JSON and the printed tables go to bench/results/edits-DATE/.
# Usage: bash bench/run_edit_bench.sh [RUNS]   (default 3)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
source bench/common.sh
bench_prepare --peers
bench_results edits
B=build/release/bin/voxfield
for n in 128 256 512; do
  for k in $(seq 1 "$runs"); do
    $B bench edits --world "$n" --edits 500 --metric euclidean --max-distance 16 --radius-min 4 --radius-max 4 \
      --json "$out/r4-euclid-c16-$n-run$k.json" | tee "$out/r4-euclid-c16-$n-run$k.txt" | sed -n 2,3p | sed "s/^/$n run $k: /"
  done
done
# The same at 512^3 with 8-bit storage (a quarter of the field memory to fill when chunks turn dense).
for k in $(seq 1 "$runs"); do
  $B bench edits --world 512 --edits 500 --metric euclidean --max-distance 16 --radius-min 4 --radius-max 4 --storage u8 \
    --json "$out/r4-euclid-c16-u8-512-run$k.json" | tee "$out/r4-euclid-c16-u8-512-run$k.txt" | sed -n 2,3p | sed "s/^/512 u8 run $k: /"
done
# The same stream at 1024^3, once (the world-size independence target).
$B bench edits --world 1024 --edits 500 --metric euclidean --max-distance 16 --radius-min 4 --radius-max 4 \
  --json "$out/r4-euclid-c16-1024.json" | tee "$out/r4-euclid-c16-1024.txt" | sed -n 2,3p | sed "s/^/1024: /"
$B bench edits --world 1024 --chunk 32 --edits 300 --metric manhattan --max-distance 16 --storage u8 \
  --json "$out/dissertation-stream-1024.json" | tee "$out/dissertation-stream-1024.txt" | sed -n 2,3p
g++ -O3 -std=c++20 -Iinclude bench/peers/dynamicedt3d/edits_peer.cpp -Lbuild/release -lvoxfield -ldynamicedt3d -ltbb -lz -lpng \
  -o build/release/edits_peer
for r in 4 8; do
  build/release/edits_peer 256 400 "$r" "$r" 16 2 "$out/dynamicedt3d-r$r.json" | tee "$out/dynamicedt3d-r$r.txt"
done
echo "results in $out"

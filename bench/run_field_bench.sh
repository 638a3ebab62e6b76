#!/usr/bin/env bash
# Reproduces the exact-field figures in docs/benchmarks.md: voxfield, SciPy and OpenVDB on the
# same inputs in one run. Results go to bench/results/field-DATE/ (records, table, plot).
# Usage: bash bench/run_field_bench.sh [RUNS]   (default 5 timed runs after a warm-up)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
source bench/common.sh
bench_prepare --peers
bin=build/release/bin
bench_results field >/dev/null
mkdir -p "$out/inputs"
inputs=()
for scene in spheres terrain; do
  for n in 128 256; do
    "$bin/voxfield" generate $scene --size $n -o "$out/inputs/$scene-$n.npy"
    inputs+=("$out/inputs/$scene-$n.npy")
  done
done
for f in ephtracy_monu3 qinzhuo_teapot1 mmmm_scene_store8; do
  "$bin/voxfield" convert "../shared/data/vox/$f.vox" "$out/inputs/$f.npy"
  inputs+=("$out/inputs/$f.npy")
done
list=$(IFS=,; echo "${inputs[*]}")
cat "$out/machine.txt"
"$bin/voxfield-bench-field" --scenes "" --inputs "$list" --threads 1,2 --runs "$runs" --json "$out/records.jsonl"
unset OPENBLAS_CORETYPE OPENBLAS_L2_SIZE
/usr/bin/python3 bench/peers/scipy_peer.py --runs "$runs" --json "$out/records.jsonl" "${inputs[@]}"
g++ -O3 -std=c++20 -Iinclude -Ibench bench/peers/openvdb/openvdb_peer.cpp -Lbuild/release -lvoxfield -lopenvdb \
  -lImath-3_1 -ltbb -lz -o "$out/openvdb_peer"
"$out/openvdb_peer" "$runs" "$out/records.jsonl" "$out/inputs/spheres-128.npy" "$out/inputs/terrain-128.npy" \
  "$out/inputs/spheres-256.npy" "$out/inputs/terrain-256.npy"
/usr/bin/python3 bench/report.py "$out/records.jsonl" --plot "$out/field-throughput.png" | tee "$out/table.md"
rm -rf "$out/inputs" "$out/openvdb_peer"
echo "results in $out"

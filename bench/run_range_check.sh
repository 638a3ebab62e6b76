#!/usr/bin/env bash
# Before/after cost of the coordinate-range checks the hostile-input work added to hot paths
# (Grid::set on unbounded grids — every voxel the .vox reader places — and Grid::copy_to_dense):
# this tree's CLI against the CLI of a commit before them (default 26eac82), runs alternated.
#  * `voxfield info ephtracy_monu3.vox` (3.4 MB, 1.9 M voxels placed) under `perf stat -r 20`;
#  * `voxfield bench edits` r = 4 spheres, Euclidean clamp 16, 256^3, 500 edits.
# Usage: bash bench/run_range_check.sh [COMMIT] [ROUNDS]   (builds COMMIT's CLI in /tmp)
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:-26eac82}; rounds=${2:-2}
source bench/common.sh
bench_prepare
bench_results range-check
old_tree=/tmp/voxfield-$base
[ -d "$old_tree" ] || git worktree add -f "$old_tree" "$base" >/dev/null
(cd "$old_tree" && cmake --preset release >/dev/null && cmake --build --preset release --target voxfield_cli >/dev/null)
NEW=build/release/bin/voxfield; OLD=$old_tree/build/release/bin/voxfield
echo "base $base" >> "$out/machine.txt"
for k in $(seq 1 "$rounds"); do
  for b in OLD NEW; do
    bin=${!b}
    perf stat -r 20 "$bin" info ../shared/data/vox/ephtracy_monu3.vox 2>&1 >/dev/null |
      grep -E "task-clock|elapsed" | sed "s/^/$b info round $k: /" | tee -a "$out/info.txt"
  done
done
for k in $(seq 1 "$rounds"); do
  for b in OLD NEW; do
    bin=${!b}
    "$bin" bench edits --world 256 --edits 500 --metric euclidean --max-distance 16 --radius-min 4 \
      --radius-max 4 --json "$out/edits-$b-$k.json" 2>/dev/null | sed -n 2,3p | sed "s/^/$b edits round $k: /" |
      tee -a "$out/edits.txt"
  done
done

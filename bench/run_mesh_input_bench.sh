#!/usr/bin/env bash
# Mesh -> signed distance field against OpenVDB's meshToLevelSet (bench/mesh_input_bench.py) on
# both threads and on one, into bench/results/mesh-input-DATE/.
# Usage: bash bench/run_mesh_input_bench.sh [REPEAT]   (default 3)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mesh-input
for threads in 0 1; do
  echo "== threads: $([ "$threads" = 0 ] && echo all || echo 1) (OpenVDB: all)"
  /usr/bin/python3 bench/mesh_input_bench.py build/release/bin/voxfield /var/cache/voxfield/test-meshes \
    "${1:-3}" "$threads" | tee "$out/threads-$threads.md"
done

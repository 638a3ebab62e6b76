#!/usr/bin/env bash
# Reproduces the rendering figures in docs/benchmarks.md: primary rays per second on a generated
# 512³ terrain at 640x360 and 1280x720, shading costs, what skipping buys and which field to skip
# by. Results go to bench/results/render-DATE/ (records and table).
# Usage: bash bench/run_render_bench.sh [RUNS]   (default 7 timed frames after a warm-up)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-7}
source bench/common.sh
bench_prepare
bench_results render
build/release/bin/voxfield-bench-render --size 512 --runs "$runs" --json "$out/records.jsonl" | tee "$out/table.txt"
build/release/bin/voxfield-bench-render --size 512 --runs "$runs" --threads 1 --resolutions 640x360 \
    --only "flat shading, manhattan" --json "$out/records.jsonl" | tee -a "$out/table.txt"
echo "results in $out"

#!/usr/bin/env bash
# The vector-field paper's six tests (voxfield bench vectors), CSV and printed tables into
# bench/results/vectors-DATE/. Usage: bash bench/run_vectors_bench.sh [STEPS]   (default 30)
set -euo pipefail
cd "$(dirname "$0")/.."
steps=${1:-30}
source bench/common.sh
bench_prepare
bench_results vectors
B=build/release/bin/voxfield
for t in fidelity decay jfa-sources jfa-resolution time-step quarter-resolution; do
  echo "== $t"
  $B bench vectors --test "$t" --steps "$steps" --csv "$out/$t.csv" 2>/dev/null | tee "$out/$t.md"
done

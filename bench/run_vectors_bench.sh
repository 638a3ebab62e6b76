#!/usr/bin/env bash
# The vector-field paper's six tests (voxfield bench vectors): CSV, printed tables and SVG plots into
# bench/results/vectors-DATE/, on the CPU; then the fidelity and quarter-resolution tests on the
# Vulkan backend for its counters (on lavapipe its times are CPU emulation, not GPU speed).
# Usage: bash bench/run_vectors_bench.sh [STEPS]   (default 30)
set -euo pipefail
cd "$(dirname "$0")/.."
steps=${1:-30}
source bench/common.sh
bench_prepare
bench_results vectors
B=build/release/bin/voxfield
for t in fidelity decay jfa-sources jfa-resolution time-step quarter-resolution; do
  echo "== $t"
  $B bench vectors --test "$t" --steps "$steps" --csv "$out/$t.csv" --plot "$out/$t.svg" 2>/dev/null |
    tee "$out/$t.md"
done
for t in fidelity quarter-resolution; do
  echo "== $t, Vulkan"
  $B bench vectors --test "$t" --steps "$steps" --backend vulkan --csv "$out/$t-vulkan.csv" 2>/dev/null |
    tee "$out/$t-vulkan.md"
done

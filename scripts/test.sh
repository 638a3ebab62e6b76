#!/usr/bin/env bash
# Quick start, command 2: set up, build and run every test — the optimised build first, then the
# same suite under AddressSanitizer + UndefinedBehaviorSanitizer (the parsers face untrusted files),
# then the concurrency tests under ThreadSanitizer.
# Set VOXFIELD_TEST_PRESETS to choose, e.g. VOXFIELD_TEST_PRESETS=release.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
presets=${VOXFIELD_TEST_PRESETS:-"release asan-ubsan tsan"}
for preset in $presets; do
  echo "=== voxfield tests: $preset ==="
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  ctest --preset "$preset" -j "$(nproc)"
done

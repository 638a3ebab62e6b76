#!/usr/bin/env bash
# Quick start, command 2: set up, build and run every test — the optimised build first, then the
# same suite under AddressSanitizer + UndefinedBehaviorSanitizer (the parsers face untrusted files),
# then the concurrency tests under ThreadSanitizer.
# then every libFuzzer harness for a short smoke on its seeds (a parser regression fails CI).
# Set VOXFIELD_TEST_PRESETS to choose, e.g. VOXFIELD_TEST_PRESETS=release; VOXFIELD_FUZZ_SECONDS
# sets the smoke's length per harness (0 skips it).
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
fuzz_seconds=${VOXFIELD_FUZZ_SECONDS:-20}
if [ "$fuzz_seconds" -gt 0 ]; then
  echo "=== voxfield fuzz smoke: ${fuzz_seconds}s per harness ==="
  cmake --preset release >/dev/null && cmake --build --preset release --target voxfield_cli  # makes the seeds
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz
  bash fuzz/run.sh "$fuzz_seconds"
fi

#!/usr/bin/env bash
# Quick start, command 2: set up, build and run every test — the optimised build first (with the
# layering check and the installed-package consumer), then the build without any GPU dependency
# (cpu-only), then the same suite under AddressSanitizer + UndefinedBehaviorSanitizer (the parsers
# face untrusted files), then the concurrency tests under ThreadSanitizer, then every libFuzzer
# harness for a short smoke on its seeds, one per core (a parser regression fails CI).
# Set VOXFIELD_TEST_PRESETS to choose, e.g. VOXFIELD_TEST_PRESETS=release; VOXFIELD_FUZZ_SECONDS
# sets the smoke's length per harness (0 skips it). Each phase prints its wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
phase_start=$SECONDS
phase_done() { echo "=== $1: $((SECONDS - phase_start)) s ==="; phase_start=$SECONDS; }
# The optimised build: release-ci (release built as unity batches, CMakePresets.json says why) on a
# fresh tree, as in CI; a tree that already has a release build (the showcase's, a developer's)
# tests that one instead of building the same code again. cpu-only-ci is the cpu-only preset at
# -O1 (what CI checks there does not depend on optimisation).
optimised=release-ci
if [ -f build/release/build.ninja ]; then optimised=release; fi
presets=${VOXFIELD_TEST_PRESETS:-"$optimised cpu-only-ci asan-ubsan tsan"}
for preset in $presets; do
  echo "=== voxfield tests: $preset ==="
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  phase_done "$preset build"
  ctest --preset "$preset" -j "$(nproc)"
  phase_done "$preset tests"
done
# 6 s per harness (11 harnesses, one per core: about 40 s): every seed runs at the start, and the
# CI run as a whole keeps under its 40 minutes (at 15 s it passed them by a few seconds; at 10 s,
# on a slow day, by a minute: 72 s of its 2473).
fuzz_seconds=${VOXFIELD_FUZZ_SECONDS:-6}
if [ "$fuzz_seconds" -gt 0 ]; then
  echo "=== voxfield fuzz smoke: ${fuzz_seconds}s per harness ==="
  # The seeds are made by an optimised CLI: the one this run built, or release's.
  cli_preset=release
  case " $presets " in *" release-ci "*) cli_preset=release-ci ;; esac
  cmake --preset $cli_preset >/dev/null && cmake --build --preset $cli_preset --target voxfield_cli
  export VOXFIELD_CLI=build/$cli_preset/bin/voxfield
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz
  phase_done "fuzz build"
  FUZZ_JOBS=$(nproc) bash fuzz/run.sh "$fuzz_seconds"
  phase_done "fuzz smoke"
fi

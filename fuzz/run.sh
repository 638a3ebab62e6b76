#!/usr/bin/env bash
# Runs every libFuzzer harness on its seeds for SECONDS each (default 25): the CI smoke, and with a
# larger budget a campaign. Seeds: the MagicaVoxel corpus in ../shared/data/vox (read in place),
# .npy and .vfw files converted from its small models by the release CLI, and the text seeds in
# fuzz/seeds/. New inputs libFuzzer finds go to a scratch corpus, not into the repository; a
# crash stops the run with the harness's report and the crashing input under $FUZZ_OUT.
# Usage: bash fuzz/run.sh [SECONDS] [HARNESS...]   (needs build/fuzz and build/release/bin/voxfield)
# FUZZ_RUNS=N stops each harness after N executions instead (with SECONDS still the cap).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-25}; shift || true
harnesses=${*:-"vox npy vfw edit_script options"}
bin=build/fuzz/bin
cli=build/release/bin/voxfield
corpus=../shared/data/vox
out=${FUZZ_OUT:-$(mktemp -d)}
mkdir -p "$out"

seeds="$out/seeds"
mkdir -p "$seeds/npy" "$seeds/vfw"
for m in ephtracy_chr_cat ephtracy_chr_knight mmmm_chr_mayor vengi_robo vengi_teardown; do
  [ -s "$seeds/npy/$m.npy" ] || "$cli" convert "$corpus/$m.vox" "$seeds/npy/$m.npy" 2>/dev/null
  [ -s "$seeds/vfw/$m.vfw" ] || "$cli" convert "$corpus/$m.vox" "$seeds/vfw/$m.vfw" 2>/dev/null
done

for h in $harnesses; do
  case $h in
    vox) dirs="$corpus"; max_len=65536 ;;
    npy) dirs="$seeds/npy"; max_len=65536 ;;
    vfw) dirs="$seeds/vfw"; max_len=65536 ;;
    edit_script) dirs="fuzz/seeds/edit_script"; max_len=4096 ;;
    options) dirs="fuzz/seeds/options"; max_len=256 ;;
    *) echo "unknown harness $h" >&2; exit 2 ;;
  esac
  work="$out/corpus-$h"; mkdir -p "$work"
  echo "=== fuzz_$h: ${seconds}s ==="
  runs=${FUZZ_RUNS:+-runs=$FUZZ_RUNS}
  "$bin/fuzz_$h" -max_total_time="$seconds" $runs -max_len="$max_len" -timeout=20 -rss_limit_mb=2560 \
      -artifact_prefix="$out/crash-$h-" -print_final_stats=1 "$work" $dirs 2>"$out/log-$h.txt" || {
    echo "fuzz_$h FAILED; its log:" >&2; tail -60 "$out/log-$h.txt" >&2; exit 1; }
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb|cov: " "$out/log-$h.txt" | tail -3
done

#!/usr/bin/env bash
# Runs every libFuzzer harness on its seeds for SECONDS each (default 25): the CI smoke, and with a
# larger budget a campaign. Seeds: the files of the MagicaVoxel corpus in ../shared/data/vox up to
# 8 KiB, .npy and .vfw files converted from its small models by the release CLI, and the text seeds
# in fuzz/seeds/. Binary inputs are capped at 8 KiB: every structure of the three formats fits, and
# a harness that spends its time on megabyte seeds (the corpus's scenes) runs a few executions a
# second instead of thousands (the large files are parsed whole by the unit tests). New inputs
# libFuzzer finds go to a scratch corpus, not into the repository; a crash stops that harness, its
# report (on stdout, with the log's tail) names the crashing input under $FUZZ_OUT, and the run
# fails once every harness has finished.
# Usage: bash fuzz/run.sh [SECONDS] [HARNESS...]   (needs build/fuzz and build/release/bin/voxfield,
# or the optimised CLI named by VOXFIELD_CLI)
# FUZZ_JOBS=N runs N harnesses at once (one per core for CI's smoke);
# FUZZ_RUNS=N stops each harness after N executions instead (with SECONDS still the cap);
# FUZZ_TIMEOUT=S sets the per-input time-out (default 20 s; a campaign at nice 19 beside a build
# needs more: a starved process is not a slow input).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-25}; shift || true
harnesses=${*:-"vox npy vfw vdb edit_script options vector_sources csg_model openscad mesh mesh_pieces"}
bin=build/fuzz/bin
cli=${VOXFIELD_CLI:-build/release/bin/voxfield}
corpus=../shared/data/vox
out=${FUZZ_OUT:-$(mktemp -d)}
mkdir -p "$out"

seeds="$out/seeds"
max_seed=8192
mkdir -p "$seeds/vox" "$seeds/npy" "$seeds/vfw" "$seeds/vdb"
find "$corpus" -name '*.vox' -size -$((max_seed + 1))c -exec cp {} "$seeds/vox/" \;
for m in ephtracy_chr_cat ephtracy_chr_knight mmmm_chr_mayor vengi_robo ephtracy_snow; do
  for ext in npy vfw; do
    [ -s "$seeds/$ext/$m.$ext" ] || "$cli" convert "$corpus/$m.vox" "$seeds/$ext/$m.$ext" >/dev/null 2>&1
    [ "$(stat -c %s "$seeds/$ext/$m.$ext")" -le $max_seed ] || rm "$seeds/$ext/$m.$ext"
  done
  # .vdb seeds: a world's Int32 grid and a signed field's level set, as voxfield writes them
  # (OpenVDB's writer: Blosc, active-mask compression); a top node alone is kilobytes, so their
  # cap is higher.
  [ -s "$seeds/vdb/$m.vdb" ] || "$cli" convert "$corpus/$m.vox" "$seeds/vdb/$m.vdb" >/dev/null 2>&1
  [ -s "$seeds/vdb/$m-sdf.vdb" ] ||
    "$cli" field "$corpus/$m.vox" -o "$seeds/vdb/$m-sdf.vdb" --signed --max-distance 3 >/dev/null 2>&1
done
# A world in a frame (a voxelised cube keeps the mesh's units): a .vfw with a frame section and a
# .vdb whose transform scales and translates.
printf 'v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 1 5 8 4\nf 2 3 7 6\n' >"$seeds/cube.obj"
for ext in vfw vdb; do
  [ -s "$seeds/$ext/framed.$ext" ] ||
    "$cli" convert "$seeds/cube.obj" "$seeds/$ext/framed.$ext" --voxel-size 0.5 >/dev/null 2>&1
done
find "$seeds/vdb" -size +$((4 * max_seed))c -delete

# One harness: its seeds, its scratch corpus, its log; a finding prints the log's tail and fails.
run_one() {
  local h=$1 dirs max_len work runs started
  case $h in
    vox) dirs="$seeds/vox"; max_len=$max_seed ;;
    npy) dirs="$seeds/npy"; max_len=$max_seed ;;
    vfw) dirs="$seeds/vfw"; max_len=$max_seed ;;
    vdb) dirs="$seeds/vdb"; max_len=$((4 * max_seed)) ;;
    edit_script) dirs="fuzz/seeds/edit_script"; max_len=4096 ;;
    options) dirs="fuzz/seeds/options"; max_len=256 ;;
    vector_sources) dirs="fuzz/seeds/vector_sources"; max_len=4096 ;;
    csg_model) dirs="fuzz/seeds/csg"; max_len=4096 ;;
    openscad) dirs="fuzz/seeds/openscad"; max_len=4096 ;;
    mesh) dirs="fuzz/seeds/mesh"; max_len=4096 ;;
    mesh_pieces) dirs=""; max_len=600 ;;  # edits to real pieces the harness makes itself
    *) echo "unknown harness $h" >&2; return 2 ;;
  esac
  work="$out/corpus-$h"; mkdir -p "$work"
  echo "=== fuzz_$h: ${seconds}s ==="
  runs=${FUZZ_RUNS:+-runs=$FUZZ_RUNS}
  started=$SECONDS
  "$bin/fuzz_$h" -max_total_time="$seconds" $runs -max_len="$max_len" -timeout="${FUZZ_TIMEOUT:-20}" -rss_limit_mb=2560 \
      -artifact_prefix="$out/crash-$h-" -print_final_stats=1 "$work" $dirs 2>"$out/log-$h.txt" || {
    echo "fuzz_$h FAILED; its log:" >&2; tail -60 "$out/log-$h.txt" >&2; return 1; }
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb|cov: " "$out/log-$h.txt" | tail -3
  echo "fuzz_$h: $((SECONDS - started)) s"
}

# FUZZ_JOBS harnesses at a time (default 1; CI's smoke runs one per core), each report printed
# whole; each job leaves its exit status in a file, so none is lost however fast it ends.
jobs_max=${FUZZ_JOBS:-1}
[ "$jobs_max" -ge 1 ] 2>/dev/null || jobs_max=1
for h in $harnesses; do rm -f "$out/status-$h"; done  # a reused FUZZ_OUT keeps no old verdict
for h in $harnesses; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do sleep 0.2; done
  ( set +e; run_one "$h"; echo $? >"$out/status-$h" ) >"$out/report-$h.txt" 2>&1 &
done
wait
failed=0
for h in $harnesses; do
  cat "$out/report-$h.txt"
  [ "$(cat "$out/status-$h" 2>/dev/null)" = 0 ] || failed=1
done
exit $failed

#!/usr/bin/env bash
# voxfield-mpi field reading a .vdb a slab per rank: the SIZE x SIZE x SIZE/2 terrain's signed
# Euclidean level set (clamp 3) as OpenVDB stores it, its field (Manhattan, clamp 8, u8) on 1, 2
# and 4 ranks (4 oversubscribe this machine's 2 cores); per run the largest and smallest peak
# resident memory of a rank and the slowest rank's load time; every field must equal
# `voxfield field`'s byte for byte. With BASE=path/to/an/older/voxfield-mpi, the same runs of that
# binary beside (e.g. one that decoded the whole file on every rank). Best of REPEAT by load time.
# JSON per run and a markdown table into bench/results/mpi-vdb-read-DATE/.
# Usage: [BASE=...] bash bench/run_mpi_vdb_read_bench.sh [REPEAT] [SIZE]   (defaults 3 and 512)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mpi-vdb-read
repeat=${1:-3}
size=${2:-512}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
B=build/release/bin
"$B/voxfield" generate terrain --size "$size,$size,$((size / 2))" -o "$out/terrain.vfw" 2>/dev/null
"$B/voxfield" field "$out/terrain.vfw" -o "$out/terrain-sdf.vdb" --metric euclidean --signed \
  --max-distance 3 2>/dev/null
opts="--metric manhattan --max-distance 8 --storage u8"
# shellcheck disable=SC2086
"$B/voxfield" field "$out/terrain-sdf.vdb" -o "$out/one.npy" $opts 2>/dev/null
binaries=("$B/voxfield-mpi")
if [ -n "${BASE:-}" ]; then binaries+=("$BASE"); fi
for r in $(seq 1 "$repeat"); do
  for n in 1 2 4; do
    for i in "${!binaries[@]}"; do
      # shellcheck disable=SC2086
      mpirun --oversubscribe -np "$n" bash -c \
        '/usr/bin/time -f "peak_kb %M" -o "$0-$OMPI_COMM_WORLD_RANK.txt" "$@"' "$out/peak-$i-$n-$r" \
        "${binaries[$i]}" field "$out/terrain-sdf.vdb" -o "$out/mpi.npy" $opts \
        --stats "$out/mpi-$i-$n-$r.json" 2>/dev/null
      cmp "$out/one.npy" "$out/mpi.npy"
    done
  done
done
rm -f "$out/terrain.vfw" "$out/one.npy" "$out/mpi.npy"
vdb_bytes=$(stat -c %s "$out/terrain-sdf.vdb")
rm -f "$out/terrain-sdf.vdb"
/usr/bin/python3 - "$out" "${#binaries[@]}" "$vdb_bytes" <<'PY' | tee "$out/table.md"
import glob, json, sys
out, binaries, file_bytes = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
print(f"The level set: {file_bytes / 1e6:.1f} MB as a .vdb.\n")
print("| binary | ranks | load ms (slowest rank) | field ms | peak per rank, MB (largest / smallest) | read in parts |")
print("|---|---|---|---|---|---|")
for i in range(binaries):
    for n in (1, 2, 4):
        runs = []
        for path in glob.glob(f"{out}/mpi-{i}-{n}-*.json"):
            r = path.rsplit("-", 1)[1][:-5]
            s = json.load(open(path))
            peaks = [int(open(p).read().split()[1]) / 1024
                     for p in glob.glob(f"{out}/peak-{i}-{n}-{r}-*.txt")]
            runs.append((s["load_ms_max"], s["ms"], max(peaks), min(peaks), s["read_in_parts"]))
        load, ms, hi, lo, parts = min(runs)
        name = "this commit" if i == 0 else "BASE"
        print(f"| {name} | {n} | {load:.0f} | {ms:.0f} | {hi:.0f} / {lo:.0f} | {parts} |")
PY

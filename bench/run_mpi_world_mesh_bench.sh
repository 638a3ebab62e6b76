#!/usr/bin/env bash
# voxfield-mpi mesh of a world (its voxels' surface through the exact signed field, coloured by
# material: `voxfield mesh WORLD`'s file) over 1, 2 and 4 ranks, beside one process (voxfield mesh,
# 2 and 1 threads), on the generated terrain worlds of SIZES; every rank count's file compared with
# one process's by cmp. Whole-command wall time and peak memory by /usr/bin/time (mpirun's start
# included), and each command's own JSON: one process's `ms` is meshing alone (its encoding in
# phases_ms), the ranks' `ms` meshing and writing the file, `load_ms_max` both readings of the
# world. This machine has 2 cores: 4 ranks oversubscribe them.
# Usage: bash bench/run_mpi_world_mesh_bench.sh [ROUNDS] [SIZES]   (defaults 3 and "256 512")
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mpi-world-mesh
rounds=${1:-3}
sizes=${2:-256 512}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
B=build/release/bin
log="$out/runs.txt"
for size in $sizes; do
  world="$out/t$size.vfw"
  "$B/voxfield" generate terrain --size "$size" -o "$world" 2>/dev/null
  for round in $(seq 1 "$rounds"); do
    for t in 2 1; do
      /usr/bin/time -f "%e s %M KB" "$B/voxfield" mesh "$world" -o "$out/one.ply" --threads "$t" \
        --stats "$out/one-$size-$t-$round.json" 2>"$out/time.txt" >/dev/null
      echo "t$size round $round one process, $t threads: $(tail -1 "$out/time.txt")" | tee -a "$log"
    done
    for n in 1 2 4; do
      /usr/bin/time -f "%e s %M KB" mpirun -np "$n" "$B/voxfield-mpi" mesh "$world" -o "$out/ranks.ply" \
        --stats "$out/ranks-$size-$n-$round.json" 2>"$out/time.txt" >/dev/null
      same=no
      cmp -s "$out/one.ply" "$out/ranks.ply" && same=yes
      echo "t$size round $round $n ranks: $(tail -1 "$out/time.txt"), the same file: $same" | tee -a "$log"
    done
  done
  rm -f "$world" "$out/one.ply" "$out/ranks.ply"
done
/usr/bin/python3 - "$out" <<'PY' | tee "$out/summary.md"
import glob, json, os, sys
out = sys.argv[1]
print("| world | run | ms per round | load ms (slowest rank) | ghost slices | chunk layers | bytes sent | peak RSS per rank, MB |")
print("|---|---|---|---|---|---|---|---|")
sizes = sorted({int(os.path.basename(p).split("-")[1]) for p in glob.glob(out + "/one-*.json")})
for size in sizes:
    for t in (2, 1):
        js = [json.load(open(p)) for p in sorted(glob.glob(f"{out}/one-{size}-{t}-*.json"))]
        ms = ", ".join("%.0f + %.0f" % (j["ms"], j["phases_ms"]["encode"]) for j in js)
        print(f"| t{size} | one process, {t} threads (mesh + encode) | {ms} | | | | | |")
    for n in (1, 2, 4):
        js = [json.load(open(p)) for p in sorted(glob.glob(f"{out}/ranks-{size}-{n}-*.json"))]
        j = js[0]
        print("| t%d | %d ranks (mesh and write) | %s | %s | %d | %s | %d | %.0f |" % (
            size, n, ", ".join("%.0f" % k["ms"] for k in js), ", ".join("%.0f" % k["load_ms_max"] for k in js),
            j["ghost_slices"], " ".join(str(c) for c in j["chunk_layers"]),
            j["exchange"]["bytes_sent_total"], max(k["peak_rss_mb_max"] for k in js)))
PY

#!/usr/bin/env bash
# voxfield-mpi mesh: the 256^3 terrain's exact signed field (a float32 .npy) meshed by marching
# cubes over 1, 2 and 4 ranks of one thread, the chunk layers dealt by count and by content, beside
# one process (voxfield mesh, 1 and 2 threads); every rank's mesh checked against one process's,
# triangle for triangle (scripts/same_triangles.py) and byte for byte (marching cubes meshes slabs of
# voxfield mesh's own passes). This machine has 2 cores: 4 ranks oversubscribe them.
# Best of REPEAT runs per row; JSON per run and a markdown table into bench/results/mpi-mesh-DATE/.
# Usage: bash bench/run_mpi_mesh_bench.sh [REPEAT] [SIZE]   (defaults 3 and 256)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mpi-mesh
repeat=${1:-3}
size=${2:-256}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
B=build/release/bin
"$B/voxfield" generate terrain --size "$size" -o "$out/terrain.npy" 2>/dev/null
"$B/voxfield" field "$out/terrain.npy" -o "$out/sdf.npy" --metric euclidean --signed 2>/dev/null
for r in $(seq 1 "$repeat"); do
  "$B/voxfield" mesh "$out/sdf.npy" -o "$out/one.ply" --threads 1 --stats "$out/one1-$r.json" 2>/dev/null
  "$B/voxfield" mesh "$out/sdf.npy" -o "$out/one.ply" --threads 2 --stats "$out/one-$r.json" 2>/dev/null
done
for n in 1 2 4; do
  for balance in count content; do
    for r in $(seq 1 "$repeat"); do
      mpirun --oversubscribe -np "$n" "$B/voxfield-mpi" mesh "$out/sdf.npy" -o "$out/mpi.ply" \
        --threads 1 --balance "$balance" --stats "$out/mpi-$n-$balance-$r.json" 2>/dev/null
    done
    /usr/bin/python3 scripts/same_triangles.py "$out/one.ply" "$out/mpi.ply" > "$out/same-$n-$balance.txt"
    if cmp -s "$out/one.ply" "$out/mpi.ply"; then echo yes; else echo no; fi > "$out/bytes-$n-$balance.txt"
  done
done
rm -f "$out/terrain.npy" "$out/sdf.npy" "$out/one.ply" "$out/mpi.ply"
/usr/bin/python3 - "$out" "$repeat" <<'PY' | tee "$out/table.md"
import glob, json, sys
out, repeat = sys.argv[1], int(sys.argv[2])
def best(pattern):
    runs = [json.load(open(f)) for f in glob.glob(out + "/" + pattern)]
    return min(runs, key=lambda j: j["ms"])
print("| run | ranks | chunk layers (cuts) | mesh ms (best of %d) | load ms (slowest rank) | bytes received, all ranks | peak RSS per rank, MB | triangles | same as one process | the same file bytes |" % repeat)
print("|---|---|---|---|---|---|---|---|---|---|")
for threads, pattern in ((1, "one1-*.json"), (2, "one-*.json")):
    one = best(pattern)
    print("| voxfield mesh, 1 process x %d thread%s | 1 | — | %.0f | %.0f | — | — | %d | — | — |" % (
        threads, "s" if threads > 1 else "", one["ms"], one["phases_ms"]["load"], one["triangles"]))
for n in (1, 2, 4):
    for balance in ("count", "content"):
        j = best("mpi-%d-%s-*.json" % (n, balance))
        same = open("%s/same-%d-%s.txt" % (out, n, balance)).read().split(",")[1].strip()
        same_bytes = open("%s/bytes-%d-%s.txt" % (out, n, balance)).read().strip()
        print("| voxfield-mpi mesh, by %s, 1 thread per rank | %d | %s | %.0f | %.0f | %d | %.0f | %d | %s | %s |" % (
            balance, n, " ".join(str(k) for k in j["chunk_layers"]), j["ms"], j["load_ms_max"],
            j["exchange"]["bytes_received_total"], j["peak_rss_mb_max"], j["triangles"], same, same_bytes))
PY

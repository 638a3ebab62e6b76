#!/usr/bin/env bash
# voxfield-mpi render against voxfield render on the same cores: the SIZE^3 terrain drawn at the
# default 1280x720 (shaded, shadows and ambient occlusion), one process and 1, 2 and 4 ranks, each
# frame compared with one process's byte for byte. mpirun binds each rank to one core when there
# are at most two, so a rank's thread pool has one core whatever --threads says: the rows set one
# process pinned to one core (taskset) beside one rank, and one process on two cores beside one
# rank bound to none with two threads and beside two ranks. This machine has 2 cores: 4 ranks
# oversubscribe them. Rows alternate within each round (the machine's load drifts); best of
# REPEAT rounds. The compute time is what each program reports after loading: voxfield render's
# fields + frame, voxfield-mpi's `ms` (its fields, scenes and the relayed frame); the whole command
# (loading, MPI's start) beside it. JSON per run and a markdown table into
# bench/results/mpi-render-DATE/.
# Usage: bash bench/run_mpi_render_bench.sh [REPEAT] [SIZE]   (defaults 5 and 256)
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results mpi-render
repeat=${1:-5}
size=${2:-256}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_pml=ob1 OMPI_MCA_btl=self,vader
B=build/release/bin
"$B/voxfield" generate terrain --size "$size" -o "$out/terrain.npy" 2>/dev/null
timed() {  # timed NAME ROUND CMD...: the command's wall seconds into NAME-ROUND.s
  local name=$1 r=$2
  shift 2
  /usr/bin/time -f %e -o "$out/$name-$r.s" "$@" >/dev/null 2>&1
}
for r in $(seq 1 "$repeat"); do
  timed one1 "$r" taskset -c 0 "$B/voxfield" render "$out/terrain.npy" -o "$out/one.png" --threads 1 \
    --stats "$out/one1-$r.json"
  timed mpi1x1 "$r" mpirun -np 1 "$B/voxfield-mpi" render "$out/terrain.npy" -o "$out/mpi1x1.png" \
    --stats "$out/mpi1x1-$r.json"
  timed one2 "$r" "$B/voxfield" render "$out/terrain.npy" -o "$out/one2.png" --threads 2 \
    --stats "$out/one2-$r.json"
  timed mpi1x2 "$r" mpirun --bind-to none -np 1 "$B/voxfield-mpi" render "$out/terrain.npy" \
    -o "$out/mpi1x2.png" --threads 2 --stats "$out/mpi1x2-$r.json"
  timed mpi2 "$r" mpirun -np 2 "$B/voxfield-mpi" render "$out/terrain.npy" -o "$out/mpi2.png" \
    --stats "$out/mpi2-$r.json"
  timed mpi4 "$r" mpirun --oversubscribe -np 4 "$B/voxfield-mpi" render "$out/terrain.npy" \
    -o "$out/mpi4.png" --stats "$out/mpi4-$r.json"
done
for f in one2 mpi1x1 mpi1x2 mpi2 mpi4; do
  if cmp -s "$out/one.png" "$out/$f.png"; then echo yes; else echo no; fi > "$out/bytes-$f.txt"
done
rm -f "$out/terrain.npy" "$out"/*.png
/usr/bin/python3 - "$out" "$repeat" <<'PY' | tee "$out/table.md"
import json, sys
out, repeat = sys.argv[1], int(sys.argv[2])
def runs(name):
    return [(json.load(open("%s/%s-%d.json" % (out, name, r))),
             float(open("%s/%s-%d.s" % (out, name, r)).read().split()[-1])) for r in range(1, repeat + 1)]
def same(name):
    return "—" if name == "one1" else open("%s/bytes-%s.txt" % (out, name)).read().strip()
print("| run | cores | compute ms, best of %d (all rounds) | whole command, s (best) | threads a rank reported | bytes sent, all ranks | frame = one process's |" % repeat)
print("|---|---|---|---|---|---|---|")
rows = (("voxfield render, pinned to one core, 1 thread", "one1", 1),
        ("voxfield-mpi render, 1 rank (bound to a core)", "mpi1x1", 1),
        ("voxfield render, 2 threads", "one2", 2),
        ("voxfield-mpi render, 1 rank bound to none, --threads 2", "mpi1x2", 2),
        ("voxfield-mpi render, 2 ranks (each bound to a core)", "mpi2", 2),
        ("voxfield-mpi render, 4 ranks (oversubscribed)", "mpi4", 2))
for label, name, cores in rows:
    rs = runs(name)
    if name.startswith("one"):
        ms = [j["field_ms"] + j["ms"] for j, _ in rs]
        sent = "—"
    else:
        ms = [j["ms"] for j, _ in rs]
        sent = "%d" % rs[0][0]["exchange"]["bytes_sent_total"]
    print("| %s | %d | %.0f (%s) | %.2f | %d | %s | %s |" % (
        label, cores, min(ms), ", ".join("%.0f" % m for m in ms), min(s for _, s in rs),
        rs[0][0]["threads"], sent, same(name)))
PY

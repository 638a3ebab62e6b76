#!/usr/bin/env bash
# The exact fields as a user runs them: `voxfield field` in a fresh process each time, one
# transform, fresh output memory (issue 20 asks for these figures beside the warmed-up harness's).
# Per run it records the transform's time (--stats: compute only), the whole command's wall time
# and its page faults. SciPy's distance_transform_edt runs on the same inputs in the same sitting.
# With --compare BIN, a second build of the CLI runs alternately with this one, run for run (what
# a before/after needs on a machine whose speed drifts).
# Usage: bash bench/run_cli_bench.sh [RUNS] [--compare BIN]   (default 5 runs per command)
# Results go to bench/results/cli-DATE/ (records.jsonl, table.md).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
other=""
if [ "${2:-}" = "--compare" ]; then other=$(realpath "$3"); fi
source bench/common.sh
bench_prepare --peers
bench_results cli >/dev/null
mkdir -p "$out/inputs"
bins=("$PWD/build/release/bin/voxfield")
[ -n "$other" ] && bins+=("$other")
"${bins[0]}" generate spheres --size 256 -o "$out/inputs/spheres-256.npy" >/dev/null
"${bins[0]}" generate terrain --size 256 -o "$out/inputs/terrain-256.npy" >/dev/null
commands=(
  "spheres-256 euclidean f32 1"
  "spheres-256 euclidean f32 2"
  "terrain-256 euclidean f32 2"
  "spheres-256 manhattan u8 2"
  "spheres-256 manhattan f32 2"
)
records="$out/records.jsonl"
for c in "${commands[@]}"; do
  read -r input metric storage threads <<<"$c"
  for ((r = 0; r < runs; ++r)); do
    for b in "${bins[@]}"; do
      /usr/bin/time -f "%e %R" -o "$out/time.txt" "$b" field "$out/inputs/$input.npy" \
        -o "$out/field.npy" --metric "$metric" --storage "$storage" --threads "$threads" \
        --stats "$out/stats.json" >/dev/null
      read -r wall faults <"$out/time.txt"
      /usr/bin/python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
print(json.dumps({"binary": sys.argv[2], "input": sys.argv[3], "metric": sys.argv[4], "storage": sys.argv[5],
                  "threads": int(sys.argv[6]), "transform_ms": s["ms"], "wall_s": float(sys.argv[7]),
                  "page_faults": int(sys.argv[8])}))' "$out/stats.json" "$b" "$input" "$metric" "$storage" \
        "$threads" "$wall" "$faults" >>"$records"
    done
  done
done
unset OPENBLAS_CORETYPE OPENBLAS_L2_SIZE
/usr/bin/python3 bench/peers/scipy_peer.py --runs "$runs" --metrics euclidean --json "$out/scipy.jsonl" \
  "$out/inputs/spheres-256.npy" "$out/inputs/terrain-256.npy" >/dev/null
/usr/bin/python3 - "$records" "$out/scipy.jsonl" <<'EOF' | tee "$out/table.md"
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
scipy = {r["input"]: r["median_ms"] for r in map(json.loads, open(sys.argv[2]))}
print("| binary | input | metric | storage | threads | transform ms | whole command s | page faults | SciPy EDT / transform |")
print("|---|---|---|---|---|---|---|---|---|")
keys = []
for r in rows:
    k = (r["binary"], r["input"], r["metric"], r["storage"], r["threads"])
    if k not in keys: keys.append(k)
for k in keys:
    g = [r for r in rows if (r["binary"], r["input"], r["metric"], r["storage"], r["threads"]) == k]
    ms = statistics.median(r["transform_ms"] for r in g)
    wall = statistics.median(r["wall_s"] for r in g)
    faults = statistics.median(r["page_faults"] for r in g)
    ratio = "%.1f×" % (scipy[k[1]] / ms) if k[2] == "euclidean" and k[4] == 1 else ""
    print("| %s | %s | %s | %s | %d | %.0f (%.0f–%.0f) | %.2f | %d | %s |" % (
        k[0].split("/")[-1] if k[0].endswith("release/bin/voxfield") else k[0], k[1], k[2], k[3], k[4], ms,
        min(r["transform_ms"] for r in g), max(r["transform_ms"] for r in g), wall, faults, ratio))
print()
for name, ms in scipy.items():
    print("SciPy distance_transform_edt, %s, one thread: %.0f ms (median of its runs)" % (name, ms))
EOF
rm -rf "$out/inputs" "$out/field.npy" "$out/stats.json" "$out/time.txt"
echo "results in $out"

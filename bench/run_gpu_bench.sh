#!/usr/bin/env bash
# The Vulkan backend's API traffic (submits, fence waits, dispatches, pipeline barriers, bytes each
# way) and its emulated times, for the operations of docs/benchmarks.md "The Vulkan backend". On a
# machine without a GPU this runs on lavapipe: the counters are hardware-independent, the times are
# the CPU emulating a GPU. With a second voxfield binary (e.g. a build of an earlier commit) every
# operation runs on both, alternated, and the outputs are compared byte for byte, so a change to the
# GPU path is measured and checked in one sitting. A markdown table goes to bench/results/gpu-DATE/.
# Usage: bash bench/run_gpu_bench.sh [RUNS] [OTHER_VOXFIELD]   (RUNS default 3; the best time is kept)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
other=${2:-}
source bench/common.sh
bench_prepare
bench_results gpu
B=$PWD/build/release/bin/voxfield
bins=("$B")
[ -n "$other" ] && bins+=("$(realpath "$other")")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$B" generate terrain --size 256 -o "$work/t256.npy" >/dev/null 2>&1
"$B" generate terrain --size 128 -o "$work/t128.npy" >/dev/null 2>&1
ops=(
  "field-euclid|field $work/t256.npy -o OUT.npy --backend vulkan --metric euclidean --max-distance 16 --storage u8 --stats STATS"
  "render|render $work/t256.npy -o OUT.png --width 640 --height 360 --backend vulkan --stats STATS"
  "jfa|field $work/t128.npy -o OUT.npy --algorithm jfa --metric euclidean --storage u8 --max-distance 16 --backend vulkan --stats STATS"
  "fim|field $work/t128.npy -o OUT.npy --algorithm fim --metric manhattan --storage u8 --max-distance 16 --backend vulkan --stats STATS"
  "hybrid|field $work/t128.npy -o OUT.npy --algorithm hybrid --metric manhattan --storage u8 --max-distance 16 --backend vulkan --stats STATS"
  "edits|bench edits --world 256 --chunk 32 --edits 200 --metric manhattan --max-distance 16 --storage u8 --backend vulkan --json STATS"
)
for run in $(seq "$runs"); do
  for op in "${ops[@]}"; do
    name=${op%%|*}
    for i in "${!bins[@]}"; do
      cmd=${op#*|}
      cmd=${cmd//OUT/$work/$name-$i}
      cmd=${cmd//STATS/$out/$name-$i-run$run.json}
      # shellcheck disable=SC2086
      "${bins[$i]}" $cmd >/dev/null 2>&1
    done
    if [ ${#bins[@]} -eq 2 ] && [ "$name" != edits ]; then
      for f in "$work/$name-0".*; do
        cmp -s "$f" "${f/-0./-1.}" || { echo "$name: the two binaries' outputs differ" >&2; exit 1; }
      done
    fi
  done
done
/usr/bin/python3 - "$out" "$runs" "${#bins[@]}" <<'PY' | tee "$out/table.md"
import json, sys
out, runs, nbins = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
names = ["field-euclid", "render", "jfa", "fim", "hybrid", "edits"]
print("| operation | binary | submits | fence waits | dispatches | barriers | bytes up | bytes down | best ms (edits: mean update) |")
print("|---|---|---|---|---|---|---|---|---|")
for n in names:
    for b in range(nbins):
        docs = [json.load(open(f"{out}/{n}-{b}-run{r}.json")) for r in range(1, runs + 1)]
        d = docs[0]
        if n == "edits":
            g = d["gpu"]
            u = g["per_update"]
            per = d["edits"]  # barriers per edit: all of the run's (the first build's few included)
            row = [u["submits"], u["fence_waits"], u["dispatches"], g["pipeline_barriers"] / per,
                   u["bytes_uploaded"], u["bytes_downloaded_outside_verify"]]
            ms = min(x["update_ms"]["mean"] for x in docs)
            cells = [f"{v:.2f}" for v in row]
        else:
            g = d["gpu"]
            cells = [str(g[k]) for k in ("submits", "fence_waits", "dispatches", "pipeline_barriers",
                                          "bytes_uploaded", "bytes_downloaded")]
            ms = min(x["ms"] for x in docs)
        print(f"| {n} | {'this' if b == 0 else 'other'} | " + " | ".join(cells) + f" | {ms:.1f} |")
PY

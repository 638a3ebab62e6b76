#!/usr/bin/env bash
# CSG models sphere-traced on Vulkan (voxfield csg MODEL render --backend vulkan) beside the CPU
# renderer, 640 x 480 at depth 6, per evaluator: each variant's own compiled kernel, the
# interpreter alone, and the interpreter until each variant's kernel is ready (the default).
# Reports the hardware-independent counters (rounds, dispatches, submits, marches by compiled
# kernels and by the interpreter), the pixels more than 8 levels from the CPU's picture, whether
# compiled and interpreted pictures are identical, and times. On lavapipe the GPU times are a
# CPU emulating a GPU: they are not GPU speed. JSON per run and a markdown table into
# bench/results/csg-gpu-DATE/.
# Usage: bash bench/run_csg_gpu_bench.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/common.sh
bench_prepare
bench_results csg-gpu
B=build/release/bin/voxfield
models=(examples/csg/gear.sdf examples/csg/blobs.sdf examples/csg/building.sdf examples/csg/menger.sdf)
for m in "${models[@]}"; do
  n=$(basename "${m%.*}")
  $B csg "$m" render -o "$out/$n-cpu.png" --stats "$out/$n-cpu.json" 2>/dev/null
  for e in compiled interpreter when-ready; do
    $B csg "$m" render --backend vulkan --evaluators "$e" -o "$out/$n-$e.png" --stats "$out/$n-$e.json" 2>/dev/null
  done
done
/usr/bin/python3 - "$out" "${models[@]}" <<'PY' | tee "$out/table.md"
import json, os, sys
import numpy as np
from PIL import Image
out = sys.argv[1]
def px(n, e): return np.asarray(Image.open(os.path.join(out, "%s-%s.png" % (n, e))).convert("RGB")).astype(int)
print("| model | variants | rounds | dispatches | submits | marches compiled / interpreted (when-ready) "
      "| pixels > 8 levels from the CPU's | compiled = interpreted | CPU ms | lavapipe ms: compiled / interpreter / when-ready |")
print("|---|---|---|---|---|---|---|---|---|---|")
for m in sys.argv[2:]:
    n = os.path.basename(os.path.splitext(m)[0])
    j = lambda e: json.load(open(os.path.join(out, "%s-%s.json" % (n, e))))
    cpu, c, i, w = j("cpu"), j("compiled"), j("interpreter"), j("when-ready")
    g = c["gpu"]
    off = int((np.abs(px(n, "compiled") - px(n, "cpu")).max(axis=2) > 8).sum())
    same = bool((px(n, "compiled") == px(n, "interpreter")).all() and (px(n, "compiled") == px(n, "when-ready")).all())
    print("| %s | %d | %d | %d | %d | %d / %d | %d of %d | %s | %.0f | %.0f / %.0f / %.0f |" % (
        n, c["variants"], g["rounds"], g["frame_dispatches"], g["frame_submits"],
        w["gpu"]["compiled_dispatches"], w["gpu"]["interpreted_dispatches"], off, c["width"] * c["height"],
        "yes" if same else "**no**", cpu["octree_ms"] + cpu["render_ms"],
        c["render_ms"], i["render_ms"], w["render_ms"]))
PY
for m in "${models[@]}"; do n=$(basename "${m%.*}"); rm -f "$out/$n-interpreter.png" "$out/$n-when-ready.png"; done

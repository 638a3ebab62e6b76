#!/usr/bin/env bash
# The voxel compiler per model (examples/csg and, when openscad is installed, OpenSCAD's
# example024 imported with --facets): octree figures at depth 7 (cells, variants, nodes per cell
# against the whole tree, octree and GLSL times), voxelisation pruned against the whole tree, and
# CPU rendering pruned against the whole tree (640 x 480), all in one run so ratios compare like
# with like. JSON per step and a markdown table into bench/results/csg-DATE/.
# Usage: bash bench/run_csg_bench.sh [THREADS]   (default: all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
threads=${1:-$(nproc)}
source bench/common.sh
bench_prepare
bench_results csg
B=build/release/bin/voxfield
models=(examples/csg/gear.sdf examples/csg/blobs.sdf examples/csg/building.sdf examples/csg/menger.sdf)
if command -v openscad >/dev/null; then
  scad=$(find /usr/share/openscad/examples -name example024.scad | head -1)
  # openscad resolves a relative -o beside its input: give it an absolute path.
  if [ -n "$scad" ]; then openscad -o "$PWD/$out/example024.csg" "$scad" >/dev/null 2>&1 && models+=("$out/example024.csg"); fi
fi
for m in "${models[@]}"; do
  n=$(basename "${m%.*}")
  $B csg "$m" --facets info --depth 7 --stats "$out/$n-info.json" >/dev/null
  # About 256 voxels along the longest side.
  size=$(/usr/bin/python3 -c "import json,sys; b=json.load(open('$out/$n-info.json'))['bounds']; print(max(h-l for l,h in zip(*b))/256)")
  $B csg "$m" --facets voxelize --voxel-size "$size" --threads "$threads" -o "$out/$n.vfw" --stats "$out/$n-vox.json" 2>/dev/null
  $B csg "$m" --facets voxelize --voxel-size "$size" --threads "$threads" --whole -o "$out/$n-whole.vfw" --stats "$out/$n-vox-whole.json" 2>/dev/null
  cmp -s "$out/$n.vfw" "$out/$n-whole.vfw" || { echo "$n: pruned and whole voxelisations differ" >&2; exit 1; }
  rm "$out/$n-whole.vfw" "$out/$n.vfw"  # checked equal; the figures are in the JSON
  $B csg "$m" --facets render --threads "$threads" -o "$out/$n.png" --stats "$out/$n-render.json" 2>/dev/null
  $B csg "$m" --facets render --threads "$threads" --whole -o "$out/$n-whole.png" --stats "$out/$n-render-whole.json" 2>/dev/null
  $B csg "$m" --facets render --threads "$threads" --view variants -o "$out/$n-variants.png" 2>/dev/null
  rm "$out/$n-whole.png"
  # Each variant's evaluation kernel to SPIR-V in-process (glslang), on worker threads.
  $B csg "$m" --facets compile --depth 7 --spirv -o "$out/$n-compiled" --stats "$out/$n-compile.json" 2>/dev/null
  rm -r "$out/$n-compiled"  # the figures are in the JSON
done
rm -f "$out/example024.csg"  # OpenSCAD's own example, exported for the run
/usr/bin/python3 - "$out" "${models[@]}" <<'PY' | tee "$out/table.md"
import json, os, sys
out = sys.argv[1]
print("| model | nodes | surface cells (depth 7) | variants | nodes per cell: mean / largest / whole | octree ms | GLSL ms "
      "| SPIR-V ms: first / mean / all (wall) | voxels | voxelise Mvox/s pruned / whole | speed-up | render ms pruned / whole "
      "| instructions whole / pruned |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for m in sys.argv[2:]:
    n = os.path.basename(os.path.splitext(m)[0])
    j = lambda s: json.load(open(os.path.join(out, "%s-%s.json" % (n, s))))
    i, v, vw, r, rw = j("info"), j("vox"), j("vox-whole"), j("render"), j("render-whole")
    c, sp = i["compile"], j("compile")["compile"]["spirv"]
    print("| %s | %d | %d | %d | %.2f / %d / %d | %.0f | %.2f | %.0f / %.1f / %.0f | %dx%dx%d | %.0f / %.1f | %.0fx | %.0f / %.0f | %.1fx |" % (
        n, i["nodes"], c["surface"], c["variants"], c["mean_nodes"], c["max_nodes"], c["whole_nodes"], c["octree_ms"],
        c["codegen_ms"], sp["first_ms"], sp["mean_ms"], sp["wall_ms"], *v["dims"], v["mvox_per_s"], vw["mvox_per_s"], vw["ms"] / v["ms"],
        r["octree_ms"] + r["render_ms"], rw["render_ms"], rw["instructions"] / max(r["instructions"], 1)))
PY

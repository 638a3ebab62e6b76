#!/usr/bin/env bash
# Reproduces the meshing figures in docs/benchmarks.md: marching cubes, surface nets and dual
# contouring of voxfield (time, ns per cell, the process's peak memory over its input's, and the
# mesh's bytes per triangle in memory) on the terrain's signed Euclidean field (256³ and 512³), on
# a scan-sized smooth noise volume and on a real MRI scan (the Colin 27 template, when installed),
# beside scikit-image's marching_cubes (one thread) and VTK's vtkFlyingEdges3D (all threads) on the
# same arrays in the same run, then voxfield-bench-mesh's fresh and reused-output library paths
# (library.md). Results go to bench/results/mesh-DATE/table.md and library.md.
# Usage: bash bench/run_mesh_bench.sh [RUNS] [SIZES]   (default 3 runs, sizes "256 512")
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
sizes=${2:-"256 512"}
source bench/common.sh
bench_prepare --peers
bin=build/release/bin
bench_results mesh >/dev/null
mkdir -p "$out/inputs"
inputs=()
for n in $sizes; do
  "$bin/voxfield" generate terrain --size "$n" -o "$out/inputs/terrain-$n.npy" 2>/dev/null
  "$bin/voxfield" field "$out/inputs/terrain-$n.npy" -o "$out/inputs/terrain-sdf-$n.npy" --metric euclidean --signed 2>/dev/null
  inputs+=("$out/inputs/terrain-sdf-$n.npy")
done
# A scan-sized volume: smooth noise (Gaussian-filtered white noise), 384 x 384 x 256 like a CT stack.
/usr/bin/python3 - "$out/inputs/scan.npy" <<'PY'
import sys
import numpy as np
from scipy.ndimage import gaussian_filter
rng = np.random.default_rng(7)
v = gaussian_filter(rng.standard_normal((384, 384, 256)).astype(np.float32), 3)
np.save(sys.argv[1], (v / v.std()).astype(np.float32))
PY
inputs+=("$out/inputs/scan.npy")
# A real scan: the Colin 27 MRI template (Debian mricron-data, installed by
# scripts/install-bench-deps.sh; read with nibabel), 301 x 370 x 316 whole-number intensities 0-130,
# meshed at 89.5 (between the 75th and 90th percentiles: a surface through the brain's tissue,
# 3.8 M triangles) and shifted so that the surface is at level 0 for every mesher. No sample lies
# on it, where scikit-image breaks ties otherwise than voxfield and VTK (at 90: 2.6 % fewer triangles).
mri=/usr/share/mricron/templates/ch2better.nii.gz
if [ -f "$mri" ]; then
  /usr/bin/python3 - "$mri" "$out/inputs/mri-colin27.npy" <<'PY'
import sys
import nibabel as nib
import numpy as np
v = nib.load(sys.argv[1]).get_fdata(dtype=np.float32)
np.save(sys.argv[2], np.ascontiguousarray(v - np.float32(89.5), dtype=np.float32))
PY
  inputs+=("$out/inputs/mri-colin27.npy")
fi
cat "$out/machine.txt"
{
  echo "| volume | library | threads | best ms of $runs | triangles | Mcells/s | ns per cell per thread | peak memory over the input | mesh bytes per triangle |"
  echo "|---|---|---|---|---|---|---|---|---|"
} > "$out/table.md"
for f in "${inputs[@]}"; do
  name=$(basename "$f" .npy)
  cells=$(/usr/bin/python3 -c "import numpy as np,sys; s=np.load(sys.argv[1], mmap_mode='r').shape; print((s[0]-1)*(s[1]-1)*(s[2]-1))" "$f")
  input_mb=$(/usr/bin/python3 -c "import os,sys; print(os.path.getsize(sys.argv[1]) / 1e6)" "$f")
  for algo in mc sn dc; do
    for threads in 1 2; do
      best=""
      peak_kb=0
      for r in $(seq "$runs"); do
        # The peak resident memory of the whole command (GNU time's %M, kB): the input, the
        # meshing, the mesh and the file's encoding.
        /usr/bin/time -f %M -o "$out/rss.txt" "$bin/voxfield" mesh "$f" -o "$out/m.stl" --algorithm "$algo" --threads "$threads" --stats "$out/s.json" 2>/dev/null
        peak_kb=$(cat "$out/rss.txt")
        ms=$(/usr/bin/python3 -c "import json; print(json.load(open('$out/s.json'))['ms'])")
        best=$(/usr/bin/python3 -c "print(min(float(x) for x in '$best $ms'.split()))")
      done
      /usr/bin/python3 - "$out/s.json" "$name" "$algo" "$threads" "$best" "$cells" "$peak_kb" "$input_mb" >> "$out/table.md" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
name, algo, threads, best, cells, peak_kb, input_mb = sys.argv[2:9]
threads, best, cells, peak_kb, input_mb = int(threads), float(best), int(cells), int(peak_kb), float(input_mb)
tris, verts = s["triangles"], s["vertices"]
# In memory: positions and normals (3 floats each) and an RGB colour per vertex, 3 indices per triangle.
mesh_bytes = verts * (12 + 12 + 3) + tris * 12
print(f"| {name} | voxfield {algo} | {threads} | {best:.0f} | {tris} | {cells / (best * 1e3):.0f} | "
      f"{best * 1e6 * threads / cells:.1f} | {peak_kb / 1e3 - input_mb:.0f} MB | {mesh_bytes / max(tris, 1):.1f} |")
PY
    done
  done
  # The library's own paths in one process: a fresh Mesh per call (mesh_volume, what the CLI
  # times above) and arrays reused across calls (mesh_volume_into, a game re-meshing per frame).
  for threads in 1 2; do
    "$bin/voxfield-bench-mesh" "$f" --runs "$runs" --threads "$threads" --algorithms mc,sn >> "$out/library.md"
  done
  /usr/bin/python3 bench/peers/mesh_peers.py "$f" 0 --runs "$runs" --json "$out/peers.json"
  /usr/bin/python3 - "$out/peers.json" "$name" "$cells" >> "$out/table.md" <<'PY'
import json, sys
d, name, cells = json.load(open(sys.argv[1])), sys.argv[2], int(sys.argv[3])
for peer in ["scikit-image", "vtk-flying-edges"]:
    p = d.get(peer)
    if p:
        print(f"| {name} | {peer} {p['version']} | {p['threads']} | {p['ms']:.0f} | {p['triangles']} | {cells / (p['ms'] * 1e3):.0f} |")
PY
done
rm -rf "$out/inputs" "$out/m.stl" "$out/s.json" "$out/peers.json" "$out/rss.txt"
cat "$out/table.md"
# One header for the library table (each run of voxfield-bench-mesh printed its own).
awk 'NR <= 2 || !/^\|( volume |---)/' "$out/library.md" > "$out/library.tmp" && mv "$out/library.tmp" "$out/library.md"
cat "$out/library.md"
echo "results in $out"

#!/usr/bin/env bash
# The showcase's MPI section (called by scripts/showcase.sh after `voxfield showcase`): the
# showcase's 256^3 terrain, its exact signed Euclidean field computed by one process and by
# voxfield-mpi on 1, 2 and 4 ranks, each rank reading only its slab of the .npy; the files must be
# identical, byte for byte (and on 2 ranks each on a Vulkan device of its own: identical, or within
# the device's f32 square roots); then that field
# meshed by one process and over 2 and 4 ranks: the same
# file; the terrain world's own surface over 2 ranks: voxfield mesh's file; then a frame of the terrain drawn over 2 and 4 ranks: voxfield render's PNG. Appends
# a section with the times and the bytes exchanged to the report.
# Usage: showcase_mpi.sh OUT_DIR   (skipped, saying so, when voxfield-mpi was not built)
set -euo pipefail
cd "$(dirname "$0")/.."
out=$1
B=build/release/bin
report="$out/report.md"
if [ ! -x "$B/voxfield-mpi" ] || ! command -v mpirun >/dev/null; then
  printf '\n## Beyond one machine (MPI)\n\nSkipped: voxfield-mpi was not built (Open MPI missing).\n' >> "$report"
  exit 0
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
opts=(--metric euclidean --signed --chunk 32)
"$B/voxfield" field "$out/terrain.npy" -o "$out/mpi-one-process.npy" "${opts[@]}" \
  --stats "$out/mpi-one-process.json" 2>/dev/null
rows=""
for n in 1 2 4; do
  mpirun --oversubscribe -np "$n" "$B/voxfield-mpi" field "$out/terrain.npy" -o "$out/mpi-$n.npy" \
    "${opts[@]}" --stats "$out/mpi-$n.json" 2>/dev/null
  same=no
  cmp -s "$out/mpi-one-process.npy" "$out/mpi-$n.npy" && same=yes
  rows+=$(/usr/bin/python3 - "$out/mpi-$n.json" "$same" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
x = j["exchange"]
print("| %d | %s | %.0f | %.0f | %.1f | %d | %s |" % (j["ranks"], " ".join(str(z) for z in j["slabs"]),
      j["ms"], x["compute_ms_max"], x["exchange_ms_max"], x["bytes_sent_total"], sys.argv[2]))
PY
)$'\n'
  rm -f "$out/mpi-$n.npy"
done
one_ms=$(/usr/bin/python3 -c "import json; print('%.0f' % json.load(open('$out/mpi-one-process.json'))['ms'])")
# The same field with each of 2 ranks computing its slab on a Vulkan device of its own (lavapipe
# here: its times are CPU emulation, its counters carry over), the z passes starting from the
# neighbours the ranks exchange: the same file. Without a device the ranks say so and use the CPU.
mpirun --oversubscribe -np 2 "$B/voxfield-mpi" field "$out/terrain.npy" -o "$out/mpi-gpu-2.npy" \
  "${opts[@]}" --backend vulkan --stats "$out/mpi-gpu-2.json" 2>/dev/null
# f32 Euclidean values: the device's square roots may differ from the CPU's by a few ulps
# (gpu::kF32Tolerance, 4e-7 of the distance); lavapipe's have matched bit for bit.
gpu_same=$(/usr/bin/python3 - "$out/mpi-one-process.npy" "$out/mpi-gpu-2.npy" <<'PY'
import sys, numpy as np
a, b = np.load(sys.argv[1]), np.load(sys.argv[2])
if a.shape != b.shape:
    print("no")
elif np.array_equal(a, b):
    print("yes")
else:
    ok = np.all(np.abs(a - b) <= 4e-7 * np.abs(a))
    print("yes (within the GPU's square roots, 4e-7)" if ok else "no")
PY
)
gpu_row=$(/usr/bin/python3 - "$out/mpi-gpu-2.json" "$gpu_same" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
g = j["gpu"]
if g is None:
    print("| 2 | cpu (no usable Vulkan device) | — | — | — | %s |" % sys.argv[2])
else:
    print("| 2 | %s (%s) | %d | %d | %d | %s |" % (g["device_rank0"], g["timings_are"], g["submits_total"],
          g["dispatches_total"], g["bytes_uploaded_total"], sys.argv[2]))
PY
)
rm -f "$out/mpi-gpu-2.npy"
# The showcase's OpenVDB level set of the terrain read by 2 ranks, each decoding only its slab's
# leaves: the same field as one process reading the whole file.
# (A failure is reported as "no" in the table, and fails the section below, not the script here.)
vdb_same=no
if "$B/voxfield" field "$out/terrain-sdf.vdb" -o "$out/mpi-vdb-one.npy" "${opts[@]}" 2>/dev/null &&
  mpirun --oversubscribe -np 2 "$B/voxfield-mpi" field "$out/terrain-sdf.vdb" -o "$out/mpi-vdb-2.npy" \
    "${opts[@]}" --stats "$out/mpi-vdb-2.json" 2>/dev/null &&
  cmp -s "$out/mpi-vdb-one.npy" "$out/mpi-vdb-2.npy" &&
  /usr/bin/python3 -c "import json, sys; sys.exit(not json.load(open('$out/mpi-vdb-2.json'))['read_in_parts'])"; then
  vdb_same=yes
fi
rm -f "$out/mpi-vdb-one.npy" "$out/mpi-vdb-2.npy"
# The same field meshed (marching cubes at iso 0) by one process and over 2 and 4 ranks, each rank
# reading only its chunk layers' planes of the .npy: the same file, byte for byte.
"$B/voxfield" mesh "$out/mpi-one-process.npy" -o "$out/mpi-mesh-one.ply" --stats "$out/mpi-mesh-one.json" 2>/dev/null
mesh_rows=""
for n in 2 4; do
  mpirun --oversubscribe -np "$n" "$B/voxfield-mpi" mesh "$out/mpi-one-process.npy" -o "$out/mpi-mesh-$n.ply" \
    --stats "$out/mpi-mesh-$n.json" 2>/dev/null
  same=no
  cmp -s "$out/mpi-mesh-one.ply" "$out/mpi-mesh-$n.ply" && same=yes
  mesh_rows+=$(/usr/bin/python3 - "$out/mpi-mesh-$n.json" "$same" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print("| %d | %s | %d | %.0f | %d | %s |" % (j["ranks"], " ".join(str(k) for k in j["chunk_layers"]),
      j["triangles"], j["ms"], j["exchange"]["bytes_received_total"], sys.argv[2]))
PY
)$'\n'
done
rm -f "$out/mpi-mesh-2.ply" "$out/mpi-mesh-4.ply"
mesh_one=$(/usr/bin/python3 -c "import json; j = json.load(open('$out/mpi-mesh-one.json')); print('%d triangles in %.0f ms' % (j['triangles'], j['ms']))")
rm -f "$out/mpi-one-process.npy" "$out/mpi-mesh-one.ply"
# The terrain world's own surface (a world meshed as `voxfield mesh` meshes it: its voxels' faces
# through the exact signed field, coloured by material) over 2 ranks, each reading only the slices
# its chunk layers need: the same file, byte for byte.
"$B/voxfield" mesh "$out/terrain.npy" -o "$out/mpi-world-one.ply" --stats "$out/mpi-world-one.json" \
  2>/dev/null
mpirun --oversubscribe -np 2 "$B/voxfield-mpi" mesh "$out/terrain.npy" -o "$out/mpi-world-2.ply" \
  --stats "$out/mpi-world-2.json" 2>/dev/null
world_same=no
cmp -s "$out/mpi-world-one.ply" "$out/mpi-world-2.ply" && world_same=yes
world_row=$(/usr/bin/python3 - "$out/mpi-world-one.json" "$out/mpi-world-2.json" "$world_same" <<'PY'
import json, sys
one, j = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
print("| terrain.npy | %d | %s | %d | %.0f (one process: %.0f) | %d | %s |" % (j["ranks"],
      " ".join(str(k) for k in j["chunk_layers"]), j["triangles"], j["ms"], one["ms"],
      j["ghost_slices"], sys.argv[3]))
PY
)
rm -f "$out/mpi-world-one.ply" "$out/mpi-world-2.ply"
# A frame of the terrain drawn where it lies (`voxfield-mpi render`): the rays, and the soft
# shadows' rays, handed from slab to slab; the PNG must be voxfield render's, byte for byte.
frame_opts=(--width 640 --height 360 --chunk 32)
"$B/voxfield" render "$out/terrain.npy" -o "$out/mpi-frame.png" "${frame_opts[@]}" >/dev/null 2>&1
frame_rows=""
for n in 2 4; do
  mpirun --oversubscribe -np "$n" "$B/voxfield-mpi" render "$out/terrain.npy" -o "$out/mpi-frame-$n.png" \
    "${frame_opts[@]}" --stats "$out/mpi-frame-$n.json" 2>/dev/null
  same=no
  cmp -s "$out/mpi-frame.png" "$out/mpi-frame-$n.png" && same=yes
  frame_rows+=$(/usr/bin/python3 - "$out/mpi-frame-$n.json" "$same" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print("| %d | %s | %.0f | %d | %d | %d | %s |" % (j["ranks"], " ".join(str(z) for z in j["slabs"]), j["ms"],
      j["primary"]["rays"], j["shadow"]["rays"], j["exchange"]["bytes_sent_total"], sys.argv[2]))
PY
)$'\n'
  [ "$n" -eq 4 ] || rm -f "$out/mpi-frame-$n.png"  # the 4 ranks' frame is pictured
done
rm -f "$out/mpi-frame.png"
{
  printf '\n## Beyond one machine (MPI)\n\n'
  printf 'The terrain'"'"'s exact signed Euclidean field by `voxfield-mpi` (docs/mpi.md): each rank reads only its\n'
  printf 'slab of `terrain.npy` and computes it; the ranks exchange 16 bytes per column and rank boundary (two\n'
  printf 'scans), never a halo of slices; rank 0 renames the file once every rank has written its slices.\n'
  printf 'One process (`voxfield field`, 2 threads): %s ms. This machine has 2 cores, so 4 ranks share them.\n\n' "$one_ms"
  printf '| ranks | slabs (z cuts) | ms | compute ms (slowest rank) | exchange ms | bytes sent | file identical to one process |\n'
  printf '|---|---|---|---|---|---|---|\n'
  printf '%s' "$rows"
  printf '\nThe same field with each rank computing its slab on a Vulkan device of its own (`--backend\n'
  printf 'vulkan`; the counters summed over the ranks):\n\n'
  printf '| ranks | device | submits | dispatches | bytes up | file equal to one process'"'"'s |\n|---|---|---|---|---|---|\n'
  printf '%s\n' "$gpu_row"
  printf '\nThe same field from `terrain-sdf.vdb` (the OpenVDB level set above), each rank decoding only the\n'
  printf 'leaves of its slab (the others'"'"' values stepped over, never decompressed):\n\n'
  printf '| input | ranks | field identical to one process reading the whole file |\n|---|---|---|\n'
  printf '| terrain-sdf.vdb | 2 | %s |\n' "$vdb_same"
  printf '\nThe field meshed by marching cubes over the ranks (`voxfield-mpi mesh`): the chunk layers dealt to\n'
  printf 'the ranks, each reading only the planes its layers read from the .npy and meshing them as one slab of\n'
  printf 'the passes `voxfield mesh` runs over a whole volume, numbered by one scan of the vertex counts, and\n'
  printf 'writing its share into the one .ply: nothing is gathered. One process (`voxfield mesh`): %s.\n\n' "$mesh_one"
  printf '| ranks | chunk layers (cuts) | triangles | ms (made and written) | bytes received (weights, census) | the same file as one process |\n'
  printf '|---|---|---|---|---|---|\n'
  printf '%s' "$mesh_rows"
  printf '\nThe terrain world'"'"'s own surface over the ranks (`voxfield-mpi mesh terrain.npy`, a world): the\n'
  printf 'voxels'"'"' faces through the exact signed field, coloured by material; after a first reading bounds\n'
  printf 'the content, each rank reads only its layers'"'"' slices and the field'"'"'s clamp beyond them (ghost slices).\n\n'
  printf '| world | ranks | chunk layers (cuts) | triangles | ms (made and written) | ghost slices | the same file as `voxfield mesh` |\n'
  printf '|---|---|---|---|---|---|---|\n'
  printf '%s\n' "$world_row"
  printf '\nA frame of the terrain over the ranks (`voxfield-mpi render`): each rank walks the rays that cross\n'
  printf 'its slab and hands each on, with the DDA'"'"'s exact state, to the rank it enters, soft-shadow rays\n'
  printf 'included; each pixel is shaded by the rank where it hit. The PNG must equal `voxfield render`'"'"'s.\n\n'
  printf '![The terrain, drawn over 4 ranks](mpi-frame-4.png)\n\n'
  printf '| ranks | slabs (z cuts) | ms (fields, scene, frame) | walks, primary | walks, shadow | bytes sent | PNG identical to one process |\n'
  printf '|---|---|---|---|---|---|---|\n'
  printf '%s' "$frame_rows"
} >> "$report"
if grep -q '| no |$' "$report"; then
  echo "voxfield: an MPI field, mesh or frame differs from one process's (see $report)" >&2
  exit 1
fi
echo "voxfield: MPI section added to $report"

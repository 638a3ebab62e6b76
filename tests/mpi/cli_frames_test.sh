#!/usr/bin/env bash
# voxfield-mpi render and mesh against voxfield render and mesh: the same input and options must
# give byte-identical PNGs and mesh files on 1 to 4 ranks, and bad options must fail on every rank
# with one clear message and no output.
# Usage: cli_frames_test.sh VOXFIELD VOXFIELD_MPI MPIEXEC
# shellcheck source=SCRIPTDIR/cli_common.sh
source "$(dirname "$0")/cli_common.sh"
# An unbounded .vfw whose content lies away from every face of the array it came from.
/usr/bin/python3 - <<'PY'
import numpy as np
a = np.zeros((30, 26, 61), np.uint8)
a[5:19, 7:20, 11:52] = np.random.default_rng(5).integers(0, 3, (14, 13, 41))
np.save("margins.npy", a)
PY
"$VF" convert margins.npy margins.vfw 2>/dev/null
if [ ! -f "$vox" ]; then echo "FAIL: $vox is missing (../shared beside the repository)"; fail=1; fi

# Frames: voxfield-mpi render draws voxfield render's PNG byte for byte on 2-4 ranks (rays and
# soft-shadow rays handed from slab to slab; one rank and many more cases are test_mpi_render's),
# on a real .vox in chunks of 8 and on a .npy world read
# a slab per rank, from the automatic camera, from the top with fog, and in the chunks view.
if [ -f "$vox" ]; then
  trex=$(dirname "$vox")/ephtracy_T-Rex.vox
  "$VF" render "$trex" -o ref.png --width 160 --height 100 --chunk 8 2>/dev/null
  for n in $(rank_counts 2 4); do
    MPIEXEC -np "$n" "$VFM" render "$trex" -o out.png --width 160 --height 100 --chunk 8 \
      --stats stats.json 2>/dev/null
    same ref.png out.png "render, $n ranks, ephtracy_T-Rex.vox"
  done
  /usr/bin/python3 - <<'PY'
import json
s = json.load(open("stats.json"))
assert s["ranks"] == 4 and s["slabs"][0] == 0 and len(s["slabs"]) == 5, s
assert s["primary"]["rays"] > 0 and s["shadow"]["rays"] > 0, s
# Where each rank's frame went: five phases per rank, each rank's phases within the frame's time
# (the slowest rank's, from a common start), their waits within them, a relay round at least.
p = s["phases"]
names = ["skip", "scene", "first_hits", "shadows", "shade"]
for r in range(4):
    total = sum(p[n]["ms"][r] for n in names)
    assert 0 < total <= s["ms"] * 1.001 + 0.5, (r, total, s["ms"])
    for n in names:
        assert 0 <= p[n]["wait_ms"][r] <= p[n]["ms"][r] + 1e-6, (r, n, p[n])
assert p["relay_rounds"] >= 1, p
PY
fi
for view in "--camera top --fog 0.02" "--view chunks --metric euclidean --skip chunks" \
  "--view distance" "--view distance --slice 24 --camera top --metric chebyshev"; do
  # shellcheck disable=SC2086
  "$VF" render f.npy -o ref.png --width 120 --height 90 --chunk 8 $view 2>/dev/null
  # shellcheck disable=SC2086
  MPIEXEC -np 3 "$VFM" render f.npy -o out.png --width 120 --height 90 --chunk 8 $view 2>/dev/null
  same ref.png out.png "render, 3 ranks, f.npy, $view"
done
# An unbounded .vfw read a slab per rank, its domain (the content's bounds) starting off a chunk.
"$VF" render margins.vfw -o ref.png --width 100 --height 80 --chunk 8 2>/dev/null
MPIEXEC -np 3 "$VFM" render margins.vfw -o out.png --width 100 --height 80 --chunk 8 2>/dev/null
same ref.png out.png "render, 3 ranks, margins.vfw"
# --repeat: the same frame drawn three times, the median of the three times reported, the
# counters one frame's (those of a single frame, not three summed).
MPIEXEC -np 2 "$VFM" render margins.vfw -o out.png --width 100 --height 80 --chunk 8 \
  --stats once.json 2>/dev/null
MPIEXEC -np 2 "$VFM" render margins.vfw -o out.png --width 100 --height 80 --chunk 8 \
  --repeat 3 --stats repeat.json 2>/dev/null
same ref.png out.png "render --repeat 3, 2 ranks, margins.vfw"
/usr/bin/python3 - <<'PY'
import json
once, s = json.load(open("once.json")), json.load(open("repeat.json"))
e = s["ms_each"]
assert len(e) == 3 and s["ms"] == sorted(e)[1] and len(once["ms_each"]) == 1, s
assert s["primary"] == once["primary"] and s["shadow"] == once["shadow"], (s, once)
assert s["exchange"]["bytes_sent_total"] == once["exchange"]["bytes_sent_total"], (s, once)
PY
# A camera in the world's frame: voxel v of framed.vfw lies at (100, -50, 3) + v / 4.
"$VF" convert f.npy framed.vfw --voxel-size 0.25 --origin 100,-50,3 2>/dev/null
"$VF" render framed.vfw -o ref.png --width 100 --height 80 --chunk 8 --camera "eye=60,-20,40:target=12,12,8" 2>/dev/null
MPIEXEC -np 2 "$VFM" render framed.vfw -o out.png --width 100 --height 80 --chunk 8 \
  --camera "eye=115,-55,13:target=103,-47,5" --camera-frame world 2>/dev/null
same ref.png out.png "render, 2 ranks, a camera in the world's frame"
# ...and in a frame of voxels that are not cubes (its rays stretched into voxels), as one process.
rm -f ref.png out.png
"$VF" convert f.npy stretched.vfw --voxel-size 0.25,0.25,1 --origin 100,-50,3 2>/dev/null
"$VF" render stretched.vfw -o ref.png --width 100 --height 80 --chunk 8 \
  --camera "eye=115,-55,40:target=103,-47,12" --camera-frame world 2>/dev/null
MPIEXEC -np 2 "$VFM" render stretched.vfw -o out.png --width 100 --height 80 --chunk 8 \
  --camera "eye=115,-55,40:target=103,-47,12" --camera-frame world 2>/dev/null
same ref.png out.png "render, 2 ranks, a camera in a frame of non-cubic voxels"
rm -f bad.png
expect_failure 2 "error not in" render f.npy -o bad.png --view error
expect_failure 1 "slice z=53 lies outside" render f.npy -o bad.png --view distance --slice 53
expect_failure 1 "cut on chunk boundaries" render f.npy -o bad.png --chunk 64
if [ -e bad.png ]; then echo "FAIL: a failed render wrote bad.png"; fail=1; fi

# Meshes: a float volume meshed over 1..4 ranks (each reading only its chunk layers' planes) gives
# voxfield mesh's file byte for byte, for every mesher, in every format: every rank meshes a slab
# of voxfield mesh's own whole-volume passes. (Its triangles are also compared as sets of corner
# positions, which names the failure better than cmp.)
/usr/bin/python3 - <<'PY'
import numpy as np
z, y, x = np.meshgrid(np.arange(45), np.arange(31), np.arange(26), indexing="ij")
v = np.sin(0.31 * x + 0.2 * y) + np.cos(0.23 * z - 0.11 * x) + 0.4 * np.sin(0.5 * y * 0.7 + z * 0.13)
np.save("wave.npy", np.ascontiguousarray(v.transpose(2, 1, 0)).astype(np.float32))  # a[x, y, z]
np.save("wave64.npy", np.asfortranarray(v.transpose(2, 1, 0)))
PY
same_triangles() {  # same_triangles REF.ply OUT.ply WHAT
  /usr/bin/python3 "$(dirname "$0")/../../scripts/same_triangles.py" "$1" "$2" >/dev/null ||
    { echo "FAIL: $3: the triangles differ from voxfield mesh's"; fail=1; }
}
for alg in mc sn dc; do
  "$VF" mesh wave.npy -o ref.ply --algorithm "$alg" --iso 0.2 --spacing 0.5,1,1.5 2>/dev/null
  # Every rank count for marching cubes; one each for the dual meshers (each mpirun costs a second).
  ranks="1 2 3 4"
  [ "$alg" = sn ] && ranks=3
  [ "$alg" = dc ] && ranks=2
  for n in $(rank_counts $ranks); do
    MPIEXEC -np "$n" "$VFM" mesh wave.npy -o out.ply --algorithm "$alg" --iso 0.2 --spacing 0.5,1,1.5 \
      --chunk 8 --stats mesh.json 2>/dev/null
    same_triangles ref.ply out.ply "$alg, $n ranks"
    same ref.ply out.ply "$alg, $n ranks"
  done
done
"$VF" mesh wave64.npy -o ref.ply --inside above 2>/dev/null
MPIEXEC -np 3 "$VFM" mesh wave64.npy -o out.ply --inside above --chunk 5 2>/dev/null
same ref.ply out.ply "float64, inside above, 3 ranks"
# Dealt by count (no first pass): the ranks exchange their seams' vertex numbers and edges, and
# every rank writes its share of the file. The census over the ranks is voxfield mesh's.
"$VF" mesh wave.npy -o ref.ply --stats ref.json 2>/dev/null
MPIEXEC -np 2 "$VFM" mesh wave.npy -o out.ply --chunk 8 --balance count --stats mesh.json 2>/dev/null
same ref.ply out.ply "by count, 2 ranks"
/usr/bin/python3 -c "
import json; s = json.load(open('mesh.json')); r = json.load(open('ref.json'))
assert s['ranks'] == 2 and s['balance'] == 'count' and s['chunk_layers'] == [0, 3, 6], s
assert s['exchange']['bytes_received_total'] > 1000, s
for k in ('triangles', 'vertices', 'watertight', 'boundary_edges', 'euler_characteristic'):
    assert s[k] == r[k], (k, s[k], r[k])"
# The other formats, byte for byte voxfield mesh's (marching cubes on 2 ranks, surface nets on 3).
for fmt in obj stl glb; do
  "$VF" mesh wave.npy -o "ref.$fmt" 2>/dev/null
  MPIEXEC -np 2 "$VFM" mesh wave.npy -o "out.$fmt" --chunk 16 2>/dev/null
  same "ref.$fmt" "out.$fmt" "mc .$fmt, 2 ranks"
done
"$VF" mesh wave.npy -o ref.glb --algorithm sn 2>/dev/null
MPIEXEC -np 3 "$VFM" mesh wave.npy -o three.glb --chunk 8 --algorithm sn 2>/dev/null
same ref.glb three.glb "sn .glb, 3 ranks"

# Worlds: their surface (mesh_world at iso 0, through the exact signed field, coloured by
# material) is voxfield mesh's file byte for byte — a .npy world read a slab per rank, an unbounded
# .vfw whose content lies away from its faces, a framed and rotated .vfw (positions and normals in
# the world's frame), a real .vox with its palette, a .vdb — on 1 to 4 ranks in layers of 8, for
# every mesher, in every format; ranks without layers; another metric (its normals differ).
"$VF" convert f.npy turned.vfw --voxel-size 0.25,0.5,1 --origin 100,-50,3 --rotate 90,0,0,1 2>/dev/null
"$VF" convert f.npy f.vdb 2>/dev/null
worlds="f.npy margins.vfw turned.vfw f.vdb"
[ -f "$vox" ] && worlds="$worlds $(dirname "$vox")/ephtracy_chr_knight.vox"
# Under the sanitizers (each mpirun takes seconds there) two of the worlds: the .npy read a slab per
# rank and the framed .vfw, in the two readings this command makes; the .vdb's, .vox's and
# unbounded .vfw's slab readings run there under mpi_cli's field, and every mesher's world slabs
# under the library tests (MpiMeshFile, MeshWorldSlab).
[ "${VOXFIELD_MPI_RANK_SAMPLE:-0}" = 1 ] && worlds="f.npy turned.vfw"
for world in $worlds; do
  for alg in mc sn dc; do
    "$VF" mesh "$world" -o ref.ply --algorithm "$alg" 2>/dev/null
    ranks="2"
    [ "$alg" = mc ] && ranks="1 2 3 4"
    for n in $(rank_counts $ranks); do
      MPIEXEC -np "$n" "$VFM" mesh "$world" -o out.ply --algorithm "$alg" --chunk 8 \
        --stats world.json 2>/dev/null
      same ref.ply out.ply "mesh $(basename "$world"), $alg, $n ranks"
    done
  done
done
/usr/bin/python3 -c "
import json; s = json.load(open('world.json'))
assert s['read_in_parts'] is True and s['read'] == 'every' and s['ghost_slices'] >= 6, s
assert s['vertices'] > 500, s"
# Two layers of 32 for 4 ranks: two ranks mesh nothing (and still read and write their part).
"$VF" mesh f.npy -o ref.ply --metric manhattan 2>/dev/null
MPIEXEC -np 4 "$VFM" mesh f.npy -o out.ply --chunk 32 --balance count --metric manhattan \
  --stats world.json 2>/dev/null
same ref.ply out.ply "mesh f.npy, manhattan, 4 ranks of which two without layers"
/usr/bin/python3 -c "
import json; c = json.load(open('world.json'))['chunk_layers']
assert len(c) == 5 and sum(c[r] == c[r + 1] for r in range(4)) == 2, c"
world_formats="obj stl glb"
[ "${VOXFIELD_MPI_RANK_SAMPLE:-0}" = 1 ] && world_formats="glb"
for fmt in $world_formats; do
  "$VF" mesh f.npy -o "ref.$fmt" 2>/dev/null
  MPIEXEC -np 3 "$VFM" mesh f.npy -o "out.$fmt" --chunk 8 --balance count --read rank0 2>/dev/null
  same "ref.$fmt" "out.$fmt" "mesh f.npy .$fmt, 3 ranks, --read rank0"
done
# A world with no solid voxel: no surface, the empty file voxfield mesh writes.
/usr/bin/python3 -c "import numpy as np; np.save('air.npy', np.zeros((9, 8, 12), np.uint8))"
"$VF" mesh air.npy -o ref.glb 2>/dev/null
MPIEXEC -np 2 "$VFM" mesh air.npy -o out.glb 2>/dev/null
same ref.glb out.glb "mesh of a world of air, 2 ranks"
expect_failure 1 "meshes a world's surface at iso 0" mesh f.npy -o bad.ply --iso 2
expect_failure 1 "--inside and --spacing are for float volumes" mesh f.npy -o bad.ply --spacing 1,1,2
expect_failure 1 "--metric is for worlds" mesh wave.npy -o bad.ply --metric chebyshev
expect_failure 1 "--read and --grid are for worlds" mesh wave.npy -o bad.ply --read rank0
expect_failure 1 "unknown mesh format" mesh wave.npy -o bad.xyz
/usr/bin/python3 -c "import numpy as np; a = np.zeros((6, 6, 20), np.float32); a[2, 3, 17] = np.nan; np.save('nan.npy', a)"
expect_failure 1 "sample (2, 3, 17) is NaN" mesh nan.npy -o bad.ply --chunk 4

if [ "$fail" -ne 0 ]; then exit 1; fi
echo "voxfield-mpi: every frame and mesh equals voxfield's; bad options refused"

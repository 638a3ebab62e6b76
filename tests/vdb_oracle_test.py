"""voxfield's .vdb files read by OpenVDB's own Python module (pyopenvdb, Debian python3-openvdb).

A real MagicaVoxel file's distance fields are written by the CLI as .vdb and as .npy in the same
run; pyopenvdb must see a level set (signed) or a scalar grid (unsigned) with the documented
background, voxel size and metadata, holding at every voxel of the domain the .npy's distance
(for a level set, less half a voxel: the distance to the surface midway between voxel centres).
voxfield reads .vdb back with its own parser: the world file as the world it came from, and a
level set pyopenvdb writes as its inside; --grid NAME reads the named grid of a file of several
(convert, info, mesh and field against the chosen grid's world) and is refused for a missing name
and for inputs that are not .vdb; a truncated file is refused naming the file, and a failed
command writes nothing.

Usage: vdb_oracle_test.py VOXFIELD_BINARY VOX_FILE WORK_DIR
"""

import json
import os
import subprocess
import sys

import numpy as np
import pyopenvdb as vdb

failures = 0


def check(cond, what):
    global failures
    if not cond:
        failures += 1
        print(f"FAIL: {what}", file=sys.stderr)


def run(*args, ok=True):
    p = subprocess.run([CLI, *args], capture_output=True, text=True)
    if ok and p.returncode != 0:
        print(p.stderr, file=sys.stderr)
        raise SystemExit(f"voxfield {' '.join(args)} failed")
    return p


CLI, VOX, WORK = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(WORK, exist_ok=True)

cases = [
    ("euclidean", True, 4.0, "f32", None),
    ("euclidean", True, 0.0, "u16", "0.5,0.5,2"),
    ("euclidean", False, 6.0, "f32", "2,1,1"),
    ("manhattan", False, 0.0, "u8", None),
    ("chebyshev", True, 3.0, "f32", None),
]
for metric, signed, clamp, storage, spacing in cases:
    name = f"{metric}-{'s' if signed else 'u'}-{clamp}-{storage}"
    args = ["field", VOX, "--metric", metric, "--max-distance", str(clamp), "--storage", storage]
    if signed:
        args.append("--signed")
    if spacing:
        args += ["--spacing", spacing]
    vdb_path, npy_path = os.path.join(WORK, name + ".vdb"), os.path.join(WORK, name + ".npy")
    run(*args, "-o", vdb_path)
    run(*args, "-o", npy_path)
    grids = vdb.readAllGridMetadata(vdb_path)
    check(len(grids) == 1 and grids[0].name == "distance", f"{name}: one grid named distance")
    g = vdb.read(vdb_path, "distance")
    size = [float(s) for s in spacing.split(",")] if spacing else [1.0, 1.0, 1.0]
    half = 0.5 * min(size) if signed else 0.0
    check(g.gridClass == (vdb.GridClass.LEVEL_SET if signed else vdb.GridClass.UNKNOWN),
          f"{name}: class {g.gridClass}")
    check(np.allclose(g.transform.voxelSize(), size), f"{name}: voxel size {g.transform.voxelSize()}")
    meta = g.metadata
    check(meta["voxfield_metric"] == metric and meta["voxfield_storage"] == storage,
          f"{name}: metadata {meta}")
    check(meta["voxfield_kind"] == ("signed distance" if signed else "unsigned distance"),
          f"{name}: kind")
    d = np.load(npy_path).astype(np.float64)
    if storage != "f32":
        # integer storage holds bias + floor(d * scale) (voxfield/distance.h): decoded here.
        bits = 8 if storage == "u8" else 16
        scale = 1 if metric != "euclidean" else (4 if storage == "u8" else 16)
        d = (d - (2 ** (bits - 1) if signed else 0)) / scale
    lo = tuple(meta["voxfield_domain_min"])
    got = np.zeros(d.shape, dtype=np.float32)
    g.copyToArray(got, ijk=lo)
    level = np.where(d > 0, d - half, np.where(d < 0, d + half, d))
    bg = g.background
    want = np.clip(level, -bg, bg).astype(np.float32)
    check(np.array_equal(got, want), f"{name}: values differ at {np.argwhere(got != want)[:3]}")
    if clamp > 0:
        check(bg == np.float32(clamp - half), f"{name}: background {bg}, clamp {clamp}")
    else:
        check(bg >= np.abs(level).max() - 1e-6, f"{name}: background {bg} below the largest value")
    check(g.activeVoxelCount() == int((np.abs(level) < bg).sum()), f"{name}: active voxels")

# A vector field: grids "vectors" (direction x strength) and "strength", against the .npy of the
# same command (float32 a[i, j, k, 4]), with the transform mapping index (i, j, k) to the volume's
# voxel centre: centre + R ((i, j, k) + 1/2) * size / resolution - size / 2), R from the
# --rotation by Rodrigues' formula. rgba32f, so the .npy holds the texels exactly.
agents = os.path.join(WORK, "agents.json")
with open(agents, "w") as f:
    f.write('{"frames": [{"sources": [{"position": [1, 2, 3], "previous": [-1, 1, 2], "radius": 2.5},'
            ' {"position": [4, 4, 4], "radius": 1.2}]}]}')
res, centre, size = (14, 11, 9), np.array([1.5, 2.0, 3.0]), np.array([9.0, 7.0, 6.0])
angle, axis = 35.0, np.array([1.0, 2.0, 3.0])
common = ["--resolution", ",".join(map(str, res)), "--box", ",".join(map(str, [*centre, *size])),
          "--rotation", ",".join(map(str, [angle, *axis])), "--storage", "rgba32f"]
run("vectors", agents, "-o", os.path.join(WORK, "v.vdb"), *common)
run("vectors", agents, "-o", os.path.join(WORK, "v.npy"), *common)
texels = np.load(os.path.join(WORK, "v.npy"))
check(texels.shape == (*res, 4), f"vectors: .npy shape {texels.shape}")
grids = {g.name: g for g in vdb.readAll(os.path.join(WORK, "v.vdb"))[0]}
check(set(grids) == {"vectors", "strength"}, f"vectors: grids {sorted(grids)}")
vec, strength = grids["vectors"], grids["strength"]
check(vec.valueTypeName == "vec3s" and strength.valueTypeName == "float",
      f"vectors: types {vec.valueTypeName}, {strength.valueTypeName}")
check(vec.metadata.get("vector_type") == "invariant", f"vectors: {vec.metadata.get('vector_type')}")
check(vec.metadata.get("voxfield_kind") == "vector field", "vectors: voxfield_kind")
got_v = np.zeros((*res, 3), np.float32)
got_s = np.zeros(res, np.float32)
vec.copyToArray(got_v, ijk=(0, 0, 0))
strength.copyToArray(got_s, ijk=(0, 0, 0))
want_s = texels[..., 3]
want_v = texels[..., :3] * want_s[..., None]
check((want_s > 0).sum() > 50 and (want_s == 0).sum() > 50, "vectors: the field has both")
check(np.array_equal(got_s, want_s), f"vectors: strengths differ at {np.argwhere(got_s != want_s)[:3]}")
check(np.array_equal(got_v, want_v), f"vectors: vectors differ at {np.argwhere(got_v != want_v)[:3]}")
check(vec.activeVoxelCount() == int((want_s > 0).sum()), "vectors: active voxels")
k = axis / np.linalg.norm(axis)
K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
t = np.radians(angle)
R = np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K
worst = 0.0
for ijk in [(0, 0, 0), (13, 0, 0), (0, 10, 0), (0, 0, 8), (13, 10, 8), (5, 7, 2)]:
    want = centre + R @ ((np.array(ijk) + 0.5) * size / np.array(res) - size / 2)
    worst = max(worst, float(np.abs(np.array(vec.transform.indexToWorld(ijk)) - want).max()))
check(worst < 1e-9, f"vectors: the transform is {worst} away from the voxel centres")

# A world is an Int32 grid, which pyopenvdb cannot open (tests/test_vdb.cpp checks it with
# OpenVDB's C++ reader); voxfield reads it back as the world it came from.
world = os.path.join(WORK, "world.vdb")
run("convert", VOX, world)
run("convert", world, os.path.join(WORK, "world-back.npy"))
run("convert", VOX, os.path.join(WORK, "world-direct.npy"))
back, direct = np.load(os.path.join(WORK, "world-back.npy")), np.load(os.path.join(WORK, "world-direct.npy"))
check(back.shape == direct.shape and np.array_equal(back, direct), "world: .vdb read back differs")

# A level set pyopenvdb writes (Blosc, active-mask compression, a 0.5 voxel size): voxfield's world
# from it is its inside, value < 0, as pyopenvdb's own dense copy says.
sphere = vdb.createLevelSetSphere(radius=6.0, center=(1.0, -2.0, 0.5), voxelSize=0.5, halfWidth=3.0)
sphere.name = "sphere"
sphere_path = os.path.join(WORK, "sphere.vdb")
vdb.write(sphere_path, grids=[sphere])
run("convert", sphere_path, os.path.join(WORK, "sphere.npy"))
lo, hi = sphere.evalActiveVoxelBoundingBox()
dense = np.zeros([hi[i] - lo[i] + 1 for i in range(3)], dtype=np.float32)
sphere.copyToArray(dense, ijk=lo)  # dense[i, j, k] is voxel lo + (i, j, k)
inside = (dense < 0).astype(np.uint8)
nz = np.nonzero(inside)  # voxfield's .npy of a world without a recorded extent covers its content
inside = inside[nz[0].min():nz[0].max() + 1, nz[1].min():nz[1].max() + 1, nz[2].min():nz[2].max() + 1]
got = np.load(os.path.join(WORK, "sphere.npy"))  # voxfield's .npy: [z, y, x] over the content
check(got.shape == inside.T.shape and np.array_equal(got != 0, inside.T != 0),
      f"sphere: voxfield's inside {got.shape} {int((got != 0).sum())} voxels, pyopenvdb's "
      f"{inside.T.shape} {int(inside.sum())}")

# --grid: a file holding a fog volume and then the sphere, so that the default rule (no Int32
# grid: the first grid) reads the fog and only --grid reads the sphere.
fog = vdb.FloatGrid(0.0)
fog.name = "fog"
fog.fill((40, 0, 0), (43, 4, 5), 0.25, True)
pair = os.path.join(WORK, "pair.vdb")
vdb.write(pair, grids=[fog, sphere])
run("convert", pair, os.path.join(WORK, "pair-default.npy"))
run("convert", pair, "--grid", "fog", os.path.join(WORK, "pair-fog.npy"))
run("convert", pair, "--grid", "sphere", os.path.join(WORK, "pair-sphere.npy"))
fog_world = np.load(os.path.join(WORK, "pair-fog.npy"))
check(int((fog_world != 0).sum()) == fog.activeVoxelCount() == 4 * 5 * 6, "the fog's world: not its active voxels")
check(np.array_equal(np.load(os.path.join(WORK, "pair-default.npy")), fog_world), "no --grid: not the first grid")
# The fog second, where the default would read the sphere: --grid fog still reads the fog.
pair2 = os.path.join(WORK, "pair2.vdb")
vdb.write(pair2, grids=[sphere, fog])
run("convert", pair2, "--grid", "fog", os.path.join(WORK, "pair2-fog.npy"))
check(np.array_equal(np.load(os.path.join(WORK, "pair2-fog.npy")), fog_world), "--grid fog: not the fog")
check(np.array_equal(np.load(os.path.join(WORK, "pair-sphere.npy")), got), "--grid sphere: not the sphere's inside")
p = run("info", pair, "--grid", "sphere", "--json")
check(json.loads(p.stdout)["solid_voxels"] == int(inside.sum()), f"info --grid sphere: {p.stdout[:300]}")
# mesh and field read the chosen grid: the same triangles and distances as from its world's .npy.
for cmd, extra in [("mesh", ["--stats"]), ("field", ["--stats"])]:
    counts = []
    for src, grid in [(pair, ["--grid", "sphere"]), (os.path.join(WORK, "pair-sphere.npy"), [])]:
        out = os.path.join(WORK, f"{cmd}-{len(grid)}." + ("stl" if cmd == "mesh" else "npy"))
        stats = os.path.join(WORK, f"{cmd}-{len(grid)}.json")
        run(cmd, src, *grid, "-o", out, *extra, stats)
        counts.append(json.load(open(stats))["triangles"] if cmd == "mesh" else np.load(out))
    same = counts[0] == counts[1] if cmd == "mesh" else np.array_equal(counts[0], counts[1])
    check(same, f"{cmd} --grid sphere: differs from the sphere's world")
out = os.path.join(WORK, "never.npy")
p = run("convert", pair, "--grid", "density", out, ok=False)
check(p.returncode == 1 and f"{pair} has no grid named 'density'; its grids: 'fog' (float), 'sphere' (float)" in p.stderr,
      f"--grid density: {p.returncode} {p.stderr}")
check(not os.path.exists(out), "a failed convert wrote its output")
for args in [("convert", VOX, "--grid", "fog", out), ("mesh", os.path.join(WORK, "pair-fog.npy"), "--grid", "fog", "-o",
             os.path.join(WORK, "never.stl")), ("render", VOX, "--grid", "fog", "-o", os.path.join(WORK, "never.png"))]:
    p = run(*args, ok=False)
    check(p.returncode == 2 and "is not a .vdb file" in p.stderr, f"{args[0]} --grid on {args[1]}: {p.returncode} {p.stderr}")
check(not any(os.path.exists(os.path.join(WORK, f)) for f in ["never.npy", "never.stl", "never.png"]),
      "a refused --grid wrote an output")

# A truncated .vdb: refused naming the file; a failed command writes nothing.
cut = os.path.join(WORK, "cut.vdb")
with open(world, "rb") as f, open(cut, "wb") as g:
    g.write(f.read()[: os.path.getsize(world) // 2])
out = os.path.join(WORK, "never.npy")
p = run("convert", cut, out, ok=False)
check(p.returncode == 1 and cut in p.stderr and "at byte" in p.stderr, f"cut .vdb: {p.returncode} {p.stderr}")
check(not os.path.exists(out), "a failed convert wrote its output")
# A clamp within half a voxel of the surface is refused by the writer, after the field is computed.
p = run("field", VOX, "--signed", "--max-distance", "0.4", "-o", os.path.join(WORK, "never.vdb"),
        ok=False)
check(p.returncode == 1 and "leaves no band" in p.stderr, f"clamp 0.4: {p.returncode} {p.stderr}")
check(not os.path.exists(os.path.join(WORK, "never.vdb")), "a failed field wrote its .vdb")

if failures:
    raise SystemExit(f"{failures} check(s) failed")
print(f"vdb oracle: {len(cases)} fields and a vector field checked against pyopenvdb")

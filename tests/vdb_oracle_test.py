"""voxfield's .vdb files read by OpenVDB's own Python module (pyopenvdb, Debian python3-openvdb).

A real MagicaVoxel file's distance fields are written by the CLI as .vdb and as .npy in the same
run; pyopenvdb must see a level set (signed) or a scalar grid (unsigned) with the documented
background, voxel size and metadata, holding at every voxel of the domain the .npy's distance
(for a level set, less half a voxel: the distance to the surface midway between voxel centres).
Reading .vdb is refused with the reason, and a failed command writes nothing.

Usage: vdb_oracle_test.py VOXFIELD_BINARY VOX_FILE WORK_DIR
"""

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

# A world is an Int32 grid, which pyopenvdb cannot open (tests/test_vdb.cpp checks it with
# OpenVDB's C++ reader); here it is only written, then refused as an input.
world = os.path.join(WORK, "world.vdb")
run("convert", VOX, world)
check(os.path.getsize(world) > 0, "world: written")

# Reading .vdb: refused with the reason; a failed command writes nothing.
out = os.path.join(WORK, "never.npy")
p = run("convert", world, out, ok=False)
check(p.returncode == 1 and "does not read them yet" in p.stderr, f"reading .vdb: {p.returncode} {p.stderr}")
check(not os.path.exists(out), "a failed convert wrote its output")
# A clamp within half a voxel of the surface is refused by the writer, after the field is computed.
p = run("field", VOX, "--signed", "--max-distance", "0.4", "-o", os.path.join(WORK, "never.vdb"),
        ok=False)
check(p.returncode == 1 and "leaves no band" in p.stderr, f"clamp 0.4: {p.returncode} {p.stderr}")
check(not os.path.exists(os.path.join(WORK, "never.vdb")), "a failed field wrote its .vdb")

if failures:
    raise SystemExit(f"{failures} check(s) failed")
print(f"vdb oracle: {len(cases)} fields checked against pyopenvdb")

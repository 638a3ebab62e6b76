#!/usr/bin/env python3
"""voxfield mesh against scikit-image's marching_cubes, and every mesh format re-read here.

The same float volume (a smooth random field and a sphere, anisotropic spacing) is meshed by
`voxfield mesh` and by skimage.measure.marching_cubes at the same level: triangle counts within
1 %, every vertex of ours on a vertex of theirs (both interpolate the same lattice edges) or, where
the two resolve an ambiguous cell differently, within one sample of their surface. The PLY, OBJ, STL
and glTF outputs are parsed with readers written here (NumPy only) and must hold the same
triangles. Usage: mesh_oracle_test.py VOXFIELD WORKDIR
"""
import json
import os
import struct
import subprocess
import sys

import numpy as np
from scipy.spatial import cKDTree
from skimage.measure import marching_cubes

voxfield, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def run(*args):
    return subprocess.run([voxfield, *args], capture_output=True, text=True)


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert header[1] == "format binary_little_endian 1.0", header[1]
    nv = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    nf = int(next(l for l in header if l.startswith("element face")).split()[2])
    props = [l.split()[-1] for l in header if l.startswith("property") and "list" not in l]
    types = {"x": "<f4", "y": "<f4", "z": "<f4", "nx": "<f4", "ny": "<f4", "nz": "<f4", "red": "u1", "green": "u1", "blue": "u1"}
    vdt = np.dtype([(p, types[p]) for p in props])
    verts = np.frombuffer(data, vdt, nv, end)
    faces = np.frombuffer(data, np.dtype([("n", "u1"), ("i", "<u4", 3)]), nf, end + nv * vdt.itemsize)
    assert (faces["n"] == 3).all()
    assert end + nv * vdt.itemsize + nf * 13 == len(data), "bytes after the faces"
    pos = np.stack([verts["x"], verts["y"], verts["z"]], 1)
    return pos, faces["i"].astype(np.int64), verts


def read_obj(path):
    v, f = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:]])
        elif line.startswith("f "):
            f.append([int(x.split("//")[0]) - 1 for x in line.split()[1:]])
    return np.array(v, np.float32), np.array(f, np.int64)


def read_stl(path):
    data = open(path, "rb").read()
    (n,) = struct.unpack_from("<I", data, 80)
    assert 84 + 50 * n == len(data)
    rec = np.frombuffer(data, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), n, 84)
    return rec["v"], rec["n"]


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2 and length == len(data)
    jlen, jtype = struct.unpack_from("<II", data, 12)
    assert jtype == 0x4E4F534A
    doc = json.loads(data[20:20 + jlen])
    blen, btype = struct.unpack_from("<II", data, 20 + jlen)
    assert btype == 0x004E4942
    bin_ = data[28 + jlen:28 + jlen + blen]

    def accessor(i, dtype, comps):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        return np.frombuffer(bin_, dtype, a["count"] * comps, v.get("byteOffset", 0)).reshape(a["count"], comps)

    prim = doc["meshes"][0]["primitives"][0]
    pos = accessor(prim["attributes"]["POSITION"], "<f4", 3)
    nrm = accessor(prim["attributes"]["NORMAL"], "<f4", 3)
    assert np.allclose(np.linalg.norm(nrm, axis=1), 1, atol=1e-5), "a glTF normal is not unit length"
    for view in doc["bufferViews"]:
        assert view["byteOffset"] % 4 == 0 and view["byteLength"] > 0
    if "COLOR_0" in prim["attributes"]:
        a = doc["accessors"][prim["attributes"]["COLOR_0"]]
        assert a["componentType"] == 5123 and a["normalized"] and a["type"] == "VEC4", a
    a = doc["accessors"][prim["attributes"]["POSITION"]]
    assert np.allclose(a["min"], pos.min(0)) and np.allclose(a["max"], pos.max(0))
    idx = accessor(prim["indices"], "<u4", 1).reshape(-1, 3).astype(np.int64)
    return pos, idx


def triangles(pos, idx):
    """Triangles as sorted rows of their corner positions (orientation kept by a rotation)."""
    t = pos[idx]  # (n, 3, 3)
    keys = [tuple(map(tuple, tri)) for tri in t]
    out = []
    for k in keys:
        m = k.index(min(k))
        out.append(k[m:] + k[:m])
    return sorted(out)


rng = np.random.default_rng(3)
n = 64
# A smooth random field: noise blurred in Fourier space, plus a sphere, so both open sheets
# reaching the volume's faces and a closed surface appear.
noise = np.fft.ifftn(np.fft.fftn(rng.standard_normal((n, n, n))) *
                     np.exp(-0.5 * (np.add.outer(np.add.outer(np.fft.fftfreq(n) ** 2, np.fft.fftfreq(n) ** 2),
                                                  np.fft.fftfreq(n) ** 2)) / 0.06 ** 2)).real
noise /= noise.std()
g = np.indices((n, n, n)).astype(np.float64)
sphere = np.sqrt(((g - n / 2) ** 2).sum(0)) - n / 4
for name, vol, level, spacing in [("noise", noise, 0.3, (1.0, 1.0, 1.0)), ("sphere", sphere, 0.0, (0.5, 1.0, 2.0))]:
    path = os.path.join(work, name + ".npy")
    np.save(path, vol.astype(np.float32))
    out = os.path.join(work, name + ".ply")
    stats = os.path.join(work, name + ".json")
    r = run("mesh", path, "-o", out, "--iso", str(level), "--spacing", ",".join(map(str, spacing)), "--stats", stats,
            "--chunk", "16")
    check(r.returncode == 0, f"{name}: voxfield mesh failed: {r.stderr}")
    if r.returncode:
        continue
    pos, idx, verts = read_ply(out)
    st = json.load(open(stats))
    check(st["triangles"] == len(idx) and st["vertices"] == len(pos), f"{name}: stats do not match the file")
    sv, sf, _, _ = marching_cubes(vol.astype(np.float32), level=level, spacing=spacing)
    ratio = len(idx) / len(sf)
    print(f"{name}: voxfield {len(idx)} triangles, scikit-image {len(sf)} ({ratio:.4f})")
    check(abs(ratio - 1) <= 0.01, f"{name}: triangle counts differ by more than 1 %: {len(idx)} vs {len(sf)}")
    d, _ = cKDTree(sv).query(pos)
    on_theirs = (d < 1e-4).mean()
    print(f"{name}: {on_theirs * 100:.2f} % of our vertices on theirs, farthest {d.max():.4f}")
    # Centre vertices of multiply ambiguous cells are not on any edge: a tiny fraction.
    check(on_theirs > 0.99, f"{name}: only {on_theirs * 100:.2f} % of the vertices match scikit-image's")
    check(d.max() < max(spacing), f"{name}: a vertex is {d.max():.3f} from scikit-image's surface")
    if name == "sphere":
        check(st["watertight"] and st["euler_characteristic"] == 2, f"sphere: not a closed genus-0 surface: {st}")
        # Normals point out of the sphere (inside is below the level).
        centre = np.array([n / 2 * s for s in spacing])
        nrm = np.stack([verts["nx"], verts["ny"], verts["nz"]], 1)
        check((np.einsum("ij,ij->i", nrm, pos - centre) > 0).all(), "sphere: a normal points in")

# Every format holds the same triangles.
world = os.path.join(work, "terrain.npy")
check(run("generate", "terrain", "--size", "40", "-o", world).returncode == 0, "generate failed")
for algo in ["mc", "sn", "dc"]:
    outs = {ext: os.path.join(work, f"terrain-{algo}.{ext}") for ext in ["ply", "obj", "stl", "glb"]}
    for ext, path in outs.items():
        r = run("mesh", world, "-o", path, "--algorithm", algo)
        check(r.returncode == 0, f"{algo} {ext}: {r.stderr}")
    pos, idx, verts = read_ply(outs["ply"])
    ref = triangles(pos, idx)
    opos, oidx = read_obj(outs["obj"])
    check(triangles(opos, oidx) == ref, f"{algo}: the OBJ holds other triangles than the PLY")
    gpos, gidx = read_glb(outs["glb"])
    check(triangles(gpos, gidx) == ref, f"{algo}: the glTF holds other triangles than the PLY")
    tri, nrm = read_stl(outs["stl"])
    stl = sorted(tuple(map(tuple, t))[k:] + tuple(map(tuple, t))[:k]
                 for t in tri for k in [tuple(map(tuple, t)).index(min(tuple(map(tuple, t))))])
    check(stl == ref, f"{algo}: the STL holds other triangles than the PLY")
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    check((np.einsum("ij,ij->i", face_n, nrm) >= 0).all(), f"{algo}: an STL facet normal disagrees with its winding")
    check(len(ref) > 1000, f"{algo}: terrain mesh too small ({len(ref)})")

# Simplified and reordered: about the triangles asked for, the file matching the stats.
simple, sstats = os.path.join(work, "terrain-simple.ply"), os.path.join(work, "terrain-simple.json")
r = run("mesh", world, "-o", simple, "--simplify", "0.3", "--optimize", "--stats", sstats)
check(r.returncode == 0, f"--simplify: {r.stderr}")
if r.returncode == 0:
    st = json.load(open(sstats))
    spos, sidx, _ = read_ply(simple)
    check(st["simplify"]["triangles_after"] == len(sidx) == st["triangles"], f"--simplify: stats {st['simplify']} vs file {len(sidx)}")
    check(len(sidx) <= 0.31 * st["simplify"]["triangles_before"], f"--simplify 0.3 kept {len(sidx)} of {st['simplify']['triangles_before']}")
    check(len(np.unique(sidx)) == len(spos), "--simplify left unreferenced vertices")

# An empty mesh is still a valid glTF (no zero-length accessors, views or buffers).
empty_world = os.path.join(work, "empty.npy")
np.save(empty_world, np.zeros((4, 4, 4), np.uint8))
empty_glb = os.path.join(work, "empty.glb")
r = run("mesh", empty_world, "-o", empty_glb)
check(r.returncode == 0, f"empty world: {r.stderr}")
if r.returncode == 0:
    data = open(empty_glb, "rb").read()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    check(len(data) == 20 + jlen and "accessors" not in doc and "buffers" not in doc and doc["nodes"] == [{}],
          f"empty glTF: {doc}")

# A failed command writes nothing.
bad = os.path.join(work, "nan.npy")
v = np.zeros((8, 8, 8), np.float32)
v[3, 4, 5] = np.nan
np.save(bad, v)
target = os.path.join(work, "nan.ply")
r = run("mesh", bad, "-o", target)
check(r.returncode == 1 and "(3, 4, 5) is NaN" in r.stderr and not os.path.exists(target),
      f"NaN volume: rc {r.returncode}, {r.stderr!r}, output exists: {os.path.exists(target)}")
r = run("mesh", world, "-o", target, "--inside", "above")
check(r.returncode == 2 and not os.path.exists(target), f"--inside on a world: rc {r.returncode}, {r.stderr!r}")
r = run("mesh", bad, "-o", target, "--metric", "manhattan")
check(r.returncode == 2 and not os.path.exists(target), f"--metric on a float volume: rc {r.returncode}, {r.stderr!r}")

# A world's offset surface in each metric: one voxel at (5, 6, 7) (centre (5.5, 6.5, 7.5)) at iso 3
# is the octahedron |dx| + |dy| + |dz| = 3 (Manhattan), the box max |d| = 3 (Chebyshev: every
# vertex on it, its edges bevelled between them), and within 1 / 24 of the sphere |d| = 3
# (Euclidean: linear interpolation of the distance along edges); closed genus-0 surfaces.
one = os.path.join(work, "one.npy")
occ = np.zeros((12, 13, 14), np.uint8)
occ[5, 6, 7] = 3
np.save(one, occ)
centre = np.array([5.5, 6.5, 7.5])
for metric, distance, tol in (("manhattan", lambda d: np.abs(d).sum(1), 1e-4),
                              ("chebyshev", lambda d: np.abs(d).max(1), 1e-4),
                              ("euclidean", lambda d: np.sqrt((d * d).sum(1)), 1 / 24 + 1e-4)):
    path, stats = os.path.join(work, f"offset-{metric}.ply"), os.path.join(work, f"offset-{metric}.json")
    r = run("mesh", one, "-o", path, "--metric", metric, "--iso", "3", "--stats", stats)
    check(r.returncode == 0, f"offset {metric}: {r.stderr}")
    if r.returncode != 0:
        continue
    pos, idx, _ = read_ply(path)
    d = distance(pos - centre)
    check(np.abs(d - 3).max() <= tol, f"offset {metric}: a vertex at {d.min():.4f}..{d.max():.4f}, not 3")
    st = json.load(open(stats))
    check(st["watertight"] and st["euler_characteristic"] == 2, f"offset {metric}: {st}")

# `voxfield edit --mesh`: the surface kept through an edit script (re-meshed chunk by chunk) holds
# the triangles `voxfield mesh` makes of the edited world — positions, normals and colours — for
# every mesher; a paint re-colours it; the stats count what each edit re-meshed.
scene = np.zeros((40, 32, 24), np.uint8)
scene[:, :, :6] = 2
scene[8:20, 6:14, 6:12] = 5
world_in = os.path.join(work, "kept-in.npy")
np.save(world_in, scene)
script = os.path.join(work, "kept.jsonl")
with open(script, "w") as f:
    f.write('{"op":"carve","shape":"sphere","center":[14,10,11],"radius":4}\n'
            '{"op":"place","shape":"capsule","a":[25,20,6],"b":[35,28,10],"radius":2,"material":7}\n'
            '{"op":"paint","shape":"box","min":[0,0,0],"max":[12,31,5],"material":9}\n'
            '{"op":"carve","shape":"box","min":[30,2,3],"max":[39,8,5]}\n')


def corner_rows(pos, idx, verts):
    attrs = np.stack([verts[k].astype(np.float64) for k in ("nx", "ny", "nz", "red", "green", "blue")], 1)
    rows = np.concatenate([pos.astype(np.float64), attrs], 1)
    return triangles(rows, idx)


for algo in ["mc", "sn", "dc"]:
    kept, full = os.path.join(work, f"kept-{algo}.ply"), os.path.join(work, f"kept-full-{algo}.ply")
    edited, stats = os.path.join(work, f"kept-world-{algo}.npy"), os.path.join(work, f"kept-{algo}.json")
    r = run("edit", world_in, "-e", script, "-o", os.path.join(work, f"kept-field-{algo}.npy"),
            "--save-world", edited, "--mesh", kept, "--mesh-algorithm", algo, "--mesh-chunk", "8",
            "--stats", stats)
    check(r.returncode == 0, f"edit --mesh {algo}: {r.stderr}")
    if r.returncode != 0:
        continue
    r = run("mesh", edited, "-o", full, "--algorithm", algo)
    check(r.returncode == 0, f"mesh of the edited world {algo}: {r.stderr}")
    a, b = read_ply(kept), read_ply(full)
    check(len(a[1]) == len(b[1]) and corner_rows(*a) == corner_rows(*b),
          f"edit --mesh {algo}: {len(a[1])} triangles kept, {len(b[1])} meshed from scratch, or other corners")
    m = json.load(open(stats))["mesh"]
    check(m["triangles"] == len(a[1]) and len(m["chunks_remeshed"]) == 4 and
          all(0 < c < m["chunks"] for c in m["chunks_remeshed"]), f"edit --mesh {algo} stats: {m}")
r = run("edit", world_in, "-e", script, "-o", os.path.join(work, "kept-bad.npy"), "--mesh",
        os.path.join(work, "kept.txt"))
check(r.returncode != 0 and not os.path.exists(os.path.join(work, "kept-bad.npy")),
      f"edit --mesh to an unknown format writes nothing: rc {r.returncode}")

print("mesh oracle:", "FAILED" if failures else "ok")
sys.exit(1 if failures else 0)

#!/usr/bin/python3
"""The voxel compiler against independent oracles, through the CLI.

- OpenSCAD itself: the examples Debian's openscad ships that use only the supported nodes are
  exported by openscad as .csg (imported by voxfield) and as STL (voxelised here by ray parity);
  with --facets the occupancies must agree but for voxels whose centre lies within half a voxel of
  a facet, and the ideal shapes nearly as well. An example using hull() is refused by name.
- A NumPy evaluation of the definitions in docs/csg.md, written from the document, against
  `voxfield csg eval` (whole and --pruned) and `voxelize --field`.
- A failed run writes nothing.
Usage: csg_oracle_test.py VOXFIELD REPO   (skips the OpenSCAD part when openscad is missing)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

VOXFIELD, REPO = sys.argv[1], sys.argv[2]
EXAMPLES = "/usr/share/openscad/examples"
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(*args, expect=0):
    p = subprocess.run([VOXFIELD, *args], capture_output=True, text=True)
    if p.returncode != expect:
        print(p.stdout, p.stderr)
    return p


def read_stl(path):
    data = open(path, "rb").read()
    if data[:5] == b"solid" and b"facet" in data[:1000]:
        v = [list(map(float, line.split()[1:4])) for line in data.decode().splitlines() if line.strip().startswith("vertex")]
        return np.array(v).reshape(-1, 3, 3)
    n = int(np.frombuffer(data[80:84], "<u4")[0])
    rec = np.frombuffer(data[84:84 + 50 * n], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    return rec["v"].astype(np.float64)


def voxelise_stl(tris, lo, voxel, dims):
    """Occupancy of voxel centres by ray parity along +z, column by column."""
    xs = lo[0] + (np.arange(dims[0]) + 0.5) * voxel
    ys = lo[1] + (np.arange(dims[1]) + 0.5) * voxel
    zs = lo[2] + (np.arange(dims[2]) + 0.5) * voxel
    crossings = [[[] for _ in range(dims[1])] for _ in range(dims[0])]
    for t in tris:
        (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = t
        d = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)
        if abs(d) < 1e-15:
            continue  # vertical facet: no z crossing
        i0 = np.searchsorted(xs, min(x0, x1, x2))
        i1 = np.searchsorted(xs, max(x0, x1, x2), side="right")
        j0 = np.searchsorted(ys, min(y0, y1, y2))
        j1 = np.searchsorted(ys, max(y0, y1, y2), side="right")
        if i0 >= i1 or j0 >= j1:
            continue
        X, Y = np.meshgrid(xs[i0:i1], ys[j0:j1], indexing="ij")
        a = ((y1 - y2) * (X - x2) + (x2 - x1) * (Y - y2)) / d
        b = ((y2 - y0) * (X - x2) + (x0 - x2) * (Y - y2)) / d
        c = 1 - a - b
        # A ray through an edge or vertex is inside every triangle there (within rounding) and
        # its crossings, equal in z, are merged below: it counts once, never zero times.
        inside = (a >= -1e-9) & (b >= -1e-9) & (c >= -1e-9)
        z = a * z0 + b * z1 + c * z2
        for i, j in zip(*np.nonzero(inside)):
            crossings[i0 + i][j0 + j].append(z[i, j])
    occ = np.zeros(dims, bool)
    for i in range(dims[0]):
        for j in range(dims[1]):
            cz = np.unique(np.round(np.array(crossings[i][j]), 7))
            if len(cz) < 2:
                continue
            count = np.searchsorted(cz, zs)  # crossings below each centre
            occ[i, j] = count % 2 == 1
    return occ


def near_surface(tris, points, radius):
    """Whether each point lies within `radius` of some triangle (checked against vertices and a
    dense sampling of the triangles, conservative by a margin)."""
    samples = []
    for u in np.linspace(0, 1, 9):
        for v in np.linspace(0, 1 - u, max(2, int(9 * (1 - u)))):
            samples.append(tris[:, 0] * (1 - u - v) + tris[:, 1] * u + tris[:, 2] * v)
    s = np.concatenate(samples)
    out = np.zeros(len(points), bool)
    for k in range(0, len(points), 256):
        d = np.sqrt(((points[k:k + 256, None, :] - s[None, :, :]) ** 2).sum(-1)).min(1)
        out[k:k + 256] = d <= radius
    return out


def openscad_part(tmp):
    if not shutil.which("openscad") or not os.path.isdir(EXAMPLES):
        print("skip: openscad is not installed")
        return
    found = {os.path.splitext(f)[0]: os.path.join(d, f) for d, _, fs in os.walk(EXAMPLES) for f in fs if f.endswith(".scad")}
    for name in ["example001", "example002", "example003", "example004", "example014", "assert"]:
        scad = found[name]
        csg, stl = os.path.join(tmp, name + ".csg"), os.path.join(tmp, name + ".stl")
        subprocess.run(["openscad", "-o", csg, scad], capture_output=True, check=True)
        subprocess.run(["openscad", "-o", stl, scad], capture_output=True, check=True)
        tris = read_stl(stl)
        lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
        voxel = float((hi - lo).max()) / 48
        lo, hi = lo - 2 * voxel, hi + 2 * voxel
        dims = np.ceil((hi - lo) / voxel).astype(int)
        box = ",".join("%.9g" % v for v in [*lo, *(lo + dims * voxel)])
        oracle = voxelise_stl(tris, lo, voxel, dims)
        for facets in (True, False):
            out = os.path.join(tmp, name + ("-f" if facets else "") + ".npy")
            args = ["csg", csg, "voxelize", "--voxel-size", "%.9g" % voxel, "--box", box, "-o", out]
            p = run(*(args + ["--facets"] if facets else args))
            if p.returncode != 0:
                check(False, "%s imports and voxelises (facets %s): %s" % (name, facets, p.stderr.strip()))
                continue
            ours = np.load(out) != 0
            check(ours.shape == tuple(dims), "%s: grid %s" % (name, ours.shape))
            if ours.shape != tuple(dims):
                continue
            differ = np.argwhere(ours != oracle)
            union = (ours | oracle).sum()
            iou = (ours & oracle).sum() / max(union, 1)
            if facets:
                # Every voxel that differs must have its centre within half a voxel of OpenSCAD's mesh.
                centres = lo + (differ + 0.5) * voxel
                near = near_surface(tris, centres, 0.5 * voxel * 1.01) if len(differ) else np.array([], bool)
                check(bool(near.all()), "%s --facets: occupancy equals OpenSCAD's mesh but for %d voxels at its "
                      "surface (IoU %.4f; %d far from it)" % (name, len(differ), iou, int((~near).sum())))
            else:
                # OpenSCAD's default facets ($fa 12, $fs 2) are coarse: the ideal shapes differ by
                # their sagitta, a few per cent of the volume.
                check(iou > 0.9, "%s (ideal shapes): IoU %.4f with OpenSCAD's facetted mesh" % (name, iou))
    csg = os.path.join(tmp, "example006.csg")
    subprocess.run(["openscad", "-o", csg, found["example006"]], capture_output=True, check=True)
    p = run("csg", csg, "info", expect=1)
    check(p.returncode == 1 and "hull() is not supported" in p.stderr and "example006.csg:" in p.stderr,
          "an unsupported node is refused by name and line: " + p.stderr.strip()[:120])


# ---- the definitions, in NumPy -------------------------------------------------------------------

def sd_box(p, size):
    q = np.abs(p) - np.asarray(size) / 2
    return np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(-1), 0)


def sd_cylinder(p, r, h):
    d = np.stack([np.hypot(p[:, 0], p[:, 1]) - r, np.abs(p[:, 2]) - h / 2], -1)
    return np.minimum(d.max(-1), 0) + np.linalg.norm(np.maximum(d, 0), axis=-1)


def smooth_min(a, b, k):
    h = np.maximum(k - np.abs(a - b), 0) / k
    return np.minimum(a, b) - h * h * k / 4


def rot_z(deg):
    a = np.radians(deg)
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


MODEL = """(diff (smooth-union 0.7 (sphere 2) (move 3 0 0 (rotate-z 30 (box 2 1 1.5))))
      (scale 0.5 (cylinder 1 10)) (move 0 0 2 (round 0.25 (cube 1))))"""


def model_numpy(p):
    sphere = np.linalg.norm(p, axis=-1) - 2
    q = (p - [3, 0, 0]) @ rot_z(30)  # R^-1 p as row vectors: p R
    box = sd_box(q, [2, 1, 1.5])
    blob = smooth_min(sphere, box, 0.7)
    cyl = 0.5 * sd_cylinder(p / 0.5, 1, 10)
    rounded = sd_box(p - [0, 0, 2], [1, 1, 1]) - 0.25
    return np.maximum(np.maximum(blob, -cyl), -rounded)


def definition_part(tmp):
    model = os.path.join(tmp, "m.sdf")
    open(model, "w").write(MODEL)
    pts = np.random.default_rng(4).uniform(-4, 6, (5000, 3))
    np.save(os.path.join(tmp, "p.npy"), pts)
    want = model_numpy(pts)
    for extra in ([], ["--pruned", "--depth", "5"]):
        out = os.path.join(tmp, "d.npy")
        p = run("csg", model, "eval", "--points", os.path.join(tmp, "p.npy"), "-o", out, *extra)
        got = np.load(out) if p.returncode == 0 else np.zeros(0)
        if not extra:
            check(got.shape == (5000,) and np.allclose(got, want, rtol=0, atol=1e-9),
                  "eval equals the NumPy definition (max error %.2g)" % (np.abs(got - want).max() if got.shape == want.shape else -1))
        else:
            same_sign = np.sign(got) == np.sign(want)
            ok = got.shape == (5000,) and same_sign.all() and (np.abs(got) <= np.abs(want) + 1e-9).all()
            exact = np.isclose(got, want, rtol=0, atol=1e-12).mean() if ok else 0
            check(ok and exact > 0.3, "eval --pruned: right sign, never larger, %.0f %% of points exact" % (100 * exact))
    field = os.path.join(tmp, "f.npy")
    p = run("csg", model, "voxelize", "--voxel-size", "0.25", "--box", "-3,-3,-3,6,3,3", "-o",
            os.path.join(tmp, "w.npy"), "--field", field)
    f = np.load(field)
    idx = np.argwhere(np.ones(f.shape, bool))
    centres = np.array([-3, -3, -3]) + (idx + 0.5) * 0.25
    want_f = model_numpy(centres).astype(np.float32).reshape(f.shape)
    check(np.allclose(f, want_f, atol=1e-5), "voxelize --field equals the definition at the voxel centres")
    w = np.load(os.path.join(tmp, "w.npy"))
    check(((w != 0) == (want_f <= 0)).mean() > 0.9999, "voxelize: solid where the value is <= 0")
    # The voxels' frame (0.25 model units from (-3, -3, -3)) has no place in a .npy: said.
    check("w.npy keeps no frame" in p.stderr and "voxel size (0.25, 0.25, 0.25)" in p.stderr,
          "voxelize to .npy says the frame is left out: " + p.stderr.strip())
    # A failed run writes nothing: an unreadable points file after a valid model.
    out = os.path.join(tmp, "never.npy")
    open(os.path.join(tmp, "bad.npy"), "wb").write(b"not an npy")
    p = run("csg", model, "eval", "--points", os.path.join(tmp, "bad.npy"), "-o", out, expect=1)
    check(p.returncode == 1 and not os.path.exists(out) and "bad.npy" in p.stderr, "a failed eval writes nothing")
    # compile replaces an earlier compile's directory whole, and refuses any other directory.
    shaders = os.path.join(tmp, "shaders")
    for depth in ("5", "3"):
        run("csg", model, "compile", "--depth", depth, "-o", shaders)
    manifest = json.load(open(os.path.join(shaders, "manifest.json")))
    names = sorted(os.listdir(shaders))
    check(manifest["depth"] == 3 and names == sorted(["manifest.json", "params.f32", "prelude.glsl"] +
          ["variant_%d.glsl" % v["index"] for v in manifest["variants"]]),
          "compile replaces an earlier compile's directory whole (%d files)" % len(names))
    p = run("csg", model, "compile", "-o", tmp, expect=2)
    check(p.returncode == 2 and "not a compile's output" in p.stderr, "compile refuses a directory of other files")
    p = run("csg", model, "voxelize", "--voxel-size", "1e-7", "-o", out, expect=1)
    check(p.returncode == 1 and not os.path.exists(out) and "memory limit" in p.stderr,
          "an absurd voxelisation is refused by the memory limit: " + p.stderr.strip()[:100])


with tempfile.TemporaryDirectory() as tmp:
    definition_part(tmp)
    openscad_part(tmp)
print("%d failures" % len(failures))
sys.exit(1 if failures else 0)

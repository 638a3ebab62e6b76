"""`voxfield vectors` against an independent NumPy implementation of docs/vectors.md.

The definition is re-implemented here from the document alone, in float64: voxel centres of an
oriented box, the distance of each centre to each source's segment, the strongest covering source,
its direction away from the segment and strength 1 - d/r; then decay and blend over frames. The
CLI's .npy output (rgba32f storage) must match it to float precision, rgba8 to its rounding; the
.fga and .vf files are re-read by parsers written here from the formats' descriptions; bad input
exits 1 or 2 and writes nothing.

Usage: vectors_oracle_test.py VOXFIELD_BINARY WORK_DIR
"""

import json
import os
import struct
import subprocess
import sys

import numpy as np

failures = 0


def check(cond, what):
    global failures
    if not cond:
        failures += 1
        print(f"FAIL: {what}", file=sys.stderr)


def rotation(deg, axis):
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    a = np.radians(deg)
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)  # Rodrigues


def centres(centre, size, res, rot):
    """World positions of the voxel centres, shape (nx, ny, nz, 3)."""
    axes = [((np.arange(n) + 0.5) / n - 0.5) * s for n, s in zip(res, size)]
    local = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    return np.asarray(centre, float) + local @ rot.T


def field(points, sources):
    """The definition: direction (3) and strength per point, strongest covering source."""
    best = np.full(points.shape[:-1], -np.inf)
    out = np.zeros(points.shape[:-1] + (4,))
    for s in sources:
        a = np.asarray(s.get("previous", s["position"]), float)
        b = np.asarray(s["position"], float)
        ab = b - a
        ab2 = ab @ ab
        t = np.zeros(points.shape[:-1]) if ab2 == 0 else np.clip(((points - a) @ ab) / ab2, 0, 1)
        q = a + t[..., None] * ab
        d = np.linalg.norm(points - q, axis=-1)
        strength = 1 - d / s["radius"]
        take = (d < s["radius"]) & (strength > best)  # strict: the lower index keeps ties
        best = np.where(take, strength, best)
        with np.errstate(invalid="ignore", divide="ignore"):
            n = np.where(d[..., None] > 0, (points - q) / d[..., None], 0)
        out[take, :3] = n[take]
        out[take, 3] = strength[take]
    return out


def blend(cur, prev, decay_s):
    sc, sp = cur[..., 3], np.maximum(0, prev[..., 3] - decay_s)
    total = sc + sp
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(total > 0, sc / total, 0)
    n = w[..., None] * cur[..., :3] + (1 - w[..., None]) * prev[..., :3]
    length = np.linalg.norm(n, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        n = np.where(length[..., None] > 0, n / length[..., None], 0)
    # One side alone keeps its direction as it is; both zero: the zero texel.
    n = np.where((sp == 0)[..., None], cur[..., :3], n)
    n = np.where((sc == 0)[..., None] & (sp > 0)[..., None], prev[..., :3], n)
    out = np.concatenate([n, np.maximum(sc, sp)[..., None]], axis=-1)
    out[total <= 0] = 0
    return out


def run(voxfield, *args):
    return subprocess.run([voxfield, *args], capture_output=True, text=True)


def main():
    voxfield, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    rng = np.random.default_rng(17)
    centre, size, res = [1.0, -2.0, 0.5], [8.0, 5.0, 6.0], [24, 10, 16]
    rot = rotation(30, [1, 2, 0.5])
    sources = []
    for i in range(30):
        p = (rng.random(3) - 0.5) * 9
        s = {"position": p.tolist(), "radius": float(0.2 + rng.random() * 1.5)}
        if i % 3:
            s["previous"] = (p + (rng.random(3) - 0.5) * 3).tolist()
        sources.append(s)
    src = os.path.join(work, "sources.json")
    with open(src, "w") as f:
        json.dump({"sources": sources}, f)
    box = ",".join(map(str, centre + size))
    common = ["--box", box, "--rotation", "30,1,2,0.5", "--resolution", ",".join(map(str, res))]
    want = field(centres(centre, size, res, rot), sources)
    check((want[..., 3] > 0).mean() > 0.05, "the scene covers part of the volume")

    for storage, tol in (("rgba32f", 1e-6), ("rgba16f", 1e-3), ("rgba8", 1 / 255 + 1e-6)):
        for algorithm in ("splat", "brute"):
            out = os.path.join(work, f"{storage}-{algorithm}.npy")
            r = run(voxfield, "vectors", src, "-o", out, "--storage", storage, "--algorithm",
                    algorithm, *common)
            check(r.returncode == 0, f"vectors {storage} {algorithm}: {r.stderr.strip()}")
            if r.returncode:
                continue
            got = np.load(out)
            check(got.shape == tuple(res) + (4,) and got.dtype == np.float32,
                  f"{storage}: shape {got.shape} dtype {got.dtype}")
            err = np.abs(got - want).max()
            check(err <= tol, f"{storage} {algorithm}: max error {err} > {tol}")

    # JFA: measured, with its error in --stats.
    stats = os.path.join(work, "jfa.json")
    r = run(voxfield, "vectors", src, "-o", os.path.join(work, "jfa.npy"), "--algorithm", "jfa+1",
            "--stats", stats, *common)
    check(r.returncode == 0, f"vectors jfa+1: {r.stderr.strip()}")
    if r.returncode == 0:
        st = json.load(open(stats))
        check("error" in st and 0 <= st["error"]["percent_source_differs"] < 100, f"jfa stats {st}")

    # Frames: decay and blend of two steps.
    frames = [{"sources": sources[:15]}, {"sources": sources[10:]}]
    fsrc = os.path.join(work, "frames.json")
    with open(fsrc, "w") as f:
        json.dump({"frames": frames}, f)
    out = os.path.join(work, "frames.npy")
    r = run(voxfield, "vectors", fsrc, "-o", out, "--storage", "rgba32f", "--dt", "0.1",
            "--decay-per-s", "2", *common)
    check(r.returncode == 0, f"vectors frames: {r.stderr.strip()}")
    if r.returncode == 0:
        pts = centres(centre, size, res, rot)
        f0 = field(pts, frames[0]["sources"])
        expect = blend(field(pts, frames[1]["sources"]), blend(f0, np.zeros_like(f0), 0.2), 0.2)
        err = np.abs(np.load(out) - expect).max()
        check(err <= 1e-5, f"frames: max error {err}")

    # .fga and .vf, read by parsers written from the formats' descriptions.
    fga = os.path.join(work, "f.fga")
    vf = os.path.join(work, "f.vf")
    axis_box = ["--box", box, "--resolution", ",".join(map(str, res))]
    for path in (fga, vf):
        r = run(voxfield, "vectors", src, "-o", path, "--storage", "rgba32f", *axis_box)
        check(r.returncode == 0, f"vectors {path}: {r.stderr.strip()}")
    expect = field(centres(centre, size, res, np.eye(3)), sources)
    vec = expect[..., :3] * expect[..., 3:4]
    flat = vec.transpose(2, 1, 0, 3).reshape(-1, 3)  # x fastest
    if os.path.exists(fga):
        lines = open(fga).read().splitlines()
        check(lines[0] == f"{res[0]},{res[1]},{res[2]},", f"fga header {lines[0]}")
        lo = [float(v) for v in lines[1].rstrip(",").split(",")]
        hi = [float(v) for v in lines[2].rstrip(",").split(",")]
        check(np.allclose(lo, np.subtract(centre, np.divide(size, 2))), f"fga min {lo}")
        check(np.allclose(hi, np.add(centre, np.divide(size, 2))), f"fga max {hi}")
        body = np.array([[float(v) for v in ln.rstrip(",").split(",")] for ln in lines[3:]])
        check(body.shape == flat.shape, f"fga body {body.shape}")
        if body.shape == flat.shape:
            check(np.abs(body - flat).max() < 1e-6, "fga values")
    if os.path.exists(vf):
        data = open(vf, "rb").read()
        check(data[:4] == b"VF_V", "vf magic")
        dims = struct.unpack("<3H", data[4:10])
        check(list(dims) == res, f"vf sizes {dims}")
        check(len(data) == 10 + 12 * np.prod(res), f"vf length {len(data)}")
        values = np.frombuffer(data[10:], "<f4").reshape(-1, 3)
        check(values.shape == flat.shape and np.abs(values - flat).max() < 1e-6, "vf values")

    # A world as input: the flow away from its solids, against SciPy's exact Euclidean transform.
    from scipy import ndimage
    world = np.zeros((30, 26, 22), np.uint8)
    world[rng.random(world.shape) < 0.004] = 3
    world[10:14, 8:20, 6:9] = 1
    wpath = os.path.join(work, "world.npy")
    np.save(wpath, world)
    out = os.path.join(work, "world-flow.npy")
    r = run(voxfield, "vectors", wpath, "-o", out, "--reach", "4.5", "--storage", "rgba32f")
    check(r.returncode == 0, f"vectors world: {r.stderr.strip()}")
    if r.returncode == 0:
        got = np.load(out)
        solid = np.argwhere(world != 0)
        lo, hi = solid.min(0) - 5, solid.max(0) + 1 + 5  # the content box grown by ceil(4.5)
        padded = np.zeros(hi - lo, bool)
        padded[tuple(slice(-l, -l + n) for l, n in zip(lo, world.shape))] = world != 0
        d, idx = ndimage.distance_transform_edt(~padded, return_indices=True)
        want = np.where(d < 4.5, 1 - d / 4.5, 0)
        check(got.shape == padded.shape + (4,), f"world flow shape {got.shape} for {padded.shape}")
        if got.shape == padded.shape + (4,):
            check(np.abs(got[..., 3] - want).max() < 1e-6, "world flow strengths against SciPy")
            # Each direction points away from a solid voxel at exactly that distance.
            pts = np.argwhere((want > 0) & (d > 0))
            away_from = np.rint(pts - got[tuple(pts.T)][:, :3] * d[tuple(pts.T)][:, None]).astype(int)
            check(padded[tuple(away_from.T)].all(), "world flow directions point away from solids")

    png = os.path.join(work, "v.png")
    r = run(voxfield, "vectors", src, "-o", png, "--width", "96", "--height", "64", *common)
    check(r.returncode == 0 and open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n", "png output")

    # Bad input: exit 1 (the file named) or 2 (usage), and nothing written.
    bad = os.path.join(work, "bad.json")
    with open(bad, "w") as f:
        f.write('{"sources": [{"position": [0, 0, 0], "radius": -1}]}')
    for args, code, words in (
            ([bad, "-o", os.path.join(work, "no1.npy")], 1, ["bad.json", "source 0", "radius"]),
            ([os.path.join(work, "missing.json"), "-o", os.path.join(work, "no2.npy")], 1, ["missing.json"]),
            ([src, "-o", os.path.join(work, "no3.fga"), "--resolution", "129,8,8"], 2, ["at most 128"]),
            ([src, "-o", os.path.join(work, "no4.npy"), "--box", "0,0,0,1,0,1"], 2, ["size"]),
            ([src, "-o", os.path.join(work, "no5.txt")], 2, [".npy, .fga, .vf, .vdb or .png"]),
            ([src, "-o", os.path.join(work, "no6.npy"), "--stats", os.path.join(work, "nodir", "s.json")], 1,
             ["nodir"])):
        r = run(voxfield, "vectors", *args)
        check(r.returncode == code, f"{args}: exit {r.returncode}, expected {code}: {r.stderr.strip()}")
        for w in words:
            check(w in r.stderr, f"{args}: '{w}' not in: {r.stderr.strip()}")
        check(not os.path.exists(args[2]), f"{args}: a failed run wrote {args[2]}")

    print(f"vectors oracle: {'ok' if failures == 0 else str(failures) + ' failures'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

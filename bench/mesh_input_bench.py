"""Mesh -> signed distance field: voxfield field MESH --voxel-size V, both as the dense field over
the mesh's box and clamped at 3 voxels (--max-distance 3V: a narrow band like OpenVDB's, every
sample still signed by the winding number), against OpenVDB's meshToLevelSet (pyopenvdb, a narrow
band of 3 voxels, its sign from a flood fill), on the meshes scripts/fetch-test-meshes.sh fetches,
at several voxel sizes, same machine, same run.

Reports for each: samples, each side's time (median of REPEAT; voxfield's from --stats, compute
only; OpenVDB's around its Python call, whose overhead is microseconds), the ratio, and each
side's error against brute force (exact point-triangle distances and the exact winding number's
sign) at 300 random samples of OpenVDB's band.
Usage: mesh_input_bench.py VOXFIELD MESH_DIR [REPEAT] [THREADS]
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import pyopenvdb as vdb

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
import mesh_input_oracle_test as oracle  # noqa: E402  (the readers and the brute-force referee)


def main():
    vf, meshes = sys.argv[1], sys.argv[2]
    repeat = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    threads = sys.argv[4] if len(sys.argv) > 4 else "0"
    cases = [("bunny.obj", 0.02), ("bunny.obj", 0.01), ("bunny.obj", 0.005), ("cow.off", 0.005),
             ("hinge.stl", 0.5)]
    print("| mesh | triangles | voxel | samples | voxfield dense ms | voxfield band ms | OpenVDB band voxels | "
          "OpenVDB ms | dense / OpenVDB | band / OpenVDB | max error voxfield | max error OpenVDB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(2)
    with tempfile.TemporaryDirectory() as work:
        for name, voxel in cases:
            path = os.path.join(meshes, name)
            pts, tris = oracle.READERS[os.path.splitext(name)[1]](path)
            ours_ms, band_ms = [], []
            for _ in range(repeat):
                for extra, times in (([], ours_ms), (["--max-distance", str(3 * voxel)], band_ms)):
                    cmd = [vf, "field", path, "-o", os.path.join(work, "f.npy"), "--voxel-size", str(voxel),
                           "--stats", os.path.join(work, "s.json")] + extra
                    if threads != "0":
                        cmd += ["--threads", threads]
                    subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
                    stats = json.load(open(os.path.join(work, "s.json")))
                    times.append(stats["ms"])
            ours = np.load(os.path.join(work, "f.npy"))  # the clamped one: exact within the band
            vdb_ms = []
            for _ in range(repeat):
                start = time.perf_counter()
                grid = vdb.FloatGrid.createLevelSetFromPolygons(
                    (pts - 0.5 * voxel).astype(np.float32), triangles=tris.astype(np.int32),
                    transform=vdb.createLinearTransform(voxelSize=voxel), halfWidth=3.0)
                vdb_ms.append((time.perf_counter() - start) * 1e3)
            theirs = np.empty(ours.shape, np.float32)
            grid.copyToArray(theirs, ijk=tuple(int(round(f / voxel - 0.5)) for f in stats["first_sample"]))
            band = np.argwhere(np.abs(theirs) < 2.5 * voxel)
            first = np.array(stats["first_sample"])
            err_ours = err_vdb = 0.0
            for i, j, k in band[rng.choice(len(band), 300, replace=False)]:
                p = first + voxel * np.array([i, j, k])
                w = oracle.winding_number(p, pts, tris)
                want = oracle.exact_distance(p, pts, tris) * (-1 if w >= 0.5 else 1)
                err_ours = max(err_ours, abs(ours[i, j, k] - want) / voxel)
                err_vdb = max(err_vdb, abs(theirs[i, j, k] - want) / voxel)
            a, c, b = float(np.median(ours_ms)), float(np.median(band_ms)), float(np.median(vdb_ms))
            print(f"| {name} | {len(tris)} | {voxel} | {ours.size} ({'x'.join(map(str, ours.shape))}) | {a:.0f} | "
                  f"{c:.0f} | {grid.activeVoxelCount()} | {b:.0f} | {a / b:.2f}x | {c / b:.2f}x | {err_ours:.1e} vox | "
                  f"{err_vdb:.2f} vox |", flush=True)


if __name__ == "__main__":
    main()

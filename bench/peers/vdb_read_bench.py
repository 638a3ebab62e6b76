"""Reading .vdb files: voxfield's own parser (voxfield.vdb.read) against OpenVDB's reader
(pyopenvdb.read, OpenVDB 10's io::File) on the same files, in one process; medians of RUNS timed
reads after a warm-up, min-max in brackets. The files are level-set spheres pyopenvdb makes (radius
100 and 250 voxels, narrow band 3) written with OpenVDB's default compression (Blosc with
active-mask compression); before timing, voxfield's values on a slab through the middle are checked
equal to pyopenvdb's copyToArray. Both readers decode every leaf: OpenVDB's delayed loading (leaves
read from a memory map when first touched) is turned off with OPENVDB_DISABLE_DELAYED_LOAD.

Usage: PYTHONPATH=build/release/python /usr/bin/python3 bench/peers/vdb_read_bench.py [RUNS]
"""

import os
import statistics
import sys
import tempfile
import time

import numpy as np

os.environ["OPENVDB_DISABLE_DELAYED_LOAD"] = "1"  # read by io::File::readGrid at each read
import pyopenvdb as openvdb  # noqa: E402

import voxfield.vdb


def timed(f, runs):
    f()
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        ts.append((time.perf_counter() - t) * 1e3)
    return statistics.median(ts), min(ts), max(ts)


def fmt(t):
    return f"{t[0]:8.1f} [{t[1]:.1f}-{t[2]:.1f}]"


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    work = tempfile.mkdtemp(prefix="voxfield-vdb-bench-")
    cases = []
    for radius in (100.0, 250.0):
        g = openvdb.createLevelSetSphere(radius=radius, voxelSize=1.0, halfWidth=3.0)
        g.name = f"sphere{int(radius)}"
        cases.append(g)
    print(f"{'file':28} {'MiB':>6} {'leaves':>8}  {'voxfield ms':>22}  {'OpenVDB ms':>22}  ratio")
    for g in cases:
        path = os.path.join(work, g.name + ".vdb")
        openvdb.write(path, grids=[g])
        (mine,) = voxfield.vdb.read(path)
        lo, hi = g.evalActiveVoxelBoundingBox()
        lo, hi = tuple(lo), tuple(int(v) + 1 for v in hi)
        # A slab through the middle (the whole box of the larger sphere is 1 GB as float64).
        mid = (lo[2] + hi[2]) // 2
        box = ((lo[0], lo[1], mid), (hi[0], hi[1], mid + 1))
        want = np.zeros((hi[0] - lo[0], hi[1] - lo[1], 1), dtype=np.float32)
        g.copyToArray(want, ijk=box[0])
        assert np.array_equal(mine.to_numpy(box), want), g.name
        ours = timed(lambda: voxfield.vdb.read(path), runs)
        theirs = timed(lambda: openvdb.read(path, g.name), runs)
        size = os.path.getsize(path) / 2**20
        print(f"{g.name + '.vdb':28} {size:6.1f} {mine.leaf_count:8d}  {fmt(ours):>22}  "
              f"{fmt(theirs):>22}  {theirs[0] / ours[0]:.2f}x")
        os.remove(path)
    os.rmdir(work)


if __name__ == "__main__":
    main()

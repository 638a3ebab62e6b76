"""voxfield.ndimage against scipy.ndimage in one process, on the same arrays: distance_transform_edt
(distances only, and with indices) and distance_transform_cdt (taxicab), voxfield on 1 and 2
threads; medians of RUNS timed calls after a warm-up, min-max in brackets, and the warm-up call's
own time, started with voxfield's cache of freed voxel arrays emptied (docs/limits.md; glibc may
still hold what the cache handed back, so it is not a fresh process's first call). Checks the results are SciPy's before timing.

Usage: PYTHONPATH=build/release/python /usr/bin/python3 bench/peers/ndimage_bench.py [RUNS] [--voxfield-only]

--voxfield-only times voxfield alone (the results are still checked against SciPy's first): run it
with two builds' PYTHONPATH in turn, alternated, to compare one binding against another.
"""

import os
import statistics
import sys
import time

import numpy as np
from scipy import ndimage as sn

import voxfield
from voxfield import ndimage as vn


def timed(f, runs):
    """(median, min, max, the warm-up call's time) in ms."""
    t = time.perf_counter()
    f()
    first = (time.perf_counter() - t) * 1e3
    ts = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        ts.append((time.perf_counter() - t) * 1e3)
    return statistics.median(ts), min(ts), max(ts), first


def fmt(t):
    return f"{t[0]:.0f} ({t[1]:.0f}–{t[2]:.0f})"


def main():
    args = [a for a in sys.argv[1:] if a != "--voxfield-only"]
    voxfield_only = len(args) != len(sys.argv) - 1
    runs = int(args[0]) if args else 3
    rng = np.random.default_rng(6683787)
    n = 256
    z, y, x = np.ogrid[:n, :n, :n]
    volumes = {
        "random-256 (0.1 % zeros)": rng.random((n, n, n)) < 0.999,
        "spheres-256 (zeros outside 40 balls)": np.zeros((n, n, n), bool),
    }
    for _ in range(40):
        c = rng.integers(20, n - 20, 3)
        r = rng.integers(6, 24)
        volumes["spheres-256 (zeros outside 40 balls)"] |= (z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2 < r * r
    # A real scan: the Colin 27 MRI template that Debian's mricron-data ships (scripts/install-bench-deps.sh),
    # its head (intensity > 0) against the air around it, in the file's own Fortran order.
    mri = "/usr/share/mricron/templates/ch2better.nii.gz"
    if os.path.exists(mri):
        import nibabel
        volumes["mri ch2better 301×370×316 (zeros outside the head, Fortran order)"] = \
            np.asarray(nibabel.load(mri).dataobj) > 0
    if voxfield_only:
        print("| volume | call | voxfield 1 thread ms | voxfield 2 threads ms |")
        print("|---|---|---|---|")
    else:
        print("| volume | call | scipy ms | voxfield 1 thread ms | voxfield 2 threads ms | scipy / voxfield 1 | scipy / voxfield 2 "
              "| voxfield's warm-up call, 1 thread ms |")
        print("|---|---|---|---|---|---|---|---|")
    for name, a in volumes.items():
        cases = [
            ("edt", lambda: sn.distance_transform_edt(a), lambda t: vn.distance_transform_edt(a, threads=t)),
            ("edt + indices", lambda: sn.distance_transform_edt(a, return_indices=True),
             lambda t: vn.distance_transform_edt(a, return_indices=True, threads=t)),
            ("cdt taxicab", lambda: sn.distance_transform_cdt(a, metric="taxicab"),
             lambda t: vn.distance_transform_cdt(a, metric="taxicab", threads=t)),
        ]
        for call, ref, ours in cases:
            want, got = ref(), ours(None)
            w0 = want[0] if isinstance(want, tuple) else want
            g0 = got[0] if isinstance(got, tuple) else got
            assert np.array_equal(w0, g0), f"{name} {call}: results differ"
            s = None if voxfield_only else timed(ref, runs)
            # The warm-up call below starts without cached arrays (a build before the cache has none).
            getattr(voxfield, "trim_chunk_cache", lambda: None)()
            v1 = timed(lambda: ours(1), runs)
            v2 = timed(lambda: ours(2), runs)
            if voxfield_only:
                print(f"| {name} | {call} | {fmt(v1)} | {fmt(v2)} |", flush=True)
                continue
            print(f"| {name} | {call} | {fmt(s)} | {fmt(v1)} | {fmt(v2)} | {s[0] / v1[0]:.1f}× | {s[0] / v2[0]:.1f}× "
                  f"| {v1[3]:.0f} |", flush=True)


if __name__ == "__main__":
    main()

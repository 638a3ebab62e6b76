# Usage: PYTHONPATH=build/release/python /usr/bin/python3 bench/peers/ndimage_overhead.py
"""voxfield.ndimage's own cost around the transform: a tiny array (fixed cost per call), and a
256^3 / MRI volume with the float64 output allocated by the call (fresh pages) or passed in
(distances=, already touched)."""
import time, statistics, numpy as np, nibabel
from voxfield import ndimage as vn
def t(f, n):
    f(); ts = []
    for _ in range(n):
        s = time.perf_counter(); f(); ts.append((time.perf_counter() - s) * 1e3)
    return statistics.median(ts), min(ts)
tiny = np.ones((4, 4, 4), bool); tiny[1, 2, 3] = False
print("tiny 4^3 call: median %.3f ms, min %.3f ms" % t(lambda: vn.distance_transform_edt(tiny, threads=1), 2000))
rng = np.random.default_rng(6683787)
vols = {"random-256": rng.random((256, 256, 256)) < 0.999,
        "mri": np.asarray(nibabel.load("/usr/share/mricron/templates/ch2better.nii.gz").dataobj) > 0}
for name, a in vols.items():
    out = np.empty(a.shape, np.float64); out.fill(1.0)
    for rep in range(2):
        fresh = t(lambda: vn.distance_transform_edt(a, threads=1), 5)
        given = t(lambda: vn.distance_transform_edt(a, threads=1, distances=out), 5)
        print(f"{name}: output allocated by the call {fresh[0]:.0f} (min {fresh[1]:.0f}) ms; passed in {given[0]:.0f} (min {given[1]:.0f}) ms")

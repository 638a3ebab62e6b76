#!/usr/bin/env python3
"""Marching cubes by voxfield's peers on one volume: scikit-image's marching_cubes (Lewiner et
al.'s table, one thread) and VTK's vtkFlyingEdges3D (Schroeder et al. 2015, multi-threaded), when
installed (Debian python3-skimage, python3-vtk9). Writes one JSON object: for each peer found,
the best time of RUNS in ms, its triangle and vertex counts and the thread count.

Usage: mesh_peers.py VOLUME.npy LEVEL --runs N --json OUT.json
"""
import argparse
import json
import os
import time

import numpy as np

parser = argparse.ArgumentParser()
parser.add_argument("volume")
parser.add_argument("level", type=float)
parser.add_argument("--runs", type=int, default=3)
parser.add_argument("--json", required=True)
args = parser.parse_args()

vol = np.load(args.volume).astype(np.float32)
result = {"volume": os.path.basename(args.volume), "shape": list(vol.shape), "level": args.level}


def best(run):
    times, out = [], None
    for _ in range(args.runs):
        t0 = time.perf_counter()
        out = run()
        times.append((time.perf_counter() - t0) * 1e3)
    return min(times), out


try:
    from skimage.measure import marching_cubes

    ms, (verts, faces, _, _) = best(lambda: marching_cubes(vol, level=args.level))
    result["scikit-image"] = {"ms": ms, "triangles": int(len(faces)), "vertices": int(len(verts)), "threads": 1,
                              "version": __import__("skimage").__version__}
except ImportError:
    result["scikit-image"] = None

try:
    import vtk
    from vtk.util import numpy_support

    image = vtk.vtkImageData()
    image.SetDimensions(*vol.shape)
    # VTK's point order is x fastest: a[x, y, z] in Fortran order.
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(vol.ravel(order="F"), deep=True))
    threads = os.cpu_count()

    def flying_edges():
        fe = vtk.vtkFlyingEdges3D()
        fe.SetInputData(image)
        fe.SetValue(0, args.level)
        fe.ComputeNormalsOff()
        fe.Update()
        return fe.GetOutput()

    vtk.vtkSMPTools.Initialize(threads)
    ms, poly = best(flying_edges)
    result["vtk-flying-edges"] = {"ms": ms, "triangles": int(poly.GetNumberOfPolys()), "vertices": int(poly.GetNumberOfPoints()),
                                  "threads": threads, "version": vtk.vtkVersion.GetVTKVersion()}
except ImportError:
    result["vtk-flying-edges"] = None

with open(args.json, "w") as f:
    json.dump(result, f, indent=1)

#!/usr/bin/env python3
"""Whether two binary PLY meshes that voxfield wrote hold the same triangles, bit for bit, however
their vertices are numbered: each triangle as its three corners' positions and normals (float
bits), rotated to start at its smallest corner (so the winding counts), the lists sorted and
compared. Prints the triangle counts; exit status 0 when equal, 1 when not.

Usage: /usr/bin/python3 scripts/same_triangles.py A.ply B.ply
"""
import sys

import numpy as np


def triangles(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    head = data[:end].decode().split("\n")
    nv = int(next(l for l in head if l.startswith("element vertex")).split()[2])
    nf = int(next(l for l in head if l.startswith("element face")).split()[2])
    props = [l.split()[-1] for l in head if l.startswith("property")]
    fields = [("p", "<f4", 3), ("n", "<f4", 3)]
    if props == ["x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "vertex_indices"]:
        fields.append(("c", "u1", 3))
    elif props != ["x", "y", "z", "nx", "ny", "nz", "vertex_indices"]:
        raise SystemExit(f"{path}: not a vertex layout voxfield writes: {props}")
    vert = np.dtype(fields)
    verts = np.frombuffer(data, vert, nv, end)
    faces = np.frombuffer(data, np.dtype([("k", "u1"), ("i", "<u4", 3)]), nf, end + nv * vert.itemsize)
    if not (faces["k"] == 3).all():
        raise SystemExit(f"{path}: a face that is not a triangle")
    corners = np.concatenate([verts["p"][faces["i"]], verts["n"][faces["i"]]], axis=2)
    return np.ascontiguousarray(corners).view(np.uint32).reshape(nf, 3, 6)


def canonical(corners, ids):
    """Each triangle as its corners' ids, rotated to start at the smallest (the winding kept), the
    rows sorted."""
    t = ids.reshape(-1, 3)
    k = np.argmin(t, axis=1)
    t = t[np.arange(len(t))[:, None], (k[:, None] + np.arange(3)) % 3]
    return t[np.lexsort(t.T[::-1])]


a, b = triangles(sys.argv[1]), triangles(sys.argv[2])
# One id per distinct corner (position and normal) over both meshes, in lexicographic order of its
# float bits.
corners = np.concatenate([a.reshape(-1, 6), b.reshape(-1, 6)])
order = np.lexsort(corners.T[::-1])
ordered = corners[order]
first = np.ones(len(ordered), bool)
first[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
ids = np.empty(len(ordered), np.int64)
ids[order] = np.cumsum(first) - 1
ta, tb = canonical(a, ids[: 3 * len(a)]), canonical(b, ids[3 * len(a):])
same = len(ta) == len(tb) and bool((ta == tb).all())
print(f"{len(a)} and {len(b)} triangles, {'the same' if same else 'different'}")
sys.exit(0 if same else 1)

"""voxfield.mesh's meshes in (docs/mesh_input.md) against oracles written here from their
definitions: the files written by NumPy, Van Oosterom & Strackee's solid angle summed in NumPy for
the winding number, the analytic distance to a box (rotated, so no face lies on the lattice), and
the CLI's own output for the same file.

Run by CTest with PYTHONPATH pointing at the build's python/ directory (and VOXFIELD naming the CLI).
"""

import os
import struct
import subprocess

import numpy as np
import pytest

import voxfield
from voxfield import mesh as vm

from gil import ticks_during

# A box [0, 2] x [0, 1.5] x [0, 1], its faces counter-clockwise seen from outside.
BOX_HALF = np.array([1.0, 0.75, 0.5])
BOX_FACES = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                      [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])


def box_vertices(rotation=np.eye(3), offset=np.zeros(3)):
    corners = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    return (corners * 2 * BOX_HALF) @ rotation.T + offset


def rotation(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def box_sdf(points, rot, offset):
    # Points into the box's frame (centred), then the exact distance to a box.
    local = (points - offset) @ rot - BOX_HALF
    q = np.abs(local) - BOX_HALF
    return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)


def solid_angle_winding(vertices, faces, points):
    # Van Oosterom & Strackee (1983): tan(omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| +
    # (b.c)|a| + (c.a)|b|), summed over the triangles, over 4 pi.
    a, b, c = (vertices[faces[:, k]][None, :, :] - points[:, None, :] for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
    num = np.einsum("pti,pti->pt", a, np.cross(b, c))
    den = (la * lb * lc + np.einsum("pti,pti->pt", a, b) * lc + np.einsum("pti,pti->pt", b, c) * la
           + np.einsum("pti,pti->pt", c, a) * lb)
    return (2 * np.arctan2(num, den)).sum(axis=1) / (4 * np.pi)


def centres(first, shape, voxel_size):
    i, j, k = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    # Fortran order, as the arrays are laid out: i fastest.
    idx = np.stack([i.ravel(order="F"), j.ravel(order="F"), k.ravel(order="F")], axis=1)
    return (np.array(first) + idx + 0.5) * voxel_size


def write_files(tmp_path, vertices, faces):
    paths = {}
    obj = tmp_path / "m.obj"
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices)
                   + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))
    paths["obj"] = obj
    off = tmp_path / "m.off"
    off.write_text(f"OFF\n{len(vertices)} {len(faces)} 0\n"
                   + "".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in vertices)
                   + "".join(f"3 {a} {b} {c}\n" for a, b, c in faces))
    paths["off"] = off
    ply = tmp_path / "m.ply"
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
              "property double x\nproperty double y\nproperty double z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    body = b"".join(struct.pack("<3d", *v) for v in vertices)
    body += b"".join(struct.pack("<B3i", 3, *f) for f in faces)
    ply.write_bytes(header.encode() + body)
    paths["ply"] = ply
    stl = tmp_path / "m.stl"  # binary STL: float32 corners, repeated per triangle
    tris = b"".join(struct.pack("<12fH", 0, 0, 0, *vertices[f].astype(np.float32).ravel(), 0) for f in faces)
    stl.write_bytes(b"voxfield test".ljust(80, b" ") + struct.pack("<I", len(faces)) + tris)
    paths["stl"] = stl
    return paths


def corner_triangles(vertices, faces):
    # Each triangle as its corners' positions, rotated to start at the smallest (orientation kept).
    out = []
    for f in faces:
        corners = [tuple(np.round(vertices[i], 6)) for i in f]
        k = corners.index(min(corners))
        out.append(tuple(corners[k:] + corners[:k]))
    return sorted(out)


def test_every_format_reads_back_what_was_written(tmp_path):
    vertices = box_vertices(rotation(1), np.array([0.3, -0.2, 0.1]))
    paths = write_files(tmp_path, vertices, BOX_FACES)
    want = corner_triangles(vertices, BOX_FACES)
    for name, path in paths.items():
        v, f = vm.read_mesh(path)
        assert v.dtype == np.float64 and f.dtype == np.uint32 and v.shape[1] == 3 and f.shape == (12, 3)
        if name == "stl":  # float32 corners, merged where they repeat
            assert len(v) == 8
            assert corner_triangles(v, f) == corner_triangles(vertices.astype(np.float32).astype(np.float64), BOX_FACES)
        else:
            np.testing.assert_array_equal(v, vertices)
            np.testing.assert_array_equal(f, BOX_FACES)
            assert corner_triangles(v, f) == want
    # str paths as well as os.PathLike.
    assert vm.read_mesh(str(paths["obj"]))[0].shape == (8, 3)


def test_malformed_and_missing_files_are_named(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n")
    with pytest.raises(voxfield.FormatError, match=r"bad\.obj: at byte 22: the face names vertex 3"):
        vm.read_mesh(bad)
    with pytest.raises(OSError, match="nothing.stl"):
        vm.read_mesh(tmp_path / "nothing.stl")
    with pytest.raises(ValueError, match=r"m\.xyz: not a mesh file"):
        vm.read_mesh(tmp_path / "m.xyz")


def test_winding_numbers_equal_the_solid_angle_sum():
    rng = np.random.default_rng(2)
    rot, offset = rotation(3), np.array([0.5, 0.25, -0.3])
    vertices = box_vertices(rot, offset)
    # Points in and around the box, in its frame first.
    points = (rng.uniform(-1.4, 1.4, (400, 3)) * BOX_HALF + BOX_HALF) @ rot.T + offset
    closed = vm.WindingNumber(vertices, BOX_FACES)
    want = solid_angle_winding(vertices, BOX_FACES, points)
    np.testing.assert_allclose(closed.exact(points), want, atol=1e-9)
    # Closed: 1 inside and 0 outside, which the analytic box tells apart.
    inside = box_sdf(points, rot, offset) < 0
    np.testing.assert_allclose(want, inside.astype(float), atol=1e-9)
    np.testing.assert_array_equal(closed.inside(points), inside)
    # The hierarchy's far-field terms: within docs/mesh_input.md's measured 0.061 of a turn.
    assert np.abs(closed(points) - want).max() < 0.07
    # A box without its top: values in between near the opening, and still the solid angle sum.
    open_faces = BOX_FACES[[0, 1, 4, 5, 6, 7, 8, 9, 10, 11]]
    holed = vm.WindingNumber(vertices, open_faces, accuracy=4.0)
    want = solid_angle_winding(vertices, open_faces, points)
    np.testing.assert_allclose(holed.exact(points), want, atol=1e-9)
    assert ((want > 0.1) & (want < 0.9)).sum() > 20
    sure = np.abs(want - 0.5) > 0.25
    np.testing.assert_array_equal(holed.inside(points)[sure], (want >= 0.5)[sure])
    assert "triangles=10" in repr(holed) and "accuracy=4.0" in repr(holed)


def test_voxels_are_the_centres_inside():
    rot, offset = rotation(4), np.array([0.1, 0.2, 0.3])
    vertices = box_vertices(rot, offset)
    for voxel_size, padding in ((0.125, 2), (0.2, 0)):
        materials, first = vm.voxelize_mesh(vertices, BOX_FACES, voxel_size, padding=padding, material=7)
        assert materials.dtype == np.uint8 and materials.flags["F_CONTIGUOUS"]
        # The box: the mesh's bounds grown by `padding` voxels.
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        p = centres(first, materials.shape, voxel_size)
        assert (p.min(axis=0) <= lo + (padding + 1) * voxel_size).all()
        assert (p.max(axis=0) >= hi - voxel_size).all()
        d = box_sdf(p, rot, offset)
        got = materials.ravel(order="F")
        clear = np.abs(d) > 1e-9  # no centre exactly on a face
        np.testing.assert_array_equal(got[clear], np.where(d[clear] < 0, 7, 0))
        assert set(np.unique(got)) == {0, 7}


def test_distance_fields_are_the_boxs_within_the_band_and_bounded_beyond():
    rot, offset = rotation(5), np.array([-0.2, 0.4, 0.05])
    vertices = box_vertices(rot, offset)
    voxel_size, band = 0.1, 3.0
    values, first = vm.mesh_distance_field(vertices, BOX_FACES, voxel_size, padding=12, band=band)
    assert values.dtype == np.float32 and values.flags["F_CONTIGUOUS"]
    p = centres(first, values.shape, voxel_size)
    want = box_sdf(p, rot, offset)
    got = values.ravel(order="F").astype(np.float64)
    near = np.abs(want) <= (band - 1) * voxel_size
    assert near.sum() > 1000 and (~near).sum() > 1000
    np.testing.assert_allclose(got[near], want[near], atol=2e-6)
    # Beyond the band: never below the true distance (the sign as the box's), and within a few
    # hundredths of a voxel of it (docs/mesh_input.md).
    far = ~near
    assert (np.sign(got[far]) == np.sign(want[far])).all()
    err = np.abs(got[far]) - np.abs(want[far])
    assert err.min() > -2e-6 and err.max() < 0.05 * voxel_size
    # Unsigned, and clamped: a narrow band whose far samples read the clamp.
    unsigned, f2 = vm.mesh_distance_field(vertices, BOX_FACES, voxel_size, padding=12, signed=False)
    assert f2 == first
    np.testing.assert_array_equal(unsigned, np.abs(values))
    clamped, _ = vm.mesh_distance_field(vertices, BOX_FACES, voxel_size, padding=12, max_distance=0.15)
    c = clamped.ravel(order="F").astype(np.float64)
    inner = np.abs(want) < 0.15 - 1e-6
    np.testing.assert_allclose(c[inner], want[inner], atol=2e-6)
    np.testing.assert_array_equal(np.abs(c[~inner]) <= 0.15 + 1e-6, True)
    np.testing.assert_array_equal(np.sign(c[np.abs(want) > 1e-3]), np.sign(want[np.abs(want) > 1e-3]))


def test_the_cli_gives_the_same_field_for_the_same_file(tmp_path):
    cli = os.environ.get("VOXFIELD")
    if not cli:
        pytest.skip("VOXFIELD (the CLI) not given")
    vertices = box_vertices(rotation(6), np.array([0.3, 0.1, -0.4]))
    path = write_files(tmp_path, vertices, BOX_FACES)["stl"]
    subprocess.run([cli, "field", str(path), "-o", str(tmp_path / "f.npy"), "--voxel-size", "0.125"],
                   check=True, capture_output=True)
    theirs = np.load(tmp_path / "f.npy")
    ours, _ = vm.mesh_distance_field(*vm.read_mesh(path), 0.125)
    assert theirs.shape == ours.shape
    np.testing.assert_array_equal(theirs, ours)


def test_bad_arguments_are_refused_by_name():
    vertices = box_vertices()
    with pytest.raises(voxfield.InvalidArgument, match=r"faces\[3\] names vertex 8 of 8"):
        vm.WindingNumber(vertices, np.where(np.arange(36).reshape(12, 3) == 9, 8, BOX_FACES))
    with pytest.raises(voxfield.InvalidArgument, match="names vertex -1"):
        vm.voxelize_mesh(vertices, -np.ones((1, 3), int), 0.5)
    nan = vertices.copy()
    nan[2, 1] = np.nan
    with pytest.raises(voxfield.InvalidArgument, match="finite"):
        vm.mesh_distance_field(nan, BOX_FACES, 0.5)
    with pytest.raises(voxfield.InvalidArgument, match=r"\(N, 3\)"):
        vm.WindingNumber(vertices[:, :2], BOX_FACES)
    with pytest.raises(voxfield.InvalidArgument):
        vm.voxelize_mesh(vertices, BOX_FACES, 0.0)
    with pytest.raises(voxfield.InvalidArgument, match="material"):
        vm.voxelize_mesh(vertices, BOX_FACES, 0.5, material=0)
    with pytest.raises(voxfield.InvalidArgument):
        vm.mesh_distance_field(vertices, BOX_FACES, 0.5, band=0.5)
    with pytest.raises(voxfield.InvalidArgument):
        vm.voxelize_mesh(vertices, np.zeros((0, 3), int), 0.5)  # an empty mesh has no box


def test_fields_release_the_gil():
    # A fine lattice (some 10^6 voxels) around the box: long enough for another thread to run.
    vertices = box_vertices(rotation(8))
    elapsed, ticks = ticks_during(
        lambda: vm.mesh_distance_field(vertices, BOX_FACES, 0.01, band=2, threads=1))
    # A call holding the GIL lets the other thread tick once at most (when it returns).
    assert elapsed > 0.05 and ticks >= 10, (elapsed, ticks)

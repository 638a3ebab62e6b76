"""voxfield.mesh against scikit-image's marching_cubes, the analytic surface, the CLI and the terrain
field's own definition (docs/meshing.md).

Run by CTest with PYTHONPATH pointing at the build's python/ directory (and VOXFIELD naming the CLI).
"""

import os
import subprocess

import numpy as np
import pytest

import voxfield
from voxfield import mesh as vm

from gil import ticks_during


def sphere_sdf(shape, centre, radius, dtype=np.float32):
    x, y, z = np.meshgrid(*(np.arange(n, dtype=np.float64) for n in shape), indexing="ij")
    return (np.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2) - radius).astype(dtype)


def triangle_set(vertices, faces):
    # Each triangle as its corners' positions, rotated to start at the smallest (orientation kept).
    out = []
    for f in faces:
        corners = [tuple(vertices[i]) for i in f]
        k = corners.index(min(corners))
        out.append(tuple(corners[k:] + corners[:k]))
    return sorted(out)


def signed_volume(vertices, faces):
    a, b, c = (vertices[faces[:, k]].astype(np.float64) for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def test_a_sphere_is_close_to_the_true_one_and_faces_out():
    v = sphere_sdf((40, 36, 30), (20.3, 17.6, 14.9), 10.2)
    for algorithm in ("mc", "sn", "dc"):
        verts, faces, normals = vm.mesh_volume(v, algorithm=algorithm)
        assert verts.dtype == np.float32 and faces.dtype == np.uint32 and normals.dtype == np.float32
        assert verts.shape[1] == 3 and faces.shape[1] == 3 and normals.shape == verts.shape
        r = np.linalg.norm(verts - np.array([20.3, 17.6, 14.9]), axis=1)
        assert np.abs(r - 10.2).max() < (0.03 if algorithm == "mc" else 0.15), algorithm
        assert signed_volume(verts, faces) == pytest.approx(4 / 3 * np.pi * 10.2 ** 3, rel=0.02)
        # Normals point out: along the radius.
        radial = (verts - np.array([20.3, 17.6, 14.9])) / r[:, None]
        assert (np.einsum("ij,ij->i", radial, normals) > 0.9).mean() > 0.99


def test_beside_scikit_image():
    measure = pytest.importorskip("skimage.measure")
    rng = np.random.default_rng(4)
    from scipy.ndimage import gaussian_filter
    noise = gaussian_filter(rng.standard_normal((48, 40, 36)), 2.5).astype(np.float32)
    for volume, level in ((sphere_sdf((40, 36, 30), (20, 18, 15), 9.7), 0.0), (noise, 0.01)):
        verts, faces, _ = vm.mesh_volume(volume, level=level, spacing=(1.0, 1.5, 2.0))
        theirs, their_faces, _, _ = measure.marching_cubes(volume, level=level, spacing=(1.0, 1.5, 2.0))
        assert abs(len(faces) - len(their_faces)) <= 0.01 * len(their_faces)
        # Every vertex of ours lies on their surface: at most a fraction of a cell from their nearest.
        from scipy.spatial import cKDTree
        distance, _ = cKDTree(theirs).query(verts)
        assert np.quantile(distance, 0.99) < 0.5 and distance.max() < 1.5


def test_order_dtype_chunks_and_threads_do_not_change_the_mesh():
    v = sphere_sdf((33, 29, 25), (16, 14, 12), 8.4)
    want = vm.mesh_volume(np.asfortranarray(v))
    # C order and float64 are converted once; the values are the same, so is the mesh.
    for variant in (np.ascontiguousarray(v), v.astype(np.float64), np.ascontiguousarray(v.astype(np.float64))):
        for a, b in zip(vm.mesh_volume(variant), want):
            np.testing.assert_array_equal(a, b)
    for a, b in zip(vm.mesh_volume(v, threads=1), want):
        np.testing.assert_array_equal(a, b)
    # Another chunk edge numbers the vertices in another order; the triangles are the same.
    assert triangle_set(*vm.mesh_volume(v, chunk=5)[:2]) == triangle_set(*want[:2])
    # Densities: inside above the level is the same surface.
    for a, b in zip(vm.mesh_volume(-v, inside="above"), want):
        np.testing.assert_array_equal(a, b)


@pytest.mark.skipif(not os.environ.get("VOXFIELD"), reason="needs the voxfield CLI")
def test_equals_the_cli(tmp_path):
    v = sphere_sdf((30, 28, 26), (15, 14, 13), 7.7)
    np.save(tmp_path / "v.npy", v)
    for algorithm in ("mc", "dc"):
        subprocess.run([os.environ["VOXFIELD"], "mesh", str(tmp_path / "v.npy"), "-o", str(tmp_path / "m.ply"),
                        "--algorithm", algorithm, "--stats", str(tmp_path / "s.json")], check=True,
                       capture_output=True)
        import json
        stats = json.load(open(tmp_path / "s.json"))
        verts, faces, _ = vm.mesh_volume(v, algorithm=algorithm)
        assert (stats["vertices"], stats["triangles"]) == (len(verts), len(faces))


def test_terrain_brushes_follow_their_formula():
    n = (30, 26, 22)
    t = vm.Terrain(n, storage="f32", spacing=0.5, origin=(1.0, -2.0, 0.0))
    assert "storage='f32'" in repr(t) and t.samples == n and t.step == 0.0
    x, y, z = np.meshgrid(*(np.arange(k, dtype=np.float64) for k in n), indexing="ij")
    px, py, pz = 1.0 + 0.5 * x, -2.0 + 0.5 * y, 0.5 * z
    ground = pz - 5.0
    t.assign(ground, material=2)
    clamp = t.max_distance
    before = np.clip(ground, -clamp, clamp).astype(np.float32)
    np.testing.assert_array_equal(t.values(), before)
    # A smooth sphere added: the polynomial smooth minimum of the stored values and the sphere.
    k = 0.8
    b = np.sqrt((px - 8.0) ** 2 + (py - 3.0) ** 2 + (pz - 5.0) ** 2) - 2.5
    d = before.astype(np.float64)
    h = np.maximum(k - np.abs(d - b), 0) / k
    want = np.clip(np.minimum(d, b) - h * h * k / 4, -clamp, clamp).astype(np.float32)
    changed = t.apply("sphere", "add", centre=(8.0, 3.0, 5.0), radius=2.5, smooth=k, material=9)
    np.testing.assert_array_equal(t.values(), want)
    np.testing.assert_array_equal(t.materials(), np.where(b < d, 9, 2))
    moved = np.argwhere((want != before) | (b < d))
    assert changed == (tuple(int(c) for c in moved.min(0)), tuple(int(c) + 1 for c in moved.max(0)))
    # A brush far outside changes nothing.
    assert t.apply("box", "subtract", centre=(500.0, 0.0, 0.0), half_extents=(1.0, 1.0, 1.0)) is None


def test_terrain_meshes_with_colours_and_storage_widths():
    palette = np.zeros((256, 3), np.uint8)
    palette[2] = (90, 70, 50)
    palette[9] = (20, 200, 40)
    sizes = {}
    for storage in ("i8", "i16", "f32"):
        t = vm.Terrain((40, 40, 24), storage=storage, palette=palette)
        x, y, z = np.meshgrid(*(np.arange(k, dtype=np.float32) for k in (40, 40, 24)), indexing="ij")
        t.assign(z - 10 - 2 * np.sin(x / 5), material=2)
        t.apply("capsule", "add", centre=(10.0, 20.0, 10.0), end=(30.0, 20.0, 12.0), radius=3.0, material=9)
        verts, faces, normals, colors = t.mesh()
        assert colors.shape == verts.shape and colors.dtype == np.uint8
        seen = {tuple(c) for c in np.unique(colors, axis=0)}
        assert seen == {(90, 70, 50), (20, 200, 40)}, (storage, seen)
        sizes[storage] = t.memory["bytes"]
    assert sizes["i8"] < sizes["i16"] < sizes["f32"]


def test_bad_arguments_raise_value_errors():
    with pytest.raises(ValueError, match="NaN"):
        vm.mesh_volume(np.full((4, 4, 4), np.nan, np.float32))
    with pytest.raises(ValueError, match="3-D"):
        vm.mesh_volume(np.zeros((4, 4), np.float32))
    with pytest.raises(ValueError, match="inside"):
        vm.mesh_volume(np.zeros((4, 4, 4), np.float32), inside="sideways")
    with pytest.raises(ValueError, match="unknown mesher"):
        vm.mesh_volume(np.zeros((4, 4, 4), np.float32), algorithm="xx")
    t = vm.Terrain((8, 8, 8))
    with pytest.raises(ValueError, match="shape"):
        t.apply("cone", centre=(1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="second end"):
        t.apply("capsule", centre=(1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="radius"):
        t.apply("sphere", centre=(1.0, 1.0, 1.0), radius=-1.0)
    with pytest.raises(ValueError, match="cannot fill"):
        t.assign(np.zeros((8, 8, 7), np.float32))
    with pytest.raises(ValueError, match="palette"):
        vm.Terrain((8, 8, 8), palette=np.zeros((10, 3), np.uint8))
    with pytest.raises(voxfield.InvalidArgument, match="storage"):
        vm.Terrain((8, 8, 8), storage="i32")


def test_the_gil_is_released_while_meshing():
    v = np.random.default_rng(2).standard_normal((150, 150, 150)).astype(np.float32)  # a surface in every cell
    elapsed, during = ticks_during(lambda: vm.mesh_volume(v, threads=1))
    assert elapsed > 0.02 and during >= 10, (elapsed, during)


def test_a_terrain_shared_by_threads():
    # Brushes from one thread while another meshes and reads: each call sees the terrain before or
    # after a brush, never during one (the binding's lock), and the end state is every brush's.
    import threading
    n = (48, 48, 24)
    t = vm.Terrain(n, storage="i16")
    z = np.broadcast_to(np.arange(n[2], dtype=np.float32), n)
    t.assign(z - 8.0, material=1)
    reference = vm.Terrain(n, storage="i16")
    reference.assign(z - 8.0, material=1)
    centres = [(4.0 + 0.8 * i, 24.0 + 10 * np.sin(i / 4), 8.0) for i in range(50)]
    errors = []

    meshing = threading.Event()

    def brushes():
        try:
            meshing.wait()  # the brushes start as the first mesh does: the two overlap
            for c in centres:
                t.apply("sphere", "subtract", centre=c, radius=3.0, smooth=1.0)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    worker = threading.Thread(target=brushes)
    worker.start()
    meshes = 0
    while True:  # at least one mesh, however fast the brushes are (they raced ahead before)
        meshing.set()
        verts, faces, _, _ = t.mesh()
        assert faces.max() < len(verts)
        assert t.values().shape == n
        meshes += 1
        if not worker.is_alive():
            break
    worker.join()
    assert not errors and meshes > 0
    for c in centres:
        reference.apply("sphere", "subtract", centre=c, radius=3.0, smooth=1.0)
    np.testing.assert_array_equal(t.values(), reference.values())

"""World frames against OpenVDB's own transforms (pyopenvdb, Debian python3-openvdb).

A .vdb grid with a rotated, anisotropic, displaced transform loads as a World whose frame puts
every voxel centre where OpenVDB's indexToWorld does; voxfield's own .vdb and .vfw files keep the
frame; a framed world's mesh is its voxel-space mesh carried into the frame; bad frames raise
ValueError and leave the frame as it was.

Run by CTest with PYTHONPATH pointing at the build's python/ directory.
"""

import math
import warnings

import numpy as np
import pyopenvdb as openvdb
import pytest

from voxfield.world import World, mesh, render


def rotation_about(degrees, axis):
    """Rodrigues' formula, written here from the definition."""
    u = np.asarray(axis, dtype=float)
    u = u / np.linalg.norm(u)
    a = math.radians(degrees)
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + math.sin(a) * k + (1 - math.cos(a)) * (k @ k)


ROTATION = rotation_about(25.0, (1.0, 2.0, -0.5))
SIZE = np.array([0.5, 0.25, 2.0])
TRANSLATION = np.array([10.0, -3.5, 100.0])  # where index (0, 0, 0)'s centre lands


def framed_vdb(path):
    """A bool grid of a small blob under a rotated, anisotropic, displaced transform."""
    grid = openvdb.BoolGrid(background=False)
    grid.name = "blob"
    linear = ROTATION * SIZE  # column a scaled by SIZE[a]: world = linear @ ijk + TRANSLATION
    matrix = [list(linear[:, 0]) + [0.0], list(linear[:, 1]) + [0.0], list(linear[:, 2]) + [0.0],
              list(TRANSLATION) + [1.0]]
    grid.transform = openvdb.createLinearTransform(matrix)
    acc = grid.getAccessor()
    for i in range(-4, 5):
        for j in range(-4, 5):
            for k in range(-3, 4):
                if i * i + j * j + 2 * k * k <= 14:
                    acc.setValueOn((i, j, k), True)
    openvdb.write(str(path), grids=[grid])
    return grid


def test_a_vdb_transform_becomes_the_worlds_frame(tmp_path):
    grid = framed_vdb(tmp_path / "blob.vdb")
    world = World.load(str(tmp_path / "blob.vdb"))
    np.testing.assert_allclose(world.voxel_size_world, SIZE, rtol=1e-12)
    np.testing.assert_allclose(world.rotation, ROTATION, atol=1e-12)
    ijk = np.array([[0, 0, 0], [3, -2, 1], [-4, 4, -3], [17, 5, -9]])
    want = np.array([grid.transform.indexToWorld(tuple(int(v) for v in p)) for p in ijk])
    np.testing.assert_allclose(world.to_world(ijk + 0.5), want, atol=1e-9)
    np.testing.assert_allclose(world.to_voxels(want), ijk + 0.5, atol=1e-9)
    assert world.solid_count == grid.activeVoxelCount()


def test_voxfields_own_files_keep_the_frame(tmp_path):
    framed_vdb(tmp_path / "blob.vdb")
    world = World.load(str(tmp_path / "blob.vdb"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # .vfw keeps the frame: nothing to say
        world.save(str(tmp_path / "blob.vfw"))
    back = World.load(str(tmp_path / "blob.vfw"))
    assert back.origin_world == world.origin_world  # doubles, stored as doubles
    assert back.voxel_size_world == world.voxel_size_world
    np.testing.assert_array_equal(back.rotation, world.rotation)
    # pyopenvdb cannot open Int32 grids (test_vdb.cpp checks OpenVDB's own transform of them): the
    # .vdb is read back by voxfield, and the voxels' centres compared.
    world.save(str(tmp_path / "again.vdb"))
    again = World.load(str(tmp_path / "again.vdb"))
    ijk = np.array([[0, 0, 0], [2, 1, -1], [-30, 12, 7]]) + 0.5
    np.testing.assert_allclose(again.to_world(ijk), world.to_world(ijk), atol=1e-9)
    assert again.solid_count == world.solid_count
    # A .npy has nowhere to put the frame: said, and the voxels written all the same.
    with pytest.warns(UserWarning, match="blob.npy keeps no frame"):
        world.save(str(tmp_path / "blob.npy"))
    assert World.load(str(tmp_path / "blob.npy")).solid_count == world.solid_count
    # Warnings raised as errors: the save fails before writing, and the old file stays.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="keeps no frame"):
            world.save(str(tmp_path / "never.npy"))
    assert not (tmp_path / "never.npy").exists()


def normal_agreement(vertices, faces, normals):
    """The median cosine between each triangle's normal and the mean of its vertex normals."""
    a, b, c = (vertices[faces[:, i]].astype(np.float64) for i in range(3))
    face = np.cross(b - a, c - a)
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    vertex = normals[faces].astype(np.float64).mean(axis=1)
    vertex /= np.linalg.norm(vertex, axis=1, keepdims=True)
    return np.median(np.einsum("ij,ij->i", face, vertex))


def test_a_framed_worlds_mesh_is_its_voxel_mesh_in_the_frame(tmp_path):
    framed_vdb(tmp_path / "blob.vdb")
    framed = World.load(str(tmp_path / "blob.vdb"))
    plain = World.load(str(tmp_path / "blob.vdb"))
    plain.origin_world = (0.0, 0.0, 0.0)
    plain.voxel_size_world = (1.0, 1.0, 1.0)
    plain.rotation = np.eye(3)
    v_world, f_world, n_world, _ = mesh(framed)
    v_vox, f_vox, n_vox, _ = mesh(plain)
    np.testing.assert_array_equal(f_world, f_vox)  # the same triangles, the same winding
    np.testing.assert_allclose(v_world, framed.to_world(v_vox.astype(np.float64)), atol=1e-4)
    # Normals: perpendicular to the carried triangles, still unit. The voxel surface is flat
    # between edges: each face's vertex normals agree with the face.
    assert normal_agreement(v_world, f_world, n_world) > 0.99
    np.testing.assert_allclose(np.linalg.norm(n_world, axis=1), 1.0, atol=1e-5)
    # An offset surface is round, its normals in every direction: carried by the map itself (not
    # its inverse transpose) they would lean off the anisotropic surface (median 0.42).
    assert normal_agreement(*mesh(framed, iso=2.0)[:3]) > 0.98


def test_a_camera_in_the_worlds_frame_draws_the_same_camera_in_voxels():
    rng = np.random.default_rng(5)
    voxels = (rng.random((24, 20, 12)) < 0.2).astype(np.uint8) * 3
    world = World(voxels)
    world.origin_world = (100.0, -50.0, 3.0)
    world.voxel_size_world = (0.25, 0.25, 0.25)
    by_hand = render(world, 96, 64, camera="eye=40,-12,30:target=12,10,5", shadows=False)
    # Voxel v lies at (100, -50, 3) + v / 4.
    placed = render(world, 96, 64, camera="eye=110,-53,10.5:target=103,-47.5,4.25", shadows=False,
                    camera_frame="world")
    np.testing.assert_array_equal(placed, by_hand)
    assert len(np.unique(by_hand.reshape(-1, 3), axis=0)) > 20  # voxels in view, not sky alone
    # Voxels that are not cubes: the view is the world's, that of the same voxels built of cubes
    # (each voxel four 0.25-cubes high), within a pixel in a thousand where a ray grazes an edge.
    # Flat light: ambient occlusion and shadows measure distances in voxels.
    world.voxel_size_world = (0.25, 0.25, 1.0)
    cubes = World(np.repeat(voxels, 4, axis=2))
    cubes.origin_world = world.origin_world
    cubes.voxel_size_world = (0.25, 0.25, 0.25)
    sky = World(np.zeros((24, 20, 48), dtype=np.uint8))  # nothing in view
    sky.origin_world = world.origin_world
    sky.voxel_size_world = (0.25, 0.25, 0.25)
    flat = dict(shadows=False, ambient_occlusion=False, camera_frame="world")
    for camera in ["eye=110,-53,16:target=103,-47.5,4.25",
                   "eye=112,-58,14:target=103,-47.5,4:ortho=8"]:
        placed = render(world, 96, 64, camera=camera, **flat)
        want = render(cubes, 96, 64, camera=camera, **flat)
        assert (want != render(sky, 96, 64, camera=camera, **flat)).any(axis=2).mean() > 0.1, camera
        assert (placed != want).any(axis=2).mean() <= 1 / 1000, camera
        # The voxels' shape matters: the scan's voxels taken for cubes give another picture.
        world.voxel_size_world = (0.25, 0.25, 0.25)
        as_cubes = render(world, 96, 64, camera=camera, **flat)
        world.voxel_size_world = (0.25, 0.25, 1.0)
        assert (placed != as_cubes).any(axis=2).mean() > 0.05, camera
    with pytest.raises(ValueError, match="camera_frame"):
        render(world, 32, 32, camera_frame="metres")


def test_bad_frames_are_refused_and_keep_the_old_one():
    world = World(np.ones((3, 3, 3), dtype=np.uint8))
    world.voxel_size_world = (0.5, 0.5, 0.5)
    for bad in [(0.0, 1.0, 1.0), (1.0, -1.0, 1.0), (math.nan, 1.0, 1.0), (math.inf, 1.0, 1.0)]:
        with pytest.raises(ValueError, match="voxel size"):
            world.voxel_size_world = bad
    with pytest.raises(ValueError, match="origin"):
        world.origin_world = (0.0, math.inf, 0.0)
    with pytest.raises(ValueError, match="mirror"):
        world.rotation = np.diag([1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match="orthonormal"):
        world.rotation = np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match="points"):
        world.to_world(np.zeros((4, 2)))
    assert world.voxel_size_world == (0.5, 0.5, 0.5)
    np.testing.assert_array_equal(world.rotation, np.eye(3))

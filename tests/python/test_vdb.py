"""voxfield.vdb against OpenVDB's own Python module (pyopenvdb, Debian python3-openvdb).

Grids pyopenvdb makes and writes (float, bool and vec3s, in full and half precision, with leaves,
tiles, inactive values, a transform and metadata) read by voxfield's parser give the values
pyopenvdb's copyToArray gives over the same box, the same active voxels, bounds, background,
transform and metadata; damaged files raise voxfield.FormatError naming the file.

Run by CTest with PYTHONPATH pointing at the build's python/ directory.
"""

import numpy as np
import pyopenvdb as openvdb
import pytest

import voxfield
import voxfield.vdb
from voxfield.world import World


def sample_grids(half):
    rng = np.random.default_rng(7)
    floats = openvdb.FloatGrid(background=1.5)
    floats.name = "floats"
    floats.transform = openvdb.createLinearTransform(voxelSize=0.25)
    vectors = openvdb.Vec3SGrid(background=(0.0, 0.0, 1.0))
    vectors.name = "vectors"
    bools = openvdb.BoolGrid(background=False)
    bools.name = "bools"
    for grid in (floats, vectors, bools):
        acc = grid.getAccessor()
        for n in range(1500):
            ijk = tuple(int(v) for v in rng.integers(-40, 40, 3))
            if grid is floats:
                value = float(rng.uniform(-3, 3))
            elif grid is vectors:
                value = tuple(float(v) for v in rng.uniform(-3, 3, 3))
            else:
                value = bool(n % 3)
            if n % 4 == 0:
                acc.setValueOff(ijk, value)  # inactive values other than the background
            else:
                acc.setValueOn(ijk, value)
    floats.fill((64, 0, 0), (79, 15, 15), -2.0, active=True)  # leaf-sized tiles
    bools.fill((0, 64, 0), (127, 191, 127), True, active=True)  # a 128^3 tile
    floats["note"] = "made by pyopenvdb"
    floats["count"] = 12
    floats["scale"] = 0.5
    floats["corner"] = (1, -2, 3)
    for grid in (floats, vectors):
        grid.saveFloatAsHalf = half
    return [floats, vectors, bools]


@pytest.mark.parametrize("half", [False, True])
def test_grids_read_as_pyopenvdb_reads_them(tmp_path, half):
    grids = sample_grids(half)
    path = str(tmp_path / "sample.vdb")
    openvdb.write(path, grids=grids)
    ref = {g.name: g for g in openvdb.readAll(path)[0]}
    got = voxfield.vdb.read(path)
    assert [g.name for g in got] == ["floats", "vectors", "bools"]
    for g in got:
        r = ref[g.name]
        assert g.value_type == {"floats": "float", "vectors": "vec3s", "bools": "bool"}[g.name]
        assert g.half_float == (half and g.name != "bools")
        assert "voxfield.vdb.Grid(name='" + g.name in repr(g)
        lo, hi = r.evalActiveVoxelBoundingBox()
        assert g.active_bounds == (tuple(lo), tuple(int(v) + 1 for v in hi))
        box = (tuple(int(v) - 2 for v in lo), tuple(min(int(v) + 3, 140) for v in hi))
        shape = tuple(box[1][a] - box[0][a] for a in range(3))
        want = np.zeros(shape + ((3,) if g.name == "vectors" else ()),
                        dtype={"floats": np.float32, "vectors": np.float32, "bools": bool}[g.name])
        r.copyToArray(want, ijk=box[0])
        values = g.to_numpy(box)
        assert values.dtype == want.dtype and values.shape == want.shape
        np.testing.assert_array_equal(values, want, err_msg=g.name)
        mask = g.active_mask(box)
        if g.name != "bools":  # (the bools' 128^3 tile sticks out of the box)
            assert int(mask.sum()) == r.activeVoxelCount(), g.name
        acc = r.getConstAccessor()
        rng = np.random.default_rng(3)
        for _ in range(3000):
            i, j, k = (int(rng.integers(0, shape[a])) for a in range(3))
            ijk = (box[0][0] + i, box[0][1] + j, box[0][2] + k)
            assert bool(mask[i, j, k]) == acc.isValueOn(ijk), (g.name, ijk)
        assert np.allclose(g.voxel_size, r.transform.voxelSize())
        for ijk in [(0, 0, 0), (3, -7, 11)]:
            world = g.index_to_world @ np.array(ijk + (1,), dtype=float)
            np.testing.assert_allclose(world, r.transform.indexToWorld(ijk), atol=1e-12)
    floats = got[0]
    assert floats.background == 1.5
    assert got[1].background == (0.0, 0.0, 1.0)
    assert got[2].background is False
    meta = floats.metadata
    assert meta["note"] == "made by pyopenvdb" and meta["count"] == 12 and meta["scale"] == 0.5
    assert meta["corner"] == (1, -2, 3)


def test_level_set_inside_matches_pyopenvdb(tmp_path):
    sphere = openvdb.createLevelSetSphere(radius=5.0, center=(0.5, 0.0, -1.0), voxelSize=0.5)
    path = str(tmp_path / "sphere.vdb")
    openvdb.write(path, grids=[sphere])
    (g,) = voxfield.vdb.read(path)
    assert g.grid_class == "level set"
    lo, hi = sphere.evalActiveVoxelBoundingBox()
    box = (tuple(lo), tuple(int(v) + 1 for v in hi))
    want = np.zeros(tuple(box[1][a] - box[0][a] for a in range(3)), dtype=np.float32)
    sphere.copyToArray(want, ijk=lo)
    np.testing.assert_array_equal(g.to_numpy(box), want)
    assert (want < 0).sum() > 1000  # the inside, inactive tiles and leaf voxels alike


def test_damaged_files_raise_format_errors_naming_the_file(tmp_path):
    path = str(tmp_path / "sample.vdb")
    openvdb.write(path, grids=sample_grids(False))
    data = open(path, "rb").read()
    for n in (0, 7, 40, 200, len(data) // 3, len(data) - 1):
        cut = str(tmp_path / f"cut{n}.vdb")
        with open(cut, "wb") as f:
            f.write(data[:n])
        with pytest.raises(voxfield.FormatError, match="cut%d.vdb: at byte" % n):
            voxfield.vdb.read(cut)
    with pytest.raises(voxfield.IoError, match="missing.vdb"):
        voxfield.vdb.read(str(tmp_path / "missing.vdb"))
    with pytest.raises(voxfield.ResourceLimitError, match="memory limit"):
        voxfield.vdb.read(path, memory_limit=len(data) + 4096)  # the bytes fit, the trees not


def test_world_load_reads_the_grid_of_the_given_name(tmp_path):
    mask = openvdb.BoolGrid(False)
    mask.name = "mask"
    mask.fill((0, 0, 0), (3, 3, 3), True, True)
    density = openvdb.FloatGrid(0.0)
    density.name = "density"
    density.fill((10, 10, 10), (11, 12, 13), 0.5, True)
    density.fill((10, 10, 13), (11, 12, 13), 0.0, True)  # active but empty: not solid
    path = str(tmp_path / "two.vdb")
    openvdb.write(path, grids=[mask, density])
    assert World.load(path).solid_count == mask.activeVoxelCount() == 64
    w = World.load(path, grid="density")
    assert w.solid_count == density.activeVoxelCount() - 6 == 18
    assert w.content_bounds == ((10, 10, 10), (12, 13, 13))
    with pytest.raises(ValueError, match=r"two\.vdb has no grid named 'fog'; its grids: 'mask' \(bool\), 'density' \(float\)"):
        World.load(path, grid="fog")

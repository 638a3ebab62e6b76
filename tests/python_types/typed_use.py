"""A typed use of voxfield, checked by mypy --strict against the package's stubs (and run, so the
stubs describe what the module really returns)."""

import os
import tempfile

import numpy as np
import numpy.typing as npt

import voxfield
from voxfield import csg, mesh, ndimage, vdb, vectors, world


def sphere_field(n: int) -> npt.NDArray[np.float64]:
    grid = np.ones((n, n, n), dtype=np.uint8)
    grid[n // 2, n // 2, n // 2] = 0
    d: npt.NDArray[np.float64] = ndimage.distance_transform_edt(grid, sampling=(1.0, 1.0, 2.0), threads=1)
    return d


def model_figures() -> tuple[int, float]:
    model = csg.Model("(union (sphere 1) (move 1.5 0 0 (box 1 1 1)))", "typed.sdf")
    values = model.evaluate(np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]]))
    bounds = model.bounds
    assert bounds is not None
    lo, hi = bounds
    figures = model.octree(depth=3)
    vertices, faces, normals, colors = model.mesh(0.25)
    assert vertices.dtype == np.float32 and faces.dtype == np.uint32 and colors.dtype == np.uint8
    assert normals.shape == vertices.shape
    return model.nodes, float(values[0]) + hi[0] - lo[0] + figures["variants"]


def terrain_triangles() -> int:
    n = 24
    values = np.broadcast_to(np.arange(n, dtype=np.float32) - 8.0, (n, n, n)).copy()
    vertices, faces, normals = mesh.mesh_volume(values, level=0.0, spacing=(1.0, 1.0, 1.0))
    assert vertices.dtype == np.float32 and faces.dtype == np.uint32 and normals.shape == vertices.shape
    terrain = mesh.Terrain((n, n, n), storage="i8")
    terrain.assign(values, material=1)
    changed = terrain.apply("sphere", "add", centre=(12.0, 12.0, 8.0), radius=4.0, smooth=1.0)
    assert changed is not None
    (x0, _, _), (x1, _, _) = changed
    v, f, nrm, colors = terrain.mesh("mc", 16)
    assert colors.dtype == np.uint8 and terrain.values().shape == (n, n, n) and terrain.memory["bytes"] > 0
    return int(f.shape[0]) + x1 - x0 + terrain.samples[0] + int(terrain.max_distance + terrain.step)


def mesh_input_figures() -> float:
    corners = np.array([[x, y, z] for z in (0.0, 1.0) for y in (0.0, 1.0) for x in (0.0, 1.0)])
    faces = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                      [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    winding = mesh.WindingNumber(corners, faces)
    at: npt.NDArray[np.float64] = winding(np.array([[0.5, 0.5, 0.5]]))
    inside: npt.NDArray[np.bool_] = winding.inside(np.array([[2.0, 0.5, 0.5]]))
    materials, first = mesh.voxelize_mesh(corners, faces, 0.25, material=3)
    values, same = mesh.mesh_distance_field(corners, faces, 0.25, band=2.0)
    assert materials.dtype == np.uint8 and values.dtype == np.float32 and first == same
    assert not inside[0] and int(materials.sum()) == 3 * 64
    return float(at[0]) + float(values.min()) + float(winding.exact(corners[:1] + 0.5)[0])


def vector_strength() -> float:
    volume = vectors.Volume(size=(4.0, 4.0, 4.0), resolution=(16, 16, 16))
    sources = np.array([[0.0, 0.0, 0.0, 1.5]])
    texture = vectors.generate(volume, sources, algorithm="splat", storage="rgba8")
    values, winners = vectors.exact(np.array([[0.5, 0.0, 0.0]]), sources)
    sim = vectors.Simulation(volume, storage="rgba32f", decay_per_s=2.0)
    sim.step(sources, 1 / 60)
    sample = sim.sample(np.array([[0.5, 0.0, 0.0]]))
    picture = sim.render(64, 48)
    assert picture.dtype == np.uint8 and texture.dtype == np.float32 and int(winners[0]) == 0
    return float(sample[0, 3]) + float(values[0, 3]) + sim.steps + sim.last_times["total_ms"] * 0


def world_field() -> float:
    a = np.zeros((8, 8, 8), dtype=np.uint8)
    a[2:5, 2:5, 2:5] = 3
    w = world.World(a, origin=(1, 0, 0))
    f: world.Field = world.distance_field(w, metric="euclidean", signed=True, sites=True)
    assert f.sites is not None and w.extent == ((1, 0, 0), (9, 8, 8))
    live = world.LiveField(w, max_distance=4.0)
    changed, count, dirty, stats = live.apply("carve", "sphere", center=(3.0, 3.0, 3.0), radius=1.0)
    assert changed is not None and count > 0 and dirty and stats["regions"] >= 0
    assert live.field().distances.shape == (8, 8, 8)
    jfa, report = world.approximate(w, algorithm="jfa")
    assert jfa.distances.shape == (8, 8, 8) and report["voxels"] == 512
    frame = world.render(w, 32, 18, shadows=False)
    vertices, faces, normals, colors = world.mesh(w, algorithm="sn")
    assert frame.shape == (18, 32, 3) and len(faces) > 0 and colors.dtype == np.uint8
    kept = world.LiveMesh(w, algorithm="sn", chunk=4)
    _, _, _, remeshed = kept.apply("place", "box", min=(6, 6, 6), max=(7, 7, 7), material=2)
    assert remeshed and all(len(c) == 3 for c in remeshed) and len(kept.chunk_count) == 3
    assert len(kept.mesh()[1]) > 0 and kept.chunk_mesh(remeshed[0])[0].dtype == np.float32
    return float(f.decoded()[0, 0, 0]) + float(w.to_numpy().sum()) * 0


def vdb_grid_values() -> int:
    a = np.zeros((8, 8, 8), dtype=np.uint8)
    a[1:4, 2:6, 3:5] = 7
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "w.vdb")
        world.World(a).save(path)
        grids: list[vdb.Grid] = vdb.read(path)
    g = grids[0]
    bounds = g.active_bounds
    assert bounds is not None and g.value_type == "int32" and g.index_to_world.shape == (3, 4)
    values = g.to_numpy()
    assert bool(g.active_mask().all()) and g.metadata["voxfield_kind"] == "world"
    return int(values.sum())


def refused() -> bool:
    try:
        csg.Model("(sphere", "bad.sdf")
    except csg.ModelError:
        return True
    except voxfield.Error:
        return False
    return False


if __name__ == "__main__":
    field = sphere_field(9)
    assert field[4, 4, 4] == 0.0 and field[4, 4, 0] == 8.0, field[4, 4, 0]
    nodes, _ = model_figures()
    assert nodes == 4, nodes
    assert refused()
    assert terrain_triangles() > 0
    assert mesh_input_figures() > 1.5
    assert vector_strength() > 1
    assert world_field() > 2
    assert vdb_grid_values() == 7 * 3 * 4 * 2
    print("typed use: ok")

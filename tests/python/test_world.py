"""voxfield.world against NumPy, SciPy and the CLI.

Worlds round-trip through arrays and files (the CLI's .npy of the same .vox is the oracle); exact
fields equal scipy.ndimage's transforms (Euclidean with anisotropic spacing, taxicab, chessboard)
and the CLI's signed fields, integer storages and nearest sites byte for byte; errors are
voxfield's exceptions naming what is wrong.

Run by CTest with PYTHONPATH pointing at the build's python/ directory (and VOXFIELD, VOX_CORPUS).
"""

import os
import subprocess

import numpy as np
import pytest
import scipy.ndimage as sn

import voxfield
from voxfield.world import Field, World, distance_field

CORPUS = os.environ.get("VOX_CORPUS")
CLI = os.environ.get("VOXFIELD")
needs_cli = pytest.mark.skipif(not CLI or not CORPUS, reason="needs the voxfield CLI and corpus")


def random_world(shape=(23, 17, 29), density=0.1, seed=4):
    rng = np.random.default_rng(seed)
    a = (rng.random(shape) < density) * rng.integers(1, 256, shape)
    return a.astype(np.uint8)


def test_arrays_round_trip_with_their_origin():
    a = random_world()
    np.testing.assert_array_equal(World(a.astype(np.int64)).to_numpy(), a)  # any integer dtype
    np.testing.assert_array_equal(World(a > 0).to_numpy(), a > 0)
    w = World(a, origin=(-3, 5, 2), chunk=16)
    assert w.extent == ((-3, 5, 2), (20, 22, 31))
    assert w.solid_count == int(np.count_nonzero(a))
    np.testing.assert_array_equal(w.to_numpy(), a)
    # A box reaching outside the world reads air there.
    part = w.to_numpy(((-5, 5, 2), (0, 8, 4)))
    np.testing.assert_array_equal(part[2:], a[:3, :3, :2])
    assert not part[:2].any()
    w.fill((0, 6, 3), (2, 8, 5), 200)
    assert (w.to_numpy(((0, 6, 3), (2, 8, 5))) == 200).all()
    p = w.palette
    p[7] = (1, 2, 3, 4)
    w.palette = p
    np.testing.assert_array_equal(w.palette[7], (1, 2, 3, 4))
    assert "solid=" in repr(w)


def test_files_round_trip(tmp_path):
    a = random_world()
    w = World(a)
    for ext in ("vox", "npy", "vfw"):
        path = str(tmp_path / f"w.{ext}")
        w.save(path)
        back = World.load(path)
        np.testing.assert_array_equal(back.to_numpy(w.extent), a, err_msg=ext)
    np.testing.assert_array_equal(np.load(tmp_path / "w.npy"), a)
    w.save(str(tmp_path / "w.vdb"))  # written with OpenVDB, read by voxfield's own parser
    back = World.load(str(tmp_path / "w.vdb"))
    np.testing.assert_array_equal(back.to_numpy(w.extent), a, err_msg="vdb")


@needs_cli
def test_real_files_read_as_the_cli_reads_them(tmp_path):
    for name in ("ephtracy_T-Rex", "ephtracy_menger"):
        vox = os.path.join(CORPUS, name + ".vox")
        out = tmp_path / f"{name}.npy"
        subprocess.run([CLI, "convert", vox, str(out)], check=True, capture_output=True)
        np.testing.assert_array_equal(World.load(vox).to_numpy(), np.load(out), err_msg=name)


def test_unsigned_fields_equal_scipy():
    a = random_world(density=0.02)
    w = World(a)
    air = a == 0
    f = distance_field(w, metric="euclidean", spacing=(1.0, 2.0, 0.5))
    assert isinstance(f, Field) and f.distances.dtype == np.float32 and f.sites is None
    want = sn.distance_transform_edt(air, sampling=(1.0, 2.0, 0.5)).astype(np.float32)
    np.testing.assert_array_equal(f.distances, want)
    for metric, scipy_metric in (("manhattan", "taxicab"), ("chebyshev", "chessboard")):
        got = distance_field(w, metric=metric).distances
        np.testing.assert_array_equal(got, sn.distance_transform_cdt(air, metric=scipy_metric),
                                      err_msg=metric)


@needs_cli
def test_signed_integer_and_site_fields_equal_the_cli(tmp_path):
    vox = os.path.join(CORPUS, "ephtracy_T-Rex.vox")
    w = World.load(vox)
    for metric, storage, clamp in (("euclidean", "f32", 0.0), ("euclidean", "u8", 6.0),
                                   ("manhattan", "u16", 0.0), ("chebyshev", "f32", 3.0)):
        d, s = tmp_path / "d.npy", tmp_path / "s.npy"
        subprocess.run([CLI, "field", vox, "-o", str(d), "--sites", str(s), "--metric", metric,
                        "--signed", "--storage", storage, "--max-distance", str(clamp)],
                       check=True, capture_output=True)
        f = distance_field(w, metric=metric, signed=True, storage=storage, max_distance=clamp,
                           sites=True)
        what = f"{metric} {storage} {clamp}"
        np.testing.assert_array_equal(f.distances, np.load(d), err_msg=what)
        np.testing.assert_array_equal(f.sites, np.load(s), err_msg=what)
        if storage != "f32":  # stored = bias + floor(d * scale), signed fields biased
            assert f.bias == (128 if storage == "u8" else 32768), what
            solid = w.to_numpy() > 0
            assert (f.decoded()[solid] < 0).all() and (f.decoded()[~solid] > 0).all(), what


def test_errors_are_voxfields():
    with pytest.raises(voxfield.IoError, match="nowhere.vox"):
        World.load("/nonexistent/nowhere.vox")
    with pytest.raises(voxfield.InvalidArgument, match="3-D"):
        World(np.zeros((4, 4), np.uint8))
    with pytest.raises(voxfield.InvalidArgument, match="one is 256"):
        World(np.full((2, 2, 2), 256, np.int32))
    with pytest.raises(voxfield.InvalidArgument, match="integers"):
        World(np.zeros((2, 2, 2), np.float32))
    with pytest.raises(voxfield.InvalidArgument, match="reach outside"):
        World(np.zeros((2, 2, 2), np.uint8), origin=(2**29 - 1, 0, 0))
    with pytest.raises(voxfield.InvalidArgument, match="metric"):
        distance_field(World(random_world()), metric="cosine")
    with pytest.raises(voxfield.InvalidArgument, match="material"):
        World().fill((0, 0, 0), (1, 1, 1), 300)
    with pytest.raises(voxfield.InvalidArgument, match="palette"):
        World().palette = np.zeros((255, 4), np.uint8)


@needs_cli
def test_frames_and_meshes_equal_the_clis(tmp_path):
    from PIL import Image

    vox = os.path.join(CORPUS, "ephtracy_T-Rex.vox")
    w = World.load(vox)
    for view, camera in (("shaded", "auto"), ("distance", "top")):
        png = tmp_path / f"{view}.png"
        subprocess.run([CLI, "render", vox, "-o", str(png), "--width", "160", "--height", "90",
                        "--view", view, "--camera", camera], check=True, capture_output=True)
        frame = voxfield.world.render(w, 160, 90, camera=camera, view=view)
        assert frame.shape == (90, 160, 3) and frame.dtype == np.uint8
        np.testing.assert_array_equal(frame, np.asarray(Image.open(png).convert("RGB")), err_msg=view)
    stats = tmp_path / "m.json"
    subprocess.run([CLI, "mesh", vox, "-o", str(tmp_path / "m.ply"), "--stats", str(stats)],
                   check=True, capture_output=True)
    import json

    want = json.load(open(stats))
    v, f, n, c = voxfield.world.mesh(w)
    assert len(f) == want["triangles"] and len(v) == want["vertices"]
    # The enclosed volume, by the divergence theorem over the triangles, as the CLI reports it.
    a, b, cc = (v[f[:, k]].astype(np.float64) for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, cc)).sum() / 6
    assert abs(volume - want["volume_units3"]) <= 1e-6 * abs(want["volume_units3"])
    assert c.shape == v.shape and np.allclose(np.linalg.norm(n, axis=1), 1, atol=1e-5)


def sphere_mask(shape, origin, center, radius):
    x, y, z = np.meshgrid(*(np.arange(n) + o for n, o in zip(shape, origin)), indexing="ij")
    return (x - center[0]) ** 2 + (y - center[1]) ** 2 + (z - center[2]) ** 2 <= radius ** 2


def test_edits_follow_their_definitions_and_report_what_changed():
    a = random_world((30, 26, 22), density=0.05)
    origin = (-4, 2, 0)
    w = World(a, origin=origin, chunk=8)
    model = a.copy()
    rng = np.random.default_rng(9)
    for n in range(40):
        op = ("place", "carve", "paint")[n % 3]
        # Inside the array's box (the world is unbounded: edits beyond it would grow it).
        radius = float(rng.uniform(0.5, 6))
        center = [float(v) for v in rng.uniform(np.array(origin) + radius,
                                                np.array(origin) + a.shape - 1 - radius)]
        before = model.copy()
        if n % 2:
            lo = [int(v) for v in rng.integers(origin, np.array(origin) + a.shape - 7)]
            hi = [v + int(rng.integers(0, 7)) for v in lo]
            x, y, z = np.meshgrid(*(np.arange(s) + o for s, o in zip(a.shape, origin)), indexing="ij")
            inside = (x >= lo[0]) & (x <= hi[0]) & (y >= lo[1]) & (y <= hi[1]) & (z >= lo[2]) & (z <= hi[2])
            changed, count, dirty = w.apply(op, "box", min=lo, max=hi, material=n + 1)
        else:
            inside = sphere_mask(a.shape, origin, center, radius)
            changed, count, dirty = w.apply(op, "sphere", center=center, radius=radius, material=n + 1)
        if op == "place":
            model[inside] = n + 1
        elif op == "carve":
            model[inside] = 0
        else:
            model[inside & (model > 0)] = n + 1
        np.testing.assert_array_equal(w.to_numpy(w.extent), model, err_msg=f"edit {n}")
        diff = np.argwhere(model != before) + origin
        assert count == len(diff), n
        if len(diff) == 0:
            assert changed is None, n
            continue
        assert changed == (tuple(diff.min(0)), tuple(diff.max(0) + 1)), n
        covered = np.zeros(len(diff), bool)
        for lo, hi in dirty:
            covered |= ((diff >= lo) & (diff < np.array(hi))).all(1)
        assert covered.all(), n


def test_live_fields_stay_equal_to_a_rebuild():
    a = random_world((28, 24, 20), density=0.03)
    for options in (dict(metric="euclidean", signed=True, max_distance=5.0, sites=True),
                    dict(metric="manhattan", storage="u8"),
                    dict(metric="chebyshev", signed=True, storage="u16", max_distance=3.0),
                    dict(metric="euclidean", spacing=(1.0, 1.0, 2.0), max_distance=6.0)):
        w = World(a, origin=(2, -3, 1))
        live = voxfield.world.LiveField(w, **options)
        rng = np.random.default_rng(2)
        for n in range(24):
            shape = ("sphere", "capsule", "rotated_box", "box")[n % 4]
            c = [float(v) for v in rng.uniform((2, -3, 1), (30, 21, 21))]
            kw = dict(sphere=dict(center=c, radius=3.5),
                      capsule=dict(a=c, b=[c[0] + 6, c[1] - 2, c[2] + 1], radius=1.5),
                      rotated_box=dict(center=c, half_extent=[4, 1.5, 2], rotation_deg=[10, 20, 30]),
                      box=dict(min=[int(v) for v in c], max=[int(v) + 3 for v in c]))[shape]
            _, _, _, stats = live.apply(("place", "carve")[n % 2], shape, **kw, material=3)
            assert stats["voxels_recomputed"] >= 0
            got = live.field()
            want = distance_field(w, box=((2, -3, 1), (30, 21, 21)), **options)  # the live box
            np.testing.assert_array_equal(got.distances, want.distances, err_msg=f"{options} {n}")
            if options.get("sites"):
                np.testing.assert_array_equal(got.sites, want.sites, err_msg=f"{options} {n}")
        del w  # the LiveField keeps its world alive
        assert live.field().distances.shape == (28, 24, 20)


def _triangles(vertices, faces, normals, colors):
    """The triangle set independent of vertex numbering: each triangle's corners (position,
    normal, colour), rotated to start at the smallest corner, the rows sorted."""
    corners = np.concatenate([vertices, normals, colors.astype(np.float32)], axis=1)[faces]
    keys = [tuple(map(tuple, tri)) for tri in corners]
    return sorted(tri[tri.index(min(tri)):] + tri[:tri.index(min(tri))] for tri in keys)


def test_live_meshes_stay_equal_to_meshing_the_edited_world():
    a = random_world((30, 26, 22), density=0.05)
    for algorithm in ("mc", "sn", "dc"):
        w = World(a, origin=(1, 2, -1))
        kept = voxfield.world.LiveMesh(w, algorithm=algorithm, chunk=8)
        assert kept.chunk_count == (5, 4, 4)  # the extent and two samples of air each side
        rng = np.random.default_rng(5)
        for n in range(8):
            c = [float(v) for v in rng.uniform((4, 5, 2), (28, 25, 18))]
            op = ("place", "carve", "paint")[n % 3]
            _, count, _, remeshed = kept.apply(op, "sphere", center=c, radius=2.5, material=4 + n)
            assert (count > 0) == (len(remeshed) > 0)
            got = _triangles(*kept.mesh())
            want = _triangles(*voxfield.world.mesh(w, algorithm=algorithm))
            assert got == want, f"{algorithm} after edit {n}"
        del w  # the LiveMesh keeps its world alive
        assert len(kept.mesh()[1]) > 0
        with pytest.raises(voxfield.InvalidArgument, match="outside"):
            kept.chunk_mesh((9, 0, 0))


def test_edit_errors_name_the_argument():
    w = World(random_world())
    with pytest.raises(voxfield.InvalidArgument, match="center"):
        w.apply("place", "sphere")
    with pytest.raises(voxfield.InvalidArgument, match="op must be"):
        w.apply("melt", "sphere", center=(0, 0, 0))
    with pytest.raises(voxfield.InvalidArgument, match="shape must be"):
        w.apply("place", "torus", center=(0, 0, 0))
    with pytest.raises(voxfield.InvalidArgument, match="material"):
        w.apply("place", "sphere", center=(0, 0, 0), material=0)


def test_the_algorithm_family_reports_its_error_against_the_exact_field():
    a = random_world((26, 22, 18), density=0.01, seed=11)
    w = World(a)
    exact = distance_field(w, metric="manhattan").distances.astype(np.float64)
    air = a == 0
    for algorithm in ("exact", "brute", "brute-chunked", "fim", "jfa-seed", "jfa", "jfa+2", "hybrid"):
        field, report = voxfield.world.approximate(w, algorithm=algorithm, metric="manhattan")
        got = field.decoded()
        # The report's figures, recomputed here from the two fields (f32: tolerance 1e-4 relative).
        diff = (got - exact)[air]
        wrong = np.abs(diff) > 1e-4 * np.maximum(1, np.abs(exact[air]))
        assert report["air_voxels"] == int(air.sum()), algorithm
        assert report["wrong"] == int(wrong.sum()), algorithm
        assert report["too_large"] == int((wrong & (diff > 0)).sum()), algorithm
        assert report["max_over"] == pytest.approx(max(0.0, diff.max()), abs=1e-9), algorithm
        if algorithm in ("exact", "brute", "fim", "hybrid"):
            assert report["wrong"] == 0, (algorithm, report)
    _, lod = voxfield.world.approximate(w, algorithm="lod", metric="manhattan",
                                        focus=((0, 0, 0), (8, 8, 8)))
    assert lod["voxels"] == a.size
    with pytest.raises(voxfield.InvalidArgument, match="focus"):
        voxfield.world.approximate(w, algorithm="lod")

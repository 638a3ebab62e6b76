"""voxfield.ndimage against scipy.ndimage: the same results, shapes, dtypes, index layout, in-place
arguments and errors, on random and real volumes of every dtype, order and dimensionality; what
SciPy lacks (signed, max_distance, threads) against SciPy-derived expectations; the GIL released.

Run by CTest with PYTHONPATH pointing at the build's python/ directory (and VOXFIELD, VOX_CORPUS
for the real volumes)."""

import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from scipy import ndimage as sn

import voxfield
from voxfield import ndimage as vn

from gil import ticks_during

RNG = np.random.default_rng(2026)


def random_volume(shape, density=0.97, dtype=bool):
    a = RNG.random(shape) < density
    if a.all():
        a.flat[0] = False
    return a.astype(dtype)


def check_indices(input, distances, indices, sampling=None):
    """Every index names a zero element at exactly the reported distance (ties may differ)."""
    nd = input.ndim
    assert indices.shape == (nd,) + input.shape and indices.dtype == np.int32
    zero = np.asarray(input) == 0
    assert zero[tuple(indices)].all()
    grid = np.indices(input.shape)
    s = np.ones(nd) if sampling is None else np.broadcast_to(np.asarray(sampling, float), (nd,))
    d = np.sqrt(sum(((indices[k] - grid[k]) * s[k]) ** 2 for k in range(nd)))
    np.testing.assert_allclose(d, distances, rtol=1e-12, atol=0)


@pytest.mark.parametrize("shape", [(37,), (23, 31), (19, 17, 23), (1, 40, 3)])
@pytest.mark.parametrize("dtype", [bool, np.uint8, np.int8, np.int16, np.uint32, np.int64,
                                   np.float32, np.float64, np.complex64])
def test_edt_matches_scipy_for_every_shape_and_dtype(shape, dtype):
    a = random_volume(shape, dtype=dtype)
    want, want_idx = sn.distance_transform_edt(a, return_indices=True)
    got, idx = vn.distance_transform_edt(a, return_indices=True)
    assert got.dtype == np.float64 and got.shape == a.shape
    np.testing.assert_array_equal(got, want)
    check_indices(a, got, idx)


@pytest.mark.parametrize("order", ["C", "F", "view"])
def test_any_memory_order(order):
    base = random_volume((30, 26, 22))
    a = {"C": base, "F": np.asfortranarray(base), "view": base[::2, 3:, ::-1]}[order]
    np.testing.assert_array_equal(vn.distance_transform_edt(a), sn.distance_transform_edt(a))


@pytest.mark.parametrize("sampling", [2.5, (0.5, 1.2, 2.0), (1.0, 0.3, 3.7), (1, 1, 1)])
def test_edt_with_sampling(sampling):
    a = random_volume((21, 19, 17), density=0.98)
    want = sn.distance_transform_edt(a, sampling=sampling)
    got, idx = vn.distance_transform_edt(a, sampling=sampling, return_indices=True)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    check_indices(a, got, idx, sampling)


@pytest.mark.parametrize("metric", ["taxicab", "chessboard", "cityblock", "manhattan"])
@pytest.mark.parametrize("shape", [(41,), (29, 33), (17, 19, 21)])
def test_cdt_matches_scipy(metric, shape):
    a = random_volume(shape, density=0.95, dtype=np.uint8)
    want, want_idx = sn.distance_transform_cdt(a, metric=metric, return_indices=True)
    got, idx = vn.distance_transform_cdt(a, metric=metric, return_indices=True)
    assert got.dtype == np.int32
    np.testing.assert_array_equal(got, want)
    zero = a == 0
    assert zero[tuple(idx)].all()
    off = np.abs(idx - np.indices(a.shape))
    d = off.sum(0) if metric != "chessboard" else off.max(0)
    np.testing.assert_array_equal(d, got)


def test_return_conventions_and_in_place_outputs():
    a = random_volume((12, 14, 9))
    want, want_idx = sn.distance_transform_edt(a, return_indices=True)
    assert isinstance(vn.distance_transform_edt(a), np.ndarray)
    assert vn.distance_transform_edt(a, return_distances=False, return_indices=True).shape == want_idx.shape
    dist = np.zeros(a.shape)
    ind = np.zeros((3,) + a.shape, np.int32)
    assert vn.distance_transform_edt(a, return_indices=True, distances=dist, indices=ind) is None
    np.testing.assert_array_equal(dist, want)
    check_indices(a, dist, ind)
    only = vn.distance_transform_edt(a, return_indices=True, distances=dist)
    assert isinstance(only, np.ndarray) and only.shape == want_idx.shape
    # Non-contiguous outputs are written where they lie.
    big = np.zeros((24, 14, 9))
    vn.distance_transform_edt(a, distances=big[::2])
    np.testing.assert_array_equal(big[::2], want)
    cdt = np.zeros(a.shape, np.int32)
    assert vn.distance_transform_cdt(a, distances=cdt) is None
    np.testing.assert_array_equal(cdt, sn.distance_transform_cdt(a))


@pytest.mark.parametrize("call, message", [
    (lambda a: vn.distance_transform_edt(a, return_distances=False), "at least one"),
    (lambda a: vn.distance_transform_edt(a, distances=np.zeros((3, 3))), "wrong shape"),
    (lambda a: vn.distance_transform_edt(a, distances=np.zeros((4, 5), np.float32)), "float64"),
    (lambda a: vn.distance_transform_edt(a, return_indices=True, indices=np.zeros((2, 4, 5))), "int32"),
    (lambda a: vn.distance_transform_edt(a, return_indices=True, indices=np.zeros((1, 4, 5), np.int32)), "wrong shape"),
    (lambda a: vn.distance_transform_edt(a, distances=np.zeros((4, 5)), return_distances=False, return_indices=True), "return_distances must be True"),
    (lambda a: vn.distance_transform_cdt(a, distances=np.zeros((4, 5))), "int32"),
])
def test_inconsistent_arguments_raise_as_scipy_does(call, message):
    a = random_volume((4, 5))
    with pytest.raises(RuntimeError, match=message):
        call(a)


def test_bad_input_raises_value_errors():
    with pytest.raises(ValueError, match="1 to 3 dimensions"):
        vn.distance_transform_edt(np.ones((2, 2, 2, 2)))
    with pytest.raises(ValueError, match="structuring elements"):
        vn.distance_transform_cdt(np.ones((3, 3)), metric=np.ones((3, 3)))
    with pytest.raises(ValueError, match="threads"):
        vn.distance_transform_edt(np.ones((3, 3)), threads=0)
    with pytest.raises(ValueError, match="max_distance"):
        vn.distance_transform_edt(np.ones((3, 3)), max_distance=float("nan"))
    with pytest.raises(ValueError, match="sampling"):
        vn.distance_transform_edt(np.ones((3, 3)), sampling=(1, -1))
    assert issubclass(voxfield.InvalidArgument, ValueError)
    assert issubclass(voxfield.IoError, OSError)


def test_signed_distances():
    a = random_volume((20, 18, 16), density=0.6)
    got = vn.distance_transform_edt(a, signed=True)
    outside = sn.distance_transform_edt(a)   # non-zero elements: distance to the nearest zero
    inside = sn.distance_transform_edt(a == 0)  # zero elements: distance to the nearest non-zero
    np.testing.assert_array_equal(got, np.where(a != 0, outside, -inside))
    cdt = vn.distance_transform_cdt(a, metric="taxicab", signed=True)
    np.testing.assert_array_equal(cdt, np.where(a != 0, sn.distance_transform_cdt(a, metric="taxicab"),
                                                -sn.distance_transform_cdt(a == 0, metric="taxicab")))


def test_max_distance_clamps():
    a = random_volume((40, 30, 20), density=0.999)
    got, idx = vn.distance_transform_edt(a, return_indices=True, max_distance=4.5)
    want = sn.distance_transform_edt(a)
    np.testing.assert_array_equal(got, np.minimum(want, 4.5))
    beyond = want > 4.5
    assert beyond.any() and (idx[:, beyond] == -1).all()
    near = ~beyond
    zero = a == 0
    assert zero[tuple(i[near] for i in idx)].all()


@pytest.mark.parametrize("metric", ["taxicab", "chessboard"])
@pytest.mark.parametrize("order", ["C", "view"])
def test_cdt_distances_clamped_across_chunks(metric, order):
    # Distances only (written from the field's stored values, not its sites), over a volume of
    # several 32^3 chunks: zeros only near one corner, so the chunks far from it are entirely at
    # the clamp (stored as one value); also from a reversed, strided view of the input.
    base = np.ones((140, 75, 70), bool)
    base[:30, :20, :24] = random_volume((30, 20, 24), density=0.9)
    a = {"C": base[:70], "view": base[::2, ::-1, 3:]}[order]
    assert (a == 0).any()
    got = vn.distance_transform_cdt(a, metric=metric, max_distance=6)
    np.testing.assert_array_equal(got, np.minimum(sn.distance_transform_cdt(a, metric=metric), 6))
    signed = vn.distance_transform_cdt(a, metric=metric, max_distance=6, signed=True)
    inside = np.minimum(sn.distance_transform_cdt(a == 0, metric=metric), 6)
    np.testing.assert_array_equal(signed, np.where(a != 0, got, -inside))
    if metric == "taxicab":  # the Euclidean distances from stored values, clamped the same way
        edt = vn.distance_transform_edt(a, max_distance=4.5)
        np.testing.assert_array_equal(edt, np.minimum(sn.distance_transform_edt(a), 4.5))


def test_threads_do_not_change_results():
    a = random_volume((64, 48, 40), density=0.995)
    one = vn.distance_transform_edt(a, threads=1, return_indices=True)
    two = vn.distance_transform_edt(a, threads=2, return_indices=True)
    np.testing.assert_array_equal(one[0], two[0])
    np.testing.assert_array_equal(one[1], two[1])


def test_no_zero_element():
    a = np.ones((5, 6))
    d, i = vn.distance_transform_edt(a, return_indices=True)
    assert np.isinf(d).all() and (i == -1).all()
    assert (vn.distance_transform_cdt(a) == -1).all()  # as SciPy's


def test_the_gil_is_released_during_a_transform():
    a = random_volume((160, 160, 160), density=0.9995)
    elapsed, during = ticks_during(lambda: vn.distance_transform_edt(a, threads=1))
    # While the transform ran (at least tens of milliseconds), the other thread kept counting.
    assert elapsed > 0.02 and during >= 10, (elapsed, during)


@pytest.mark.skipif(not os.environ.get("VOXFIELD") or not os.environ.get("VOX_CORPUS"),
                    reason="needs the voxfield CLI and the MagicaVoxel corpus")
def test_real_volumes_from_the_corpus(tmp_path):
    for name in ("ephtracy_menger", "ephtracy_dragon", "vengi_teardown"):
        out = tmp_path / f"{name}.npy"
        subprocess.run([os.environ["VOXFIELD"], "convert",
                        os.path.join(os.environ["VOX_CORPUS"], name + ".vox"), str(out)],
                       check=True, capture_output=True)
        world = np.load(out)
        for a in (world, world == 0):  # distances to air, and to the model
            want = sn.distance_transform_edt(a, sampling=(1.0, 1.0, 1.5))
            got = vn.distance_transform_edt(a, sampling=(1.0, 1.0, 1.5))
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
            np.testing.assert_array_equal(vn.distance_transform_cdt(a, metric="taxicab"),
                                          sn.distance_transform_cdt(a, metric="taxicab"))


def test_ctrl_c_stops_a_long_transform():
    import _thread
    a = random_volume((320, 320, 320), density=0.99999)
    start = time.perf_counter()
    vn.distance_transform_edt(a, threads=1)
    full = time.perf_counter() - start
    timer = threading.Timer(full / 10, _thread.interrupt_main)
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        vn.distance_transform_edt(a, threads=1)
    stopped = time.perf_counter() - start
    timer.join()
    assert stopped < 0.8 * full, (stopped, full)


def test_voxfield_errors_arrive_as_their_python_classes():
    # A field larger than the 16-bit nearest-site offsets allow: voxfield's InvalidArgument.
    with pytest.raises(voxfield.InvalidArgument):
        vn.distance_transform_edt(np.ones((1, 1, 40000)), return_indices=True)


@pytest.mark.parametrize("clamp", [2.3, 4.5, 7.1])
@pytest.mark.parametrize("with_indices", [False, True])
def test_max_distance_is_exact_on_every_path(clamp, with_indices):
    a = random_volume((30, 26, 22), density=0.998)
    want = np.minimum(sn.distance_transform_edt(a), clamp)
    got = vn.distance_transform_edt(a, max_distance=clamp, return_indices=with_indices)
    got = got[0] if with_indices else got
    np.testing.assert_array_equal(got, want)


def test_empty_and_byte_swapped_arrays():
    e = np.ones((0, 4), bool)
    assert vn.distance_transform_edt(e).shape == (0, 4)
    a = random_volume((9, 8, 7))
    big = np.zeros(a.shape, ">f8")
    vn.distance_transform_edt(a, distances=big)
    np.testing.assert_array_equal(big, sn.distance_transform_edt(a))


def test_misaligned_outputs_and_long_lines():
    # A float64 output that is not 8-byte aligned (a view one byte into a buffer) gets its
    # distances through a copy; clamps that are not floats and lines whose squared distances pass
    # 2^22 (the float round trip's limit) are exact too.
    a = random_volume((9, 8, 7))
    raw = np.zeros(a.size * 8 + 1, np.uint8)
    dist = raw[1:].view(np.float64).reshape(a.shape)
    assert not dist.flags.aligned
    vn.distance_transform_edt(a, distances=dist, max_distance=4.00000001)
    np.testing.assert_array_equal(dist, np.minimum(sn.distance_transform_edt(a), 4.00000001))
    line = np.ones(5000, bool)
    line[17] = False
    np.testing.assert_array_equal(vn.distance_transform_edt(line), sn.distance_transform_edt(line))


def test_repeated_transforms_reuse_voxel_memory_and_agree():
    """A second transform of the same size takes its arrays from the cache of freed ones (the
    reused count grows), and gives the result a transform with the cache turned off gives."""
    a = random_volume((70, 60, 50), density=0.995)
    saved = voxfield.chunk_cache_limit()
    try:
        voxfield.set_chunk_cache_limit(0)
        assert voxfield.chunk_memory_stats()["cached_bytes"] == 0
        d0, i0 = vn.distance_transform_edt(a, return_indices=True)
        voxfield.set_chunk_cache_limit(256 << 20)
        vn.distance_transform_edt(a, return_indices=True)
        stats = voxfield.chunk_memory_stats()
        assert 0 < stats["cached_bytes"] <= 256 << 20 and stats["limit_bytes"] == 256 << 20
        reused = stats["reused"]
        d1, i1 = vn.distance_transform_edt(a, return_indices=True)
        assert voxfield.chunk_memory_stats()["reused"] > reused
        np.testing.assert_array_equal(d1, d0)
        np.testing.assert_array_equal(i1, i0)
        np.testing.assert_array_equal(d1, sn.distance_transform_edt(a))
        voxfield.trim_chunk_cache()
        assert voxfield.chunk_memory_stats()["cached_bytes"] == 0
        assert voxfield.chunk_cache_limit() == 256 << 20
        with pytest.raises(ValueError, match="negative"):
            voxfield.set_chunk_cache_limit(-1)
    finally:
        voxfield.set_chunk_cache_limit(saved)


def test_the_chunk_cache_limit_from_the_environment():
    """VOXFIELD_CHUNK_CACHE sets the limit ("0" in any unit turns the cache off); a value that
    cannot be read stops every transform with an error that names it, until a limit is set."""
    script = (
        "import numpy as np, voxfield\n"
        "from voxfield import ndimage as vn\n"
        "a = np.ones((9, 8, 7), bool); a[4, 4, 4] = False\n"
        "try:\n"
        "    vn.distance_transform_edt(a)\n"
        "    print('ok', voxfield.chunk_cache_limit())\n"
        "except ValueError as e:\n"
        "    print('refused', e)\n"
        "    voxfield.set_chunk_cache_limit(1 << 20)\n"
        "    print('then', vn.distance_transform_edt(a)[0, 0, 0] > 0, voxfield.chunk_cache_limit())\n"
    )

    def run(value):
        env = dict(os.environ, VOXFIELD_CHUNK_CACHE=value)
        return subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True,
                              check=True).stdout.split("\n")

    assert run("64M")[0] == f"ok {64 << 20}"
    assert run("0")[0] == "ok 0"
    assert run("0M")[0] == "ok 0"
    out = run("lots")
    assert out[0].startswith("refused") and "VOXFIELD_CHUNK_CACHE" in out[0]
    assert out[1] == f"then True {1 << 20}"

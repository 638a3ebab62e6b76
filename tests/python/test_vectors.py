"""voxfield.vectors against the definition (voxfield.vectors.exact, double precision), the CLI's
`voxfield vectors` output for the same frames, and its own storage rules (docs/vectors.md).

Run by CTest with PYTHONPATH pointing at the build's python/ directory (and VOXFIELD naming the CLI).
"""

import json
import os
import subprocess

import numpy as np
import pytest

from voxfield import vectors as vv

from gil import ticks_during

VOLUME = dict(centre=(0.5, -1.0, 2.0), size=(6.0, 4.0, 3.0), resolution=(24, 18, 12),
              rotation_degrees=30.0, rotation_axis=(0.3, 0.2, 1.0))


def moving_sources(n, seed):
    rng = np.random.default_rng(seed)
    position = rng.uniform(-2.5, 2.5, (n, 3)) + np.array([0.5, -1.0, 2.0])
    previous = position + rng.normal(0, 0.4, (n, 3))
    radius = rng.uniform(0.2, 1.5, (n, 1))
    return np.hstack([position, previous, radius])


def centres(volume):
    nx, ny, nz = volume.resolution
    return np.array([volume.voxel_centre(i, j, k) for k in range(nz) for j in range(ny) for i in range(nx)])


def test_generation_equals_the_definition_at_every_voxel_centre():
    volume = vv.Volume(**VOLUME)
    sources = moving_sources(12, 1)
    want, winners = vv.exact(centres(volume), sources)
    assert (winners >= 0).sum() > 200 and (winners < 0).sum() > 200  # covered and uncovered voxels
    for algorithm in ("splat", "brute"):
        got = vv.generate(volume, sources, algorithm=algorithm)
        assert got.shape == (24, 18, 12, 4) and got.dtype == np.float32
        flat = np.moveaxis(got, 3, 0).reshape(4, -1, order="F").T  # voxels x fastest, as centres()
        np.testing.assert_allclose(flat, want, rtol=0, atol=1e-6, err_msg=algorithm)
    # Stationary sources as (N, 4) rows are the same as (N, 7) rows that did not move.
    still = sources[:, [0, 1, 2, 6]]
    moved_nowhere = np.hstack([sources[:, :3], sources[:, :3], sources[:, 6:]])
    np.testing.assert_array_equal(vv.generate(volume, still), vv.generate(volume, moved_nowhere))


def test_rgba8_is_the_documented_rounding_of_the_exact_values():
    volume = vv.Volume(**VOLUME)
    sources = moving_sources(8, 2)
    exact = vv.generate(volume, sources, storage="rgba32f").astype(np.float64)
    got = vv.generate(volume, sources, storage="rgba8")
    direction = np.floor((np.clip(exact[..., :3], -1, 1) + 1) / 2 * 255 + 0.5) * 2 / 255 - 1
    strength = np.floor(np.clip(exact[..., 3], 0, 1) * 255 + 0.5) / 255
    np.testing.assert_allclose(got[..., :3], direction, atol=1e-6)
    np.testing.assert_allclose(got[..., 3], strength, atol=1e-6)


@pytest.mark.skipif(not os.environ.get("VOXFIELD"), reason="needs the voxfield CLI")
def test_a_simulation_equals_the_cli_over_the_same_frames(tmp_path):
    frames = [moving_sources(6, 10 + f) for f in range(5)]
    doc = {"frames": [{"sources": [{"position": list(s[:3]), "previous": list(s[3:6]), "radius": s[6]}
                                   for s in frame]} for frame in frames]}
    (tmp_path / "frames.json").write_text(json.dumps(doc))
    c, size = VOLUME["centre"], VOLUME["size"]
    for storage in ("rgba8", "rgba32f"):
        subprocess.run([os.environ["VOXFIELD"], "vectors", str(tmp_path / "frames.json"), "-o",
                        str(tmp_path / "f.npy"), "--resolution", "24,18,12", "--box",
                        ",".join(map(str, [*c, *size])), "--rotation", "30,0.3,0.2,1", "--storage", storage,
                        "--dt", "0.05", "--decay-per-s", "3"], check=True, capture_output=True)
        sim = vv.Simulation(vv.Volume(**VOLUME), storage=storage, decay_per_s=3.0)
        for frame in frames:
            sim.step(frame, 0.05)
        assert sim.steps == 5
        np.testing.assert_array_equal(sim.field(), np.load(tmp_path / "f.npy"), err_msg=storage)


def test_sampling_rendering_and_refusals():
    volume = vv.Volume(centre=(0, 0, 0), size=(4, 4, 4), resolution=(16, 16, 16))
    sim = vv.Simulation(volume, storage="rgba32f", decay_per_s=0.0)
    sim.step(np.array([[0.0, 0.0, 0.0, 1.6]]), 0.1)
    field = sim.field()
    # At a voxel centre the sample is the texel (vector = direction * strength); outside, zero.
    centre = np.array([volume.voxel_centre(10, 8, 8)])
    s = sim.sample(np.vstack([centre, [[9.0, 0.0, 0.0]]]))
    np.testing.assert_allclose(s[0, :3], field[10, 8, 8, :3] * field[10, 8, 8, 3], atol=1e-6)
    np.testing.assert_allclose(s[0, 3], field[10, 8, 8, 3], atol=1e-6)
    assert (s[1] == 0).all()
    # The direction points away from the source.
    assert s[0, 0] > 0
    picture = sim.render(160, 120, sheet=True)
    assert picture.shape == (120, 160, 3) and picture.dtype == np.uint8
    assert len(np.unique(picture.reshape(-1, 3), axis=0)) > 20
    assert set(sim.last_times) >= {"search_ms", "blend_ms", "total_ms"}
    with pytest.raises(ValueError, match="shape"):
        sim.step(np.zeros((3, 5)), 0.1)
    with pytest.raises(ValueError, match="radius"):
        sim.step(np.array([[0.0, 0.0, 0.0, -1.0]]), 0.1)
    with pytest.raises(ValueError, match="time step"):
        sim.step(np.array([[0.0, 0.0, 0.0, 1.0]]), 0.0)
    with pytest.raises(ValueError):
        vv.generate(volume, np.array([[0.0, 0.0, 0.0, 1.0]]), algorithm="bfs")
    with pytest.raises(ValueError):
        vv.Volume(size=(0, 1, 1))
    assert sim.steps == 1  # the refused steps changed nothing
    np.testing.assert_array_equal(sim.field(), field)


def test_the_gil_is_released_while_generating():
    volume = vv.Volume(size=(10, 10, 10), resolution=(128, 128, 128))
    sources = np.random.default_rng(3).uniform(-4, 4, (400, 4))
    sources[:, 3] = 0.5
    elapsed, during = ticks_during(lambda: vv.generate(volume, sources, algorithm="brute"))
    assert elapsed > 0.02 and during >= 10, (elapsed, during)

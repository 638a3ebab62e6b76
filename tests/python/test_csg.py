"""voxfield.csg against NumPy's evaluation of docs/csg.md's definitions and against the CLI."""
import os
import subprocess
import tempfile

import numpy as np
import pytest

import voxfield
from voxfield import csg

MODEL = "(diff (union (sphere 2) (move 3 0 0 (box 2 2 2))) (cylinder 0.5 10))"


def model_numpy(p):
    sphere = np.linalg.norm(p, axis=-1) - 2
    q = np.abs(p - [3, 0, 0]) - 1
    box = np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(-1), 0)
    d = np.stack([np.hypot(p[:, 0], p[:, 1]) - 0.5, np.abs(p[:, 2]) - 5], -1)
    cyl = np.minimum(d.max(-1), 0) + np.linalg.norm(np.maximum(d, 0), axis=-1)
    return np.maximum(np.minimum(sphere, box), -cyl)


def test_evaluate_matches_the_definition():
    m = csg.Model(MODEL)
    pts = np.random.default_rng(1).uniform(-3, 5, (20000, 3))
    got = m.evaluate(pts)
    assert got.shape == (20000,) and got.dtype == np.float64
    assert np.abs(got - model_numpy(pts)).max() < 1e-12
    assert m.label == "bound" and m.shapes == 3
    assert m.bounds == ((-2.0, -2.0, -2.0), (4.0, 2.0, 2.0))


def test_voxelize_equals_the_cli_and_the_definition():
    m = csg.Model(MODEL)
    mats, field = m.voxelize(0.25, box=(-2, -2, -2, 4, 2, 2), field=True)
    assert mats.shape == (24, 16, 16) and field.shape == (24, 16, 16)
    idx = np.indices(mats.shape).reshape(3, -1).T
    centres = np.array([-2, -2, -2]) + (idx + 0.5) * 0.25
    want = model_numpy(centres).reshape(mats.shape)
    assert np.allclose(field, want, atol=1e-5)
    assert ((mats != 0) == (want <= 0)).all()
    cli = os.environ.get("VOXFIELD")
    if cli:
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "m.sdf")
            open(path, "w").write(MODEL)
            out = os.path.join(tmp, "m.npy")
            subprocess.run([cli, "csg", path, "voxelize", "--voxel-size", "0.25", "--box", "-2,-2,-2,4,2,2", "-o", out],
                           check=True, capture_output=True)
            assert (np.load(out) == mats).all()


def test_json_materials_octree_and_mesh():
    m = csg.Model('[["paint", "#ff0000", ["sphere", 1]]]', "red.json")
    red = m.materials(np.zeros((1, 3)))[0]
    assert tuple(m.palette[red]) == (255, 0, 0, 255)
    figures = csg.Model(MODEL).octree(5)
    assert figures["variants"] >= 2 and figures["mean_nodes"] < figures["whole_nodes"]
    v, f, n, c = csg.Model("(box 2 3 4)").mesh(0.37)
    assert v.shape[1] == 3 and f.shape[1] == 3 and f.max() < len(v) and len(n) == len(v)
    # Dual contouring with exact Hermite data: the corners are vertices.
    assert np.abs(v - [1, 1.5, 2]).sum(1).min() < 1e-5


def test_errors_name_line_and_column():
    with pytest.raises(csg.ModelError, match=r"m.sdf:2:4: unknown shape or operation \"sphre\""):
        csg.Model("(union\n  (sphre 1))", "m.sdf")
    with pytest.raises(ValueError):
        csg.Model("(sphere -1)")
    with pytest.raises(ValueError, match="unbounded"):
        csg.Model("(plane 0 0 1 0)").voxelize(1.0)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        csg.Model(MODEL).evaluate(np.zeros((4, 2)))
    with pytest.raises(MemoryError):
        csg.Model("(sphere 100)").voxelize(1e-5)

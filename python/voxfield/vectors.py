"""Dynamic vector-field volume textures (docs/vectors.md): moving sources rendered into a 3-D
texture, decayed and blended step by step, as games use them to push grass, water and particles.

``Volume(centre=(0, 0, 0), size=(1, 1, 1), resolution=(64, 64, 64), rotation_degrees=0,
rotation_axis=(0, 0, 1))`` is the oriented box. Sources are float64 rows: (N, 4) ``x, y, z,
radius`` for stationary sources, (N, 7) ``x, y, z, previous x, y, z, radius`` for moving ones (a
source covers the segment it moved along).

- ``generate(volume, sources, algorithm="splat", rule="strongest", storage="rgba32f")``: one
  generation, float32 ``a[i, j, k, 4]`` (direction x, y, z in world space, strength), decoded from
  the storage; ``i`` runs along the box's x axis, as in the CLI's .npy output;
- ``exact(points, sources, rule="strongest")``: the definition at world points in double precision,
  ``(values (N, 4), winners (N,))``;
- ``Simulation(volume, storage="rgba8", algorithm="splat", rule="strongest", decay_per_s=1.0)``:
  ``step(sources, dt)``, ``field()`` and ``current()`` as arrays, ``sample(points)`` (trilinear,
  zero outside the box), ``render(width, height, eye=None, sheet=False)`` (the visualiser's
  picture, uint8 (height, width, 3)), ``steps``, ``last_times``.

The GIL is released while voxfield works; Ctrl-C stops a generation (``voxfield.Cancelled``).
Bad sources or volumes raise ``voxfield.InvalidArgument`` (a ValueError) naming what is wrong.
"""

from ._voxfield.vectors import Simulation, Volume, exact, generate

__all__ = ["Simulation", "Volume", "exact", "generate"]

#!/usr/bin/env python3
"""Checks voxfield's layering: which header each source may include (run as a test).

The rules (docs/architecture.md):
- the layers, lowest first: core, gpu, distance, vectors, csg, mesh, io, render, live; every public header
  (include/voxfield/...) belongs to one, and a public header or a module's source includes public
  headers of its own layer or of one beneath only;
- a module is a directory of src/ (grid, edit and scene make up core); its private headers are for
  itself: a source never includes another module's private header, except the GPU compute layer's
  internal interface (INTERNAL_INTERFACE below), which the modules' GPU halves build on;
- public headers include only public headers; applications, benchmarks and fuzz harnesses include
  public headers and their own directory's files; tests may also include src/ internals (the few
  tests of internals say so where they do).
Usage: check_layers.py [REPO]   Exit status 1 and one line per violation when any is found.
"""
import pathlib
import re
import sys

LAYERS = ["core", "gpu", "distance", "vectors", "csg", "mesh", "io", "render", "live", "mpi"]
MODULE_LAYER = {"grid": "core", "edit": "core", "scene": "core", "gpu": "gpu", "distance": "distance",
                "vectors": "vectors", "csg": "csg", "mesh": "mesh", "io": "io", "render": "render", "live": "live", "mpi": "mpi"}
PUBLIC_LAYER = {
    "box.h": "core", "error.h": "core", "parallel.h": "core", "limits.h": "core", "chunk_memory.h": "core", "grid.h": "core",
    "detail/grid_impl.h": "core", "detail/assert.h": "core", "detail/vector_clones.h": "core", "world.h": "core", "edit.h": "core", "edit_stream.h": "core",
    "scene.h": "core", "image.h": "core", "interrupt.h": "core", "primitives.h": "core", "png.h": "io",
    "hash.h": "core", "voxel_frame.h": "core",
    "gpu.h": "gpu", "gpu_vulkan.h": "gpu",
    "distance.h": "distance", "algorithms.h": "distance", "dynamic_field.h": "distance",
    "dissertation_format.h": "distance", "gpu_distance.h": "distance", "distance_executor.h": "distance", "distance_slab.h": "distance",
    "vectors.h": "vectors", "vector_world.h": "vectors", "gpu_vectors.h": "vectors", "vector_agents.h": "vectors", "gpu_vectors_vulkan.h": "vectors", "vector_files.h": "io",
    "csg.h": "csg", "csg_compile.h": "csg", "csg_files.h": "io",
    "mesh.h": "mesh", "mesh_chunks.h": "mesh", "mesh_pieces.h": "mesh", "mesh_slab.h": "mesh", "terrain.h": "mesh", "gpu_mesh.h": "mesh", "gpu_terrain.h": "mesh", "gpu_terrain_vulkan.h": "mesh", "csg_mesh.h": "mesh", "mesh_optimize.h": "mesh", "mesh_files.h": "io", "mesh_voxelize.h": "mesh", "mesh_read.h": "io",
    "file.h": "io", "npy.h": "io", "vox.h": "io", "world_file.h": "io", "world_io.h": "io", "vdb.h": "io",
    "edit_script.h": "io",
    "render.h": "render", "mesh_render.h": "render", "csg_render.h": "render", "gpu_render.h": "render", "gpu_render_vulkan.h": "render", "render_executor.h": "render", "render_relay.h": "render",
    "live_world.h": "live", "mpi.h": "mpi",
}
# Headers of the GPU compute layer that the modules above it may include (its internal interface).
INTERNAL_INTERFACE = {"src/gpu/vulkan_context.h", "src/gpu/kernel.h", "src/gpu/recorder.h",
                      "src/gpu/graphics.h", "src/gpu/split_buffer.h",
                      "src/gpu/shader_source.h", "src/gpu/unavailable.h", "shaders/layout.h"}
# Headers generated in the build tree: each module's list of embedded shaders
# (voxfield_embed_shaders in src/CMakeLists.txt), private to that module (and its tests).
GENERATED = {"distance_shaders.h": "distance", "render_shaders.h": "render", "vectors_shaders.h": "vectors", "mesh_shaders.h": "mesh"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCES = (".h", ".hpp", ".cpp", ".cc")


def rank(layer):
    return LAYERS.index(layer)


def resolve(repo, source, name):
    """The repository path a quoted include names: beside the source, else under its top directory
    (bench/ includes bench/bench_util.h), src/ or the root (the library's include directories)."""
    top = repo / source.relative_to(repo).parts[0]
    for base in (source.parent, top, repo / "src", repo):
        candidate = (base / name).resolve()
        if candidate.is_file():
            return candidate.relative_to(repo.resolve()).as_posix()
    return None


def check(repo):
    problems = []
    for name in sorted(p.relative_to(repo / "include/voxfield").as_posix()
                       for p in (repo / "include/voxfield").rglob("*.h")):
        if name not in PUBLIC_LAYER:
            problems.append(f"include/voxfield/{name}: a public header with no layer (add it to "
                            "scripts/check_layers.py)")
    for top in ("src", "include", "apps", "bench", "fuzz", "tests"):
        for path in sorted((repo / top).rglob("*")):
            if path.suffix not in SOURCES or not path.is_file():
                continue
            rel = path.relative_to(repo).as_posix()
            parts = rel.split("/")
            module = parts[1] if top == "src" and len(parts) > 2 else None
            if top == "src" and module not in MODULE_LAYER:
                problems.append(f"{rel}: src/{parts[1]} is not a module of any layer")
                continue
            if top == "include":
                layer = PUBLIC_LAYER.get("/".join(parts[2:]))
            else:
                layer = MODULE_LAYER.get(module)
            text = path.read_text(encoding="utf-8", errors="replace")
            for line_no, included in ((text.count("\n", 0, m.start()) + 1, m.group(1))
                                      for m in INCLUDE.finditer(text)):
                where = f"{rel}:{line_no}: #include \"{included}\""
                if included.startswith("voxfield/"):
                    target = PUBLIC_LAYER.get(included[len("voxfield/"):])
                    if target is None:
                        if not (repo / "include" / included).is_file():
                            problems.append(f"{where}: no such public header")
                        continue
                    if layer is not None and rank(target) > rank(layer):
                        problems.append(f"{where}: the {layer} layer includes the {target} layer above it")
                    continue
                if top == "include":
                    problems.append(f"{where}: a public header includes a private one")
                    continue
                if included in GENERATED:
                    if top == "src" and GENERATED[included] != module:
                        problems.append(f"{where}: the {GENERATED[included]} module's generated header")
                    continue
                target = resolve(repo, path, included)
                if target is None:
                    if top != "fuzz":  # harnesses may include headers of the build tree
                        problems.append(f"{where}: no such file")
                    continue
                if top == "src":
                    if target.startswith(f"src/{module}/"):
                        continue
                    if target in INTERNAL_INTERFACE and rank(layer) >= rank("gpu"):
                        continue
                    problems.append(f"{where}: reaches into another module's private header ({target})")
                elif top == "tests":
                    continue
                elif not target.startswith("/".join(parts[:2]) + "/") and not target.startswith(f"{top}/"):
                    problems.append(f"{where}: reaches outside {parts[0]}/ ({target})")
                elif target.startswith("src/"):
                    problems.append(f"{where}: includes a private header of the library ({target})")
    return problems


def self_test():
    """The check on a made-up tree with one violation of each kind (and allowed includes beside
    them): it must report exactly the violations."""
    import tempfile
    files = {
        "include/voxfield/box.h": '#include "grid_private.h"\n',            # public includes private
        "include/voxfield/render.h": '#include "voxfield/box.h"\n',
        "include/voxfield/unlisted.h": "",                                   # no layer
        "src/grid/grid_private.h": "",
        "src/grid/a.cpp": '#include "voxfield/render.h"\n#include "grid_private.h"\n',  # upward
        "src/gpu/vulkan_context.h": "",
        "src/render/b.cpp": '#include "../grid/grid_private.h"\n',          # reach-in
        "src/render/gpu/c.cpp": '#include "gpu/vulkan_context.h"\n#include "voxfield/box.h"\n',
        "apps/cli/d.cpp": '#include "../../src/grid/grid_private.h"\n',     # app reaches into src
        "tests/t.cpp": '#include "grid/grid_private.h"\n',                  # allowed for tests
    }
    expected = ["include/voxfield/unlisted.h:", "include/voxfield/box.h:1:", "src/grid/a.cpp:1:",
                "src/render/b.cpp:1:", "apps/cli/d.cpp:1:"]
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        for name, text in files.items():
            (root / name).parent.mkdir(parents=True, exist_ok=True)
            (root / name).write_text(text)
        problems = check(root)
    found = sorted(next((e for e in expected if p.startswith(e)), p) for p in problems)
    if found != sorted(expected):
        print("self-test: expected violations", sorted(expected), "got", problems)
        return 1
    print(f"layering self-test: the {len(expected)} planted violations found, nothing else")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    repo = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
    problems = check(repo)
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} layering violation(s)", file=sys.stderr)
        return 1
    print("layering: no violations")
    return 0


if __name__ == "__main__":
    sys.exit(main())

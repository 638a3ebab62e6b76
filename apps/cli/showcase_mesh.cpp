// voxfield showcase — the meshing section: the terrain through marching cubes, surface nets and
// dual contouring, checked closed and seamless, pictured, exported, and set beside scikit-image and
// VTK on the same signed distance field.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "cli.h"
#include "showcase.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_optimize.h"
#include "voxfield/mesh_render.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"
#include "voxfield/png.h"

namespace voxfield::cli {

namespace fs = std::filesystem;

namespace {

double mesh_bytes_per_triangle(const Mesh& m) {
  const double bytes = static_cast<double>(m.positions.size() * 12 + m.normals.size() * 12 +
                                           m.colors.size() * 3 + m.indices.size() * 4);
  return m.triangle_count() ? bytes / static_cast<double>(m.triangle_count()) : 0;
}

// An order-independent hash of the triangle set: each triangle's three positions (rotated to
// start at the smallest, so orientation counts) hashed, and the hashes summed.
std::uint64_t triangle_hash(const Mesh& m) {
  std::uint64_t sum = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    std::array<std::array<float, 3>, 3> tri{m.positions[m.indices[3 * t]],
                                            m.positions[m.indices[3 * t + 1]],
                                            m.positions[m.indices[3 * t + 2]]};
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the nine floats' bytes
    for (const auto& p : tri)
      for (const float c : p) {
        std::uint32_t bits;
        std::memcpy(&bits, &c, 4);
        for (int k = 0; k < 4; ++k) h = (h ^ ((bits >> (8 * k)) & 0xFF)) * 1099511628211ull;
      }
    sum += h;
  }
  return sum;
}

// Runs the peers' script on the field; null when Python, the script or the peers are missing.
nlohmann::json run_peers(const fs::path& script, const fs::path& sdf_npy, const fs::path& out) {
  if (!fs::exists(script) || !fs::exists("/usr/bin/python3")) return nullptr;
  const fs::path result = out / "mesh-peers.json";
  const std::string command = "/usr/bin/python3 '" + script.string() + "' '" + sdf_npy.string() +
                              "' 0 --runs 2 --json '" + result.string() + "' 2>/dev/null";
  if (std::system(command.c_str()) != 0 || !fs::exists(result)) return nullptr;
  nlohmann::json j = nlohmann::json::parse(std::ifstream(result));
  fs::remove(result);
  return j;
}

// The terrain world edited with its mesh kept (WorldMeshChunks): seeded spheres placed, carved
// and painted on the surface, each re-meshing only the chunks it reaches; the kept mesh checked
// against mesh_world of the edited world, and pictured.
void showcase_world_mesh_edits(const World& terrain, const Camera& hero,
                               const MeshRenderOptions& ro, const fs::path& out, std::ostream& md,
                               std::vector<Timing>& timings) {
  World world = terrain;
  MeshOptions mo;
  mo.chunk_edge = 16;
  auto t0 = std::chrono::steady_clock::now();
  WorldMeshChunks kept(world, mo);
  const double first_ms = ms_since(t0);
  const Box3i content = world.voxels.content_bounds();
  std::mt19937 rng(6683787);
  constexpr int kEdits = 60;
  std::vector<double> update_ms;
  std::size_t remeshed = 0;
  for (int e = 0; e < kEdits; ++e) {
    const int x =
        content.begin.x + static_cast<int>(rng() % static_cast<unsigned>(content.size().x));
    const int y =
        content.begin.y + static_cast<int>(rng() % static_cast<unsigned>(content.size().y));
    int z = content.end.z - 1;
    while (z > content.begin.z && world.voxels.get({x, y, z}) == 0) --z;
    Edit edit;
    edit.op = e % 3 == 0 ? EditOp::kCarve : e % 3 == 1 ? EditOp::kPlace : EditOp::kPaint;
    edit.material = static_cast<std::uint8_t>(1 + e % 7);
    edit.brush =
        SphereBrush{{double(x), double(y), double(z)}, 2.0 + static_cast<double>(rng() % 3)};
    DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
    apply_edit(world, edit, &dirty);
    t0 = std::chrono::steady_clock::now();
    remeshed += kept.update(dirty).size();
    update_ms.push_back(ms_since(t0));
  }
  const Mesh mine = kept.merged(), fresh = mesh_world(world, mo);
  const bool same = mine.triangle_count() == fresh.triangle_count() &&
                    mine.vertex_count() == fresh.vertex_count() &&
                    triangle_hash(mine) == triangle_hash(fresh);
  if (!same) throw Error("showcase: the kept world mesh differs from meshing the edited world");
  std::sort(update_ms.begin(), update_ms.end());
  const double p50 = update_ms[update_ms.size() / 2], worst = update_ms.back();
  t0 = std::chrono::steady_clock::now();
  static_cast<void>(mesh_world(world, mo));
  const double scratch_ms = ms_since(t0);
  timings.push_back({"edit the terrain world with its mesh kept: one edit (median of " +
                         std::to_string(kEdits) + ")",
                     p50, fixed(scratch_ms / p50, 0) + "× faster than meshing it again"});
  write_png(render_mesh(mine, hero, ro), out / "terrain-mesh-edited.png");
  const Vec3i count = kept.chunk_count();
  md << "\n**Edited with its mesh kept.** `WorldMeshChunks` keeps the world's surface per chunk "
        "(chunks of "
     << mo.chunk_edge << " cells, first mesh " << fixed(first_ms, 0) << " ms): " << kEdits
     << " seeded spheres carved, placed and painted on the surface, each followed by an update "
        "of the exact signed field where it reaches and a re-mesh of the chunks that read it — "
     << fixed(static_cast<double>(remeshed) / kEdits, 1) << " of " << count.x * count.y * count.z
     << " chunks per edit, " << fixed(p50, 2) << " ms at the median (slowest " << fixed(worst, 2)
     << " ms) against " << fixed(scratch_ms, 0)
     << " ms to mesh the edited world again; the kept mesh has **exactly the triangles of "
        "meshing the edited world from scratch** ("
     << mine.triangle_count() << ").\n\n![edited](terrain-mesh-edited.png)\n";
}

}  // namespace

void showcase_meshing(const World& terrain, int world_size, const fs::path& out,
                      const fs::path& sdf_npy, const fs::path& peers_script, const Camera& hero,
                      std::ostream& md, std::vector<Timing>& timings) {
  md << "\n## Meshes of the terrain\n\n"
     << "The terrain's surface as triangles, through its exact signed Euclidean field (`voxfield "
        "mesh`): marching "
        "cubes with ambiguous faces settled by the asymptotic decider (a closed, oriented "
        "2-manifold), naive "
        "surface nets (one vertex per cell, closed, not always manifold) and dual contouring "
        "(surface nets' "
        "topology, each vertex where the crossings' tangent planes meet: the voxels' edges and "
        "corners stay "
        "sharp). A whole volume is meshed in Flying Edges' passes on all threads (rows counted, "
        "then "
        "every vertex and triangle written once in place); on one thread the same triangles come "
        "out.\n\n"
     << "| mesher | triangles | vertices | ms | watertight | Euler characteristic | area (voxel "
        "faces) | bytes/triangle | "
        "one thread: same triangles |\n|---|---|---|---|---|---|---|---|---|\n";
  const Vec3i size = terrain.voxels.content_bounds().size();
  Mesh meshes[3];
  const Mesher kinds[3] = {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring};
  const char* names[3] = {"marching cubes", "surface nets", "dual contouring"};
  for (int i = 0; i < 3; ++i) {
    MeshOptions o;
    o.algorithm = kinds[i];
    const auto t0 = std::chrono::steady_clock::now();
    meshes[i] = mesh_world(terrain, o);
    const double ms = ms_since(t0);
    const MeshStats st = mesh_stats(meshes[i]);
    Mesh one_thread;
    {
      ThreadLimit limit(1);
      one_thread = mesh_world(terrain, o);
    }
    const bool same = triangle_hash(one_thread) == triangle_hash(meshes[i]) &&
                      one_thread.triangle_count() == meshes[i].triangle_count() &&
                      one_thread.vertex_count() == meshes[i].vertex_count() &&
                      mesh_stats(one_thread).edges == st.edges;
    timings.push_back(
        {std::string("mesh the terrain, ") + mesher_name(kinds[i]) + " (field included)", ms,
         fixed(static_cast<double>(st.triangles) / (ms * 1e3), 1) + " M triangles/s"});
    md << "| " << names[i] << " | " << st.triangles << " | " << st.vertices << " | " << fixed(ms, 0)
       << " | " << (st.watertight() ? "yes" : (st.boundary_edges == 0 ? "closed" : "**no**"))
       << " | " << st.euler_characteristic << " | " << fixed(st.area_units2, 0) << " | "
       << fixed(mesh_bytes_per_triangle(meshes[i]), 1) << " | " << (same ? "yes" : "**no**")
       << " |\n";
    std::cout << "voxfield showcase: " << mesher_name(kinds[i])
              << " mesh of the terrain: " << st.triangles << " triangles in " << fixed(ms, 0)
              << " ms\n";
    if (!same) throw Error("showcase: meshing on one thread changed the terrain's mesh");
  }
  write_mesh(meshes[0], out / "terrain.glb");
  write_mesh(meshes[1], out / "terrain-sn.ply");
  write_mesh(meshes[2], out / "terrain-dc.obj");
  static_cast<void>(size);

  // The peers, on the very same field (the terrain's signed Euclidean field over its box).
  const NpyVolume sdf = read_npy(sdf_npy);
  if (sdf.dtype != DType::kFloat32)
    throw Error("showcase: " + sdf_npy.string() + " is not float32");
  std::vector<float> values(static_cast<std::size_t>(sdf.count()));
  std::memcpy(values.data(), sdf.bytes.data(), values.size() * sizeof(float));
  ScalarVolume volume{sdf.dims, values.data()};
  MeshOptions mo;
  double ours_ms = 1e300;
  std::size_t ours_triangles = 0;
  for (int run = 0; run < 2; ++run) {
    const auto t0 = std::chrono::steady_clock::now();
    const Mesh m = mesh_volume(volume, mo);
    ours_ms = std::min(ours_ms, ms_since(t0));
    ours_triangles = m.triangle_count();
  }
  const nlohmann::json peers = run_peers(peers_script, sdf_npy, out);
  md << "\nMarching cubes of `terrain-sdf.npy` at level 0 (" << sdf.dims.x
     << "³ samples), voxfield beside its peers "
        "in this run (best of 2):\n\n| library | threads | ms | triangles | voxfield's speed-up "
        "|\n|---|---|---|---|---|\n"
     << "| voxfield " << mesher_name(Mesher::kMarchingCubes) << " | " << max_threads() << " | "
     << fixed(ours_ms, 0) << " | " << ours_triangles << " | |\n";
  bool any_peer = false;
  if (!peers.is_null())
    for (const char* name : {"scikit-image", "vtk-flying-edges"}) {
      if (!peers.contains(name) || peers[name].is_null()) continue;
      const auto& p = peers[name];
      any_peer = true;
      md << "| " << name << " " << p["version"].get<std::string>() << " | "
         << p["threads"].get<int>() << " | " << fixed(p["ms"].get<double>(), 0) << " | "
         << p["triangles"].get<std::int64_t>() << " | " << fixed(p["ms"].get<double>() / ours_ms, 1)
         << "× |\n";
    }
  if (!any_peer)
    md << "\n(The peers were not run: Debian's python3-skimage / python3-vtk9 are not installed, "
          "see "
          "scripts/install-bench-deps.sh.)\n";

  // Pictures: the whole terrain from the hero camera, and a close-up with the triangles' edges.
  MeshRenderOptions ro;
  ro.width = picture_pixels(1280, world_size);
  ro.height = picture_pixels(720, world_size);
  const Box3i content = terrain.voxels.content_bounds();
  const int cx = (content.begin.x + content.end.x) / 2, cy = (content.begin.y + content.end.y) / 2;
  const int r = std::max(8, content.size().x / 8);
  Box3i close{{cx - r, cy - r, content.begin.z}, {cx + r, cy + r, content.end.z}};
  for (int z = content.end.z - 1; z >= content.begin.z; --z)  // frame the surface around the centre
    if (terrain.voxels.get({cx, cy, z})) {
      close.begin.z = std::max(content.begin.z, z - r);
      close.end.z = std::min(content.end.z, z + r);
      break;
    }
  const Camera near = Camera::framing(close, 16.0 / 9.0);
  for (int i = 0; i < 3; ++i) {
    const std::string tag = mesher_name(kinds[i]);
    MeshRenderStats st;
    write_png(render_mesh(meshes[i], hero, ro, &st), out / ("terrain-mesh-" + tag + ".png"));
    timings.push_back({"picture of the " + tag + " mesh (CPU rasteriser, " +
                           std::to_string(ro.width) + "×" + std::to_string(ro.height) + ")",
                       st.ms, ""});
    MeshRenderOptions edges = ro;
    edges.edges = true;
    write_png(render_mesh(meshes[i], near, edges), out / ("terrain-mesh-" + tag + "-edges.png"));
  }
  // The marching-cubes mesh simplified to a tenth (meshoptimizer's quadric edge collapse) for
  // distant chunks or export.
  SimplifyOptions so;
  so.triangle_ratio = 0.1;
  SimplifyStats sst;
  auto ts = std::chrono::steady_clock::now();
  Mesh simple = simplify_mesh(meshes[0], so, &sst);
  optimize_mesh(simple);
  const double simplify_ms = ms_since(ts);
  timings.push_back({"simplify the marching-cubes mesh to 10 % and order it for the vertex cache",
                     simplify_ms, ""});
  write_png(render_mesh(simple, hero, ro), out / "terrain-mesh-simplified.png");
  write_mesh(simple, out / "terrain-simplified.glb");
  md << "\nSimplified to a tenth with meshoptimizer (quadric edge collapse, borders locked; error "
        "limit 1 % of "
        "the extent): "
     << sst.triangles_before << " → " << sst.triangles_after << " triangles in "
     << fixed(simplify_ms, 0) << " ms, largest deviation " << fixed(sst.error_units, 2)
     << " voxels (`terrain-simplified.glb`).\n\n"
     << "![simplified](terrain-mesh-simplified.png)\n";

  showcase_world_mesh_edits(terrain, hero, ro, out, md, timings);

  md << "\n| marching cubes | surface nets | dual contouring |\n|---|---|---|\n"
     << "| ![mc](terrain-mesh-mc.png) | ![sn](terrain-mesh-sn.png) | ![dc](terrain-mesh-dc.png) |\n"
     << "| ![mc edges](terrain-mesh-mc-edges.png) | ![sn edges](terrain-mesh-sn-edges.png) | "
        "![dc edges](terrain-mesh-dc-edges.png) |\n\n"
     << "Files: `terrain.glb` (marching cubes, glTF binary with vertex colours: drop it into any "
        "glTF viewer) and "
        "`terrain-sn.ply` (surface nets), `terrain-dc.obj` (dual contouring).\n";
}

}  // namespace voxfield::cli

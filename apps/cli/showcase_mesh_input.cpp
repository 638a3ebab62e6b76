// voxfield showcase — the meshes-in section: a 96³ block of the terrain meshed by surface nets,
// written as OBJ, read back and voxelised by its winding number (set against the block it came
// from), its signed distance field dense and as a band, and — when scripts/fetch-test-meshes.sh
// has fetched it — the Stanford bunny voxelised, pictured and saved as .vox, and, in its frame
// (the mesh's units), as .vfw and meshed again where the bunny was.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>

#include "cli.h"
#include "showcase.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_read.h"
#include "voxfield/png.h"
#include "voxfield/vox.h"
#include "voxfield/world_file.h"

namespace voxfield::cli {

namespace fs = std::filesystem;

void showcase_mesh_input(const World& terrain, int size, const fs::path& out, std::ostream& md,
                         std::vector<Timing>& timings) {
  // A 96³ block from the terrain's middle, as a world of its own (air around it: a closed surface).
  const Box3i whole =
      terrain.voxels.bounds() ? *terrain.voxels.bounds() : terrain.voxels.content_bounds();
  Vec3i lo;
  for (int k = 0; k < 3; ++k)
    lo[k] = whole.begin[k] + std::max(0, static_cast<int>(whole.extent(k)) / 2 - 48);
  const Box3i block = Box3i{lo, lo + Vec3i::splat(96)}.intersect(whole);
  World piece(Grid<std::uint8_t>::kDefaultChunkEdge);
  std::vector<std::uint8_t> voxels(static_cast<std::size_t>(block.volume()));
  terrain.voxels.copy_to_dense(block, voxels.data());
  piece.voxels.copy_from_dense(block, voxels.data());
  MeshOptions mo;
  mo.algorithm = Mesher::kSurfaceNets;
  write_mesh(mesh_world(piece, mo), out / "terrain-block.obj");
  md << "\n## Meshes in\n\n"
     << "A " << to_string(block.size())
     << " block of the terrain, meshed by surface nets into "
        "`terrain-block.obj`, read back and voxelised where its generalized winding number is at "
        "least ½ (docs/mesh_input.md), against the block it was meshed from; then its signed "
        "distance field, dense and as a 3-voxel band.\n\n";
  auto t = std::chrono::steady_clock::now();
  const TriangleMesh mesh = read_mesh(out / "terrain-block.obj");
  const double read_ms = ms_since(t);
  MeshVoxelOptions vo;
  vo.voxel_size = 1;
  vo.padding_voxels = 0;
  t = std::chrono::steady_clock::now();
  const World back = voxelize_mesh(mesh, vo);
  const double voxelise_ms = ms_since(t);
  // The mesh runs through the centres of the boundary's samples, so a voxel on it may go either
  // way: count the voxels where the two worlds differ.
  const Box3i box = *back.voxels.bounds();
  std::int64_t differ = 0;
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x)
        differ += (piece.voxels.get({x, y, z}) != 0) != (back.voxels.get({x, y, z}) != 0);
  MeshDistanceOptions fo;
  fo.voxel_size = 1;
  t = std::chrono::steady_clock::now();
  const MeshDistanceField dense = mesh_distance_field(mesh, fo);
  const double dense_ms = ms_since(t);
  fo.max_distance = 3;
  t = std::chrono::steady_clock::now();
  const MeshDistanceField band = mesh_distance_field(mesh, fo);
  const double band_ms = ms_since(t);
  md << "| step | result | ms |\n|---|---|---|\n"
     << "| read terrain-block.obj | " << mesh.triangles.size() << " triangles, "
     << mesh.positions.size() << " vertices | " << fixed(read_ms, 0) << " |\n"
     << "| voxelise (voxel 1) | " << back.solid_count() << " solid voxels; " << differ
     << " differ from the block's " << piece.solid_count() << " | " << fixed(voxelise_ms, 0)
     << " |\n"
     << "| signed distance field, dense | " << to_string(dense.box.size()) << " samples, "
     << dense.band_voxels << " exact in the band | " << fixed(dense_ms, 0) << " |\n"
     << "| signed distance field, clamped at 3 voxels | the same samples | " << fixed(band_ms, 0)
     << " |\n";
  timings.push_back({"voxelise a terrain block's surface-nets mesh (winding number)", voxelise_ms,
                     std::to_string(mesh.triangles.size()) + " triangles"});
  timings.push_back({"signed distance field of that mesh, dense", dense_ms, ""});
  timings.push_back({"signed distance field of that mesh, a 3-voxel band", band_ms, ""});
  std::cout << "voxfield showcase: a terrain block's mesh voxelised back in "
            << fixed(voxelise_ms, 0) << " ms, " << differ << " voxels differ\n";

  const fs::path bunny_path =
      fs::path(std::getenv("VOXFIELD_TEST_MESHES") ? std::getenv("VOXFIELD_TEST_MESHES")
                                                   : "/var/cache/voxfield/test-meshes") /
      "bunny.obj";
  if (!fs::exists(bunny_path)) {
    md << "\n(The Stanford bunny was not voxelised: run scripts/fetch-test-meshes.sh.)\n";
    return;
  }
  TriangleMesh bunny = read_mesh(bunny_path);
  // The bunny stands on y (OBJ's habit); voxfield's worlds stand on z: a quarter turn about x.
  for (auto& p : bunny.positions) p = {p[0], -p[2], p[1]};
  MeshVoxelOptions bo;
  // 0.012 units (the bunny about 130 voxels tall) at the default size; coarser in the small runs
  // the tests make, as the pictures are (picture_pixels).
  bo.voxel_size = 0.012 * 256 / std::clamp(size, 64, 256);
  bo.padding_voxels = 0;
  t = std::chrono::steady_clock::now();
  World bunny_world = voxelize_mesh(bunny, bo);
  const double bunny_ms = ms_since(t);
  for (int m = 1; m < 256; ++m) bunny_world.palette[m] = {222, 196, 160, 255};
  write_vox(bunny_world, out / "bunny.vox");
  const RenderScene scene(bunny_world);
  RenderOptions ro;
  ro.width = ro.height = picture_pixels(720, size);
  const Camera cam = Camera::framing(bunny_world.voxels.content_bounds(), 1.0);
  write_png(render(scene, cam, ro), out / "bunny.png");
  md << "\nThe Stanford bunny (`" << bunny_path.string() << "`, " << bunny.triangles.size()
     << " triangles, from Debian's glmark2-data) voxelised at " << bo.voxel_size << ": "
     << bunny_world.solid_count() << " voxels in " << fixed(bunny_ms, 0)
     << " ms, saved as `bunny.vox`.\n\n![the bunny](bunny.png)\n";
  std::ostringstream at;
  at << bo.voxel_size;
  timings.push_back({"voxelise the Stanford bunny (" + std::to_string(bunny.triangles.size()) +
                         " triangles) at " + at.str(),
                     bunny_ms, std::to_string(bunny_world.solid_count()) + " voxels"});
  // The voxelised bunny keeps the mesh's units as its frame (docs/frames.md): meshed again, it
  // lands where the bunny was, and its .vfw keeps the frame for the next tool.
  write_world_file(bunny_world, out / "bunny.vfw");
  MeshOptions again;
  again.algorithm = Mesher::kSurfaceNets;
  t = std::chrono::steady_clock::now();
  const Mesh remeshed = mesh_world(bunny_world, again);
  const double remesh_ms = ms_since(t);
  write_mesh(remeshed, out / "bunny-remeshed.obj");
  std::array<double, 3> lo_in{1e300, 1e300, 1e300}, hi_in{-1e300, -1e300, -1e300};
  std::array<double, 3> lo_out = lo_in, hi_out = hi_in;
  auto widen = [](std::array<double, 3>& lo, std::array<double, 3>& hi, const auto& p) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<double>(p[a]));
      hi[a] = std::max(hi[a], static_cast<double>(p[a]));
    }
  };
  for (const auto& p : bunny.positions) widen(lo_in, hi_in, p);
  for (const auto& p : remeshed.positions) widen(lo_out, hi_out, p);
  double off = 0;
  for (int a = 0; a < 3; ++a)
    off = std::max({off, std::abs(lo_in[a] - lo_out[a]), std::abs(hi_in[a] - hi_out[a])});
  md << "\nIn its frame (origin 0, voxel size " << bo.voxel_size
     << ", the mesh's units; `bunny.vfw` keeps it), the "
        "voxelised bunny meshed again by surface nets (`bunny-remeshed.obj`, "
     << remeshed.triangle_count() << " triangles, " << fixed(remesh_ms, 0)
     << " ms) lands on the bunny: its bounding box is within " << fixed(off / bo.voxel_size, 2)
     << " voxels (" << fixed(off, 4) << " units) of the original's.\n";
  std::cout << "voxfield showcase: bunny.png, bunny.vox, bunny.vfw, bunny-remeshed.obj (in the "
               "bunny's units, its box within "
            << fixed(off / bo.voxel_size, 2) << " voxels of the original's)\n";

  // The bunny as a scanner of thick slices sees it: voxels three times as tall as wide (the mesh
  // squashed by three along z, voxelised, then given voxels of s x s x 3s). The camera placed in
  // the bunny's units frames the picture above; through the slices' frame it draws the same
  // bunny in the same place, in steps of the slices' height (docs/frames.md).
  TriangleMesh squashed = bunny;
  for (auto& p : squashed.positions) p[2] /= 3;
  t = std::chrono::steady_clock::now();
  World slices = voxelize_mesh(squashed, bo);
  const double slices_ms = ms_since(t);
  slices.palette = bunny_world.palette;
  slices.frame.voxel_size_world.z *= 3;
  slices.frame.origin_world.z *= 3;
  Camera placed = cam;  // the camera above, in the bunny's units
  placed.eye = bunny_world.frame.world_from_vox(cam.eye);
  placed.target = bunny_world.frame.world_from_vox(cam.target);
  placed.up = bunny_world.frame.world_direction(cam.up);
  write_png(render(RenderScene(slices), placed.in_voxels(slices.frame), ro),
            out / "bunny-slices.png");
  md << "\nThe bunny as a scanner of thick slices sees it — voxels of " << bo.voxel_size << " × "
     << bo.voxel_size << " × " << 3 * bo.voxel_size << " (" << slices.solid_count()
     << " voxels, voxelised in " << fixed(slices_ms, 0)
     << " ms) — drawn by the same camera placed in the bunny's units: the same bunny in the same "
        "place, in steps of the slices' height.\n\n![the bunny in thick "
        "slices](bunny-slices.png)\n";
  std::cout << "voxfield showcase: bunny-slices.png (voxels of three to one, a camera in the "
               "bunny's units)\n";
}

}  // namespace voxfield::cli

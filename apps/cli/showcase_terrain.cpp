// voxfield showcase — the deformable terrain section: smooth hills in a quantised terrain field,
// shaped by brushes (a smooth hill, a tunnel, a sharp plateau, a crater, a dug trench), each edit
// re-meshing only the chunks it reaches; the three storage widths side by side; pictures before
// and after, and the edited terrain as a .glb; then, on a Vulkan device, the same edits drawn the
// thesis's way (gpu_terrain.h) with the bytes each edit uploads.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>

#include "cli.h"
#include "showcase.h"
#include "voxfield/error.h"
#include "voxfield/gpu_terrain.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_render.h"
#include "voxfield/png.h"
#include "voxfield/terrain.h"

namespace voxfield::cli {

namespace fs = std::filesystem;

namespace {

constexpr Vec3i kSize{192, 192, 96};

double height(double x, double y) {
  return 34 + 9 * std::sin(x / 17) * std::cos(y / 23) + 5 * std::sin((x + 2 * y) / 41);
}

// The edits, in order: named, so the report can list them.
struct NamedBrush {
  const char* what;
  TerrainBrush brush;
};

std::vector<NamedBrush> edits(std::uint64_t seed) {
  std::vector<NamedBrush> list;
  TerrainBrush b;
  b.centre_units = {58, 64, height(58, 64)};
  b.radius_units = 22;
  b.smooth_units = 8;
  b.material = 2;
  list.push_back({"a smooth rock hill (sphere r 22, blend 8)", b});
  b = {};
  b.shape = TerrainBrush::Shape::kCapsule;
  b.mode = TerrainBrush::Mode::kSubtract;
  b.centre_units = {20, 40, height(58, 64) + 6};
  b.end_units = {100, 88, height(58, 64) + 6};
  b.radius_units = 7;
  b.smooth_units = 2;
  list.push_back({"a tunnel through it (capsule r 7, carved)", b});
  b = {};
  b.shape = TerrainBrush::Shape::kBox;
  b.centre_units = {140, 128, height(140, 128) + 4};
  b.half_extents_units = {22, 16, 9};
  b.material = 3;
  list.push_back({"a sharp sand plateau (box, no blend)", b});
  b = {};
  b.mode = TerrainBrush::Mode::kSubtract;
  b.centre_units = {132, 48, height(132, 48) + 4};
  b.radius_units = 16;
  b.smooth_units = 5;
  list.push_back({"a smooth crater (sphere r 16, carved, blend 5)", b});
  // A trench dug along a wavy line, a small smooth sphere at a time, with seeded jitter.
  std::uint64_t state = seed * 6364136223846793005ull + 1442695040888963407ull;
  auto jitter = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 40) / static_cast<double>(1ull << 24) - 0.5;
  };
  for (int i = 0; i < 40; ++i) {
    const double x = 30 + i * 3.4, y = 108 + 10 * std::sin(i / 5.0) + jitter() * 2;
    b = {};
    b.mode = TerrainBrush::Mode::kSubtract;
    b.centre_units = {x, y, height(x, y) + 1};
    b.radius_units = 4 + jitter();
    b.smooth_units = 1.5;
    list.push_back({"trench", b});
  }
  return list;
}

struct StorageRun {
  TerrainStorage storage;
  TerrainField::Memory before, after;
  std::vector<double> edit_ms;
  double remeshed = 0;  // chunks per edit
  std::size_t triangles = 0;
};

// The i8 terrain on the GPU: uploaded whole once, then each brush's changed samples only, and a
// frame drawn by classify + HistoPyramid + one indirect draw, compared with the CPU picture.
void showcase_terrain_gpu(const fs::path& out, const Palette& palette,
                          const std::vector<NamedBrush>& brushes, const Camera& camera,
                          const MeshRenderOptions& ro, const Mesh& cpu_mesh, std::ostream& md,
                          std::vector<Timing>& timings) {
  const std::shared_ptr<gpu::Context> context = showcase_vulkan(md);
  if (!context) return;
  try {
    TerrainOptions to;
    to.samples = kSize;
    to.storage = TerrainStorage::kI8;
    to.palette = palette;
    TerrainField terrain(to);
    terrain.assign([](const Vec3d& p) { return p.z - height(p.x, p.y); }, 1);
    gpu::TerrainRenderer renderer(context);
    const std::uint64_t whole = renderer.sync(terrain);
    std::uint64_t sent = 0, largest = 0;
    for (const NamedBrush& nb : brushes) {
      const std::uint64_t b = renderer.sync(terrain, terrain.apply(nb.brush));
      sent += b;
      largest = std::max(largest, b);
    }
    gpu::TerrainDrawStats st;
    const Image frame = renderer.render(terrain_view(camera, ro), &st);
    write_png(frame, out / "terrain-field-gpu.png");
    timings.push_back(
        {"the terrain drawn from its HistoPyramid on Vulkan (" + context->device().name + ")",
         st.ms, context->device().hardware ? "" : "CPU emulation of the GPU"});
    const Image cpu = render_mesh(cpu_mesh, camera, ro);
    std::int64_t differ = 0;
    for (std::size_t i = 0; i < cpu.rgb.size(); i += 3)
      for (std::size_t ch = 0; ch < 3; ++ch)
        if (std::abs(int{cpu.rgb[i + ch]} - int{frame.rgb[i + ch]}) > 6) {
          ++differ;
          break;
        }
    md << "\nOn Vulkan (" << context->device().name
       << "), the thesis's loop: the i8 field resident on the device, uploaded whole once ("
       << format_bytes(whole) << " with the materials and case table), then after each of the "
       << brushes.size() << " brushes only the samples and materials it changed — "
       << format_bytes(sent / brushes.size()) << " per brush on average, " << format_bytes(largest)
       << " at most, against "
       << format_bytes(static_cast<std::uint64_t>(Box3i::from_size(kSize).volume()))
       << " for the whole field each frame as the thesis sent it. A frame is " << st.dispatches
       << " dispatches (classify, the HistoPyramid's levels, the draw's arguments) and " << st.draws
       << " indirect draw whose vertex shader walks the pyramid, " << st.submits
       << " submission, nothing read back to draw; it drew " << st.triangles
       << " triangles (the CPU mesh has " << cpu_mesh.triangle_count() << ") and " << differ
       << " of its " << cpu.width * cpu.height
       << " pixels differ from the CPU rasteriser's picture by more than 6 levels.\n\n"
       << "![the edited terrain drawn on the GPU](terrain-field-gpu.png)\n";
  } catch (const GpuUnavailable& e) {
    md << "\nOn Vulkan: not run here (" << e.what() << ").\n";
  }
}

}  // namespace

void showcase_terrain(const fs::path& out, std::uint64_t seed, int size, std::ostream& md,
                      std::vector<Timing>& timings) {
  Palette palette{};
  palette[1] = {92, 128, 64, 255};    // grass
  palette[2] = {128, 118, 108, 255};  // rock
  palette[3] = {214, 192, 128, 255};  // sand
  const std::vector<NamedBrush> brushes = edits(seed);
  MeshOptions mo;
  mo.chunk_edge = 16;
  std::vector<StorageRun> runs;
  Mesh before_mesh, after_mesh;
  for (TerrainStorage storage : {TerrainStorage::kI8, TerrainStorage::kI16, TerrainStorage::kF32}) {
    TerrainOptions to;
    to.samples = kSize;
    to.storage = storage;
    to.palette = palette;
    TerrainField terrain(to);
    terrain.assign([](const Vec3d& p) { return p.z - height(p.x, p.y); }, 1);
    StorageRun run{storage, terrain.memory(), {}, {}, 0, 0};
    MeshChunks chunks(terrain, mo);
    if (storage == TerrainStorage::kI8) before_mesh = chunks.merged();
    std::size_t remeshed = 0;
    for (const NamedBrush& nb : brushes) {
      const auto t0 = std::chrono::steady_clock::now();
      remeshed += chunks.update(terrain, terrain.apply(nb.brush)).size();
      run.edit_ms.push_back(ms_since(t0));
    }
    run.after = terrain.memory();
    run.remeshed = static_cast<double>(remeshed) / static_cast<double>(brushes.size());
    const Mesh kept = chunks.merged(), fresh = mesh_terrain(terrain, mo);
    if (kept.positions != fresh.positions || kept.indices != fresh.indices ||
        kept.colors != fresh.colors)
      throw Error(std::string("showcase: the ") + terrain_storage_name(storage) +
                  " terrain's kept chunk meshes differ from a fresh mesh");
    run.triangles = kept.triangle_count();
    if (storage == TerrainStorage::kI8) after_mesh = kept;
    runs.push_back(std::move(run));
  }
  std::cout << "voxfield showcase: terrain field " << kSize.x << "x" << kSize.y << "x" << kSize.z
            << ", " << brushes.size() << " brushes in each of i8, i16, f32; kept meshes equal "
            << "fresh ones\n";

  const Box3i box = Box3i::from_size(kSize);
  const Camera camera = Camera::framing(box, 16.0 / 9.0, 42);
  MeshRenderOptions ro;
  ro.width = picture_pixels(1280, size);
  ro.height = picture_pixels(720, size);
  MeshRenderStats st;
  write_png(render_mesh(before_mesh, camera, ro), out / "terrain-field-before.png");
  write_png(render_mesh(after_mesh, camera, ro, &st), out / "terrain-field-after.png");
  timings.push_back({"picture of the edited terrain field (CPU rasteriser)", st.ms, ""});
  write_mesh(after_mesh, out / "terrain-field.glb");

  md << "\n## A deformable terrain field\n\n"
     << "Smooth hills (" << kSize.x << " × " << kSize.y << " × " << kSize.z
     << " samples, a height map's signed distance) in a `TerrainField`, shaped by "
     << brushes.size() << " brushes — ";
  for (std::size_t i = 0; i < 4; ++i) md << brushes[i].what << (i < 3 ? "; " : "");
  md << "; and a trench dug by " << brushes.size() - 4
     << " small smooth spheres. After each brush, `MeshChunks` re-meshes only the chunks it "
        "reached (marching cubes, chunks of 16); at the end the kept chunks are checked equal to a "
        "fresh mesh of the edited field, in every width. Colours are the samples' materials "
        "(grass, rock added by the hill, sand by the plateau). The edited terrain is "
        "`terrain-field.glb`.\n\n"
     << "| before | after |\n|---|---|\n"
     << "| ![before](terrain-field-before.png) | ![after](terrain-field-after.png) |\n\n"
     << "| storage | clamp | bytes before → after | uniform chunks after | edit + re-mesh p50 / "
        "max "
        "| chunks re-meshed per edit | triangles |\n|---|---|---|---|---|---|---|\n";
  for (StorageRun& r : runs) {
    std::sort(r.edit_ms.begin(), r.edit_ms.end());
    TerrainOptions to;
    to.samples = kSize;
    to.storage = r.storage;
    md << "| " << terrain_storage_name(r.storage) << " | ±" << TerrainField(to).max_distance_units()
       << " | " << format_bytes(r.before.bytes) << " → " << format_bytes(r.after.bytes) << " | "
       << r.after.uniform_chunks << " of " << r.after.chunks << " | "
       << fixed(r.edit_ms[r.edit_ms.size() / 2], 2) << " / " << fixed(r.edit_ms.back(), 2)
       << " ms | " << fixed(r.remeshed, 1) << " | " << r.triangles << " |\n";
    timings.push_back({std::string(terrain_storage_name(r.storage)) + " terrain: " +
                           std::to_string(brushes.size()) + " brushes with re-meshing",
                       [&] {
                         double sum = 0;
                         for (double v : r.edit_ms) sum += v;
                         return sum;
                       }(),
                       ""});
  }
  md << "\n(A dense float32 copy of this field would be "
     << format_bytes(static_cast<std::uint64_t>(box.volume()) * 4)
     << "; docs/benchmarks.md measures the widths at 512³.)\n";
  showcase_terrain_gpu(out, palette, brushes, camera, ro, after_mesh, md, timings);
}

}  // namespace voxfield::cli

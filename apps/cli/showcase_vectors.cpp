// The showcase's vector fields: the paper's agents flying through a 64^3 volume for a second and a
// half of fixed steps (splatting, decay and blend), the field pictured by the visualiser, every
// algorithm on the last frame against the definition, and the texture exported for Unreal (.fga)
// and Unity (.vf).
#include <algorithm>
#include <chrono>

#include "cli.h"
#include "showcase.h"
#include "voxfield/file.h"
#include "voxfield/gpu_vectors.h"
#include "voxfield/png.h"
#include "voxfield/scene.h"
#include "voxfield/vector_agents.h"
#include "voxfield/vector_files.h"
#include "voxfield/vector_world.h"

namespace voxfield::cli {
namespace {

// A horizontal cut through a world's flow field at height z, four pixels per voxel: solid voxels
// dark, air coloured by |direction| per channel and brightened by strength.
Image flow_slice(const World& world, const WorldVectorField& flow, int z) {
  const Vec3i n = flow.volume().resolution;
  const int scale = 4;
  Image img(n.x * scale, n.y * scale);
  for (int y = 0; y < n.y; ++y)
    for (int x = 0; x < n.x; ++x) {
      std::uint8_t rgb[3] = {96, 78, 58};  // solid: earth
      if (!world.voxels.get({x, y, z})) {
        const VectorTexel t = flow.texture().get(flow.volume().index(x, y, z));
        const float c[3] = {std::abs(t.x), std::abs(t.y), std::abs(t.z)};
        for (int k = 0; k < 3; ++k)
          rgb[k] = static_cast<std::uint8_t>(255.0f *
                                             (0.08f + 0.92f * t.strength * (0.2f + 0.8f * c[k])));
      }
      for (int dy = 0; dy < scale; ++dy)
        for (int dx = 0; dx < scale; ++dx) {
          std::uint8_t* px = img.pixel(x * scale + dx, (n.y - 1 - y) * scale + dy);
          px[0] = rgb[0];
          px[1] = rgb[1];
          px[2] = rgb[2];
        }
    }
  return img;
}

// Flow around obstacles: the terrain's solid voxels push particles away (every solid voxel a
// source of radius 6), read from the exact nearest-site field and kept current under an edit.
void showcase_world_flow(const std::filesystem::path& out, std::uint64_t seed, std::ostream& md,
                         std::vector<Timing>& timings) {
  SceneOptions so;
  so.size = {96, 96, 96};
  so.seed = seed;
  World world = make_terrain(so);
  const Box3i box = Box3i::from_size(so.size);
  const double reach = 6;
  auto start = std::chrono::steady_clock::now();
  WorldVectorField flow(world, box, reach, VectorStorage::kRgba8);
  const double build_ms = ms_since(start);
  timings.push_back(
      {"world flow field (96³ terrain, reach 6)", build_ms, "nearest-site field + texels"});
  const int z = 54;
  write_png(flow_slice(world, flow, z), out / "flow-before.png");
  DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
  Edit carve;
  carve.op = EditOp::kCarve;
  carve.brush = SphereBrush{{48, 48, static_cast<double>(z)}, 12};
  apply_edit(world, carve, &dirty);
  start = std::chrono::steady_clock::now();
  const std::int64_t texels = flow.update(dirty);
  const double update_ms = ms_since(start);
  timings.push_back({"world flow update after a carve (radius 12)", update_ms,
                     std::to_string(texels) + " texels re-encoded"});
  write_png(flow_slice(world, flow, z), out / "flow-after.png");
  const WorldVectorField rebuilt(world, box, reach, VectorStorage::kRgba8);
  const bool same = std::equal(flow.texture().bytes().begin(), flow.texture().bytes().end(),
                               rebuilt.texture().bytes().begin());
  md << "\n### Flow around obstacles\n\n"
     << "Every solid voxel of a 96³ terrain pushes away within 6 voxels: the direction away from "
        "the "
        "nearest solid voxel, strength 1 − d/6 from its exact distance, read from the nearest-site "
        "field ("
     << fixed(build_ms, 1) << " ms). A carve of radius 12 then re-encodes " << texels
     << " texels in " << fixed(update_ms, 1) << " ms; the result is "
     << (same ? "**byte-identical** to a rebuild" : "**DIFFERENT** from a rebuild") << ".\n\n"
     << "| cut at z = " << z << ", before | after the carve |\n|---|---|\n"
     << "| ![flow before](flow-before.png) | ![flow after](flow-after.png) |\n";
}

// The reactive sheet over the same field, and the same steps on the Vulkan backend when a device
// is there: the field byte for byte the CPU's, with its counters.
void showcase_sheet_and_gpu(const std::filesystem::path& out, const VectorVolume& volume,
                            const VectorTexture& cpu_field, int steps, int size, std::ostream& md,
                            std::vector<Timing>& timings) {
  VectorViewOptions view;
  view.width = picture_pixels(640, size);
  view.height = picture_pixels(480, size);
  view.sheet = true;
  view.sheet_push = 1.2;
  auto start = std::chrono::steady_clock::now();
  write_png(render_vectors(volume, cpu_field, view), out / "vectors-sheet.png");
  timings.push_back({"vector-field visualiser with the reactive sheet (" +
                         std::to_string(view.width) + "×" + std::to_string(view.height) + ")",
                     ms_since(start), ""});
  md << "\nThe same field pushing a sheet of cloth (what grass or water does with it through "
        "`voxfield_vectors.glsl`): each point is displaced along z by the field's vector at its "
        "rest position, tinted by its direction.\n\n![the reactive sheet](vectors-sheet.png)\n";
  const std::shared_ptr<gpu::Context> context = showcase_vulkan(md);
  if (!context) return;
  try {
    gpu::VectorSimulation gpu_sim(context, volume, VectorStorage::kRgba8, {}, 1.0);
    VectorAgents agents(20, 2026);
    context->reset_counters();
    start = std::chrono::steady_clock::now();
    for (int i = 0; i < steps; ++i) gpu_sim.step(agents.step(1.0 / 60), 1.0 / 60);
    const double ms = ms_since(start);
    const gpu::Counters c = context->counters();
    const VectorTexture field = gpu_sim.field();
    const bool same = std::equal(field.bytes().begin(), field.bytes().end(),
                                 cpu_field.bytes().begin(), cpu_field.bytes().end());
    timings.push_back(
        {std::to_string(steps) + " vector-field steps on Vulkan (" + context->device().name + ")",
         ms, context->device().hardware ? "" : "CPU emulation of the GPU"});
    md << "\nOn Vulkan (" << context->device().name << "): the same " << steps
       << " steps as compute passes — " << static_cast<double>(c.dispatches) / steps
       << " dispatch and " << static_cast<double>(c.submits) / steps << " submission per step, "
       << c.bytes_uploaded / steps
       << " bytes uploaded per step on average (the sources, splatting's bins, and once the "
          "voxel-centre tables); the field after the last step is "
       << (same ? "**byte-identical** to the CPU's" : "**DIFFERENT** from the CPU's") << ".\n";
  } catch (const GpuUnavailable& e) {
    md << "\nOn Vulkan: not run here (" << e.what() << ").\n";
  }
}

}  // namespace

void showcase_vectors(const std::filesystem::path& out, std::uint64_t seed, int size,
                      std::ostream& md, std::vector<Timing>& timings) {
  const VectorVolume volume = vector_agents_volume({64, 64, 64});
  const double dt = 1.0 / 60;
  const int steps = 90;
  VectorSimulation sim(volume, VectorStorage::kRgba8, {}, 1.0);
  VectorAgents agents(20, 2026);
  std::vector<VectorSource> last;
  double step_ms = 0;
  for (int i = 0; i < steps; ++i) {
    last = agents.step(dt);
    const auto start = std::chrono::steady_clock::now();
    sim.step(last, dt);
    step_ms += ms_since(start);
  }
  timings.push_back({std::to_string(steps) + " vector-field steps (64³, 20 sources, splat, rgba8)",
                     step_ms, fixed(step_ms / steps, 3) + " ms per step"});

  auto start = std::chrono::steady_clock::now();
  VectorViewOptions view;
  view.width = picture_pixels(640, size);
  view.height = picture_pixels(480, size);
  write_png(render_vectors(volume, sim.field(), view), out / "vectors.png");
  timings.push_back({"vector-field visualiser (" + std::to_string(view.width) + "×" +
                         std::to_string(view.height) + ")",
                     ms_since(start), ""});
  const std::string fga = encode_fga(volume, sim.field());
  write_file_atomic(out / "vectors.fga",
                    {reinterpret_cast<const std::uint8_t*>(fga.data()), fga.size()});
  write_file_atomic(out / "vectors.vf", encode_vf(volume, sim.field()));

  md << "\n## Vector fields: agents pushing the space around them\n\n"
     << "Twenty sources (the paper's agents, radius 0.8 in a 10-unit box) fly for " << steps
     << " fixed steps of 1/60 s; each step splats them into a 64³ RGBA8 texture, decays the "
        "previous field by 1 per second and blends the two, so every agent leaves a fading "
        "wake. Mean whole step: **"
     << fixed(step_ms / steps, 3)
     << " ms** (generation, conversion, decay and blend).\n\n"
        "![the field after the last step: density from strength, colour from |direction|]"
        "(vectors.png)\n\n"
        "The last frame's sources by every algorithm, against the exact definition:\n\n"
        "| algorithm | ms | % voxels with another source | max angle error (°) | max strength "
        "error |\n|---|---|---|---|---|\n";
  VectorOptions exact;
  const std::vector<std::int32_t> want = vector_winners(volume, last, exact);
  for (VectorAlgorithm a : {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat, VectorAlgorithm::kJfa,
                            VectorAlgorithm::kJfaPlus1, VectorAlgorithm::kJfaPlus2}) {
    VectorOptions o;
    o.algorithm = a;
    start = std::chrono::steady_clock::now();
    const std::vector<std::int32_t> got = vector_winners(volume, last, o);
    const double ms = ms_since(start);
    const VectorError e = compare_vector_winners(volume, last, want, got);
    md << "| " << vector_algorithm_name(a) << " | " << fixed(ms, 2) << " | "
       << fixed(e.percent_differs(), 3) << " | " << fixed(e.max_angle_deg, 2) << " | "
       << fixed(e.max_strength_error, 4) << " |\n";
  }
  md << "\nFiles: `vectors.fga` (Unreal), `vectors.vf` (Unity VFX Graph).\n";
  showcase_sheet_and_gpu(out, volume, sim.field(), steps, size, md, timings);
  showcase_world_flow(out, seed, md, timings);
}

}  // namespace voxfield::cli

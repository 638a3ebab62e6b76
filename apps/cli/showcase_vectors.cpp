// The showcase's vector fields: the paper's agents flying through a 64^3 volume for a second and a
// half of fixed steps (splatting, decay and blend), the field pictured by the visualiser, every
// algorithm on the last frame against the definition, and the texture exported for Unreal (.fga)
// and Unity (.vf).
#include <chrono>

#include "cli.h"
#include "showcase.h"
#include "vector_agents.h"
#include "voxfield/file.h"
#include "voxfield/png.h"
#include "voxfield/vector_files.h"

namespace voxfield::cli {

void showcase_vectors(const std::filesystem::path& out, std::ostream& md,
                      std::vector<Timing>& timings) {
  const VectorVolume volume = agents_volume({64, 64, 64});
  const double dt = 1.0 / 60;
  const int steps = 90;
  VectorSimulation sim(volume, VectorStorage::kRgba8, {}, 1.0);
  Agents agents(20, 2026);
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
  view.width = 640;
  view.height = 480;
  write_png(render_vectors(volume, sim.field(), view), out / "vectors.png");
  timings.push_back({"vector-field visualiser (640×480)", ms_since(start), ""});
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
}

}  // namespace voxfield::cli

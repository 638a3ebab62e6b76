// voxfield csg MODEL render -o PNG: a picture of a CSG model by sphere tracing through the octree's
// cells, on the CPU or on Vulkan (each variant its own generated kernel, the interpreter standing
// in), with its statistics.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numeric>

#include <unistd.h>

#include "backend_choice.h"
#include "cli.h"
#include "csg_commands.h"
#include "progress.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"
#include "voxfield/csg_files.h"
#include "voxfield/csg_render.h"
#include "voxfield/file.h"
#include "voxfield/gpu.h"
#include "voxfield/gpu_render.h"
#include "voxfield/parallel.h"
#include "voxfield/png.h"

namespace voxfield::cli {

int run_render(const CsgSettings& s) {
  Outputs outputs({s.model});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  if (std::filesystem::path(s.out).extension() != ".png")
    throw UsageError("-o: render writes a .png, not " + s.out);
  const csg::Model model = load_model(s.model, s.facets);
  CsgRenderOptions o;
  o.width = s.width;
  o.height = s.height;
  o.view =
      s.view == "variants" ? CsgRenderOptions::View::kVariants : CsgRenderOptions::View::kShaded;
  o.prune = !s.whole;
  o.depth = s.depth >= 0 ? s.depth : 6;
  o.shadows = !s.no_shadows;
  o.box = parse_box(s.box);
  if (s.camera != "auto") {
    const auto b = o.box ? o.box : csg::model_bounds(model);
    // A voxel box around the model for "top" framing, clamped to the coordinate range.
    auto coord = [](double v) {
      return static_cast<int>(std::clamp(v, -double(kCoordLimit), double(kCoordLimit)));
    };
    const Box3i around =
        b ? Box3i{{coord(std::floor(b->lo.x)), coord(std::floor(b->lo.y)),
                   coord(std::floor(b->lo.z))},
                  {coord(std::ceil(b->hi.x)), coord(std::ceil(b->hi.y)), coord(std::ceil(b->hi.z))}}
          : Box3i::from_size({1, 1, 1});
    o.camera = Camera::parse(s.camera, around, static_cast<double>(s.width) / s.height);
  }
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  set_activity("rendering " + s.model);
  CsgRenderStats st;
  const auto gpu_context = choose_backend(s.backend);
  gpu::CsgGpuOptions go;
  go.evaluators = s.evaluators == "compiled" ? gpu::CsgGpuOptions::Evaluators::kCompiled
                  : s.evaluators == "interpreter"
                      ? gpu::CsgGpuOptions::Evaluators::kInterpreter
                      : gpu::CsgGpuOptions::Evaluators::kCompiledWhenReady;
  gpu::CsgGpuStats gs;
  o.interrupter = progress();
  const Image image = gpu_context ? gpu::render_csg(*gpu_context, model, o, &st, go, &gs)
                                  : render_csg(model, o, &st);
  outputs.stage(s.out, encode_png(image));
  nlohmann::json gpu_block = nullptr;
  if (gpu_context) {
    gpu_block = gpu_json(*gpu_context);
    gpu_block.update({{"evaluators", s.evaluators},
                      {"rounds", gs.rounds},
                      {"variants_compiled", gs.variants_compiled},
                      {"compiled_dispatches", gs.compiled_dispatches},
                      {"interpreted_dispatches", gs.interpreted_dispatches},
                      {"frame_dispatches", gs.dispatches},
                      {"frame_submits", gs.submits},
                      {"compile_ms", gs.compile_ms}});
  }
  auto cpu_count = [&](auto n) -> nlohmann::json {
    if (gpu_context) return nullptr;
    return n;
  };
  outputs.stage_json(s.stats, {{"model", s.model},
                               {"backend", gpu_context ? "vulkan" : "cpu"},
                               {"gpu", gpu_block},
                               {"output", s.out},
                               {"width", s.width},
                               {"height", s.height},
                               {"view", s.view},
                               {"pruned", o.prune},
                               {"depth", o.depth},
                               {"threads", max_threads()},
                               {"octree_ms", st.octree_ms},
                               {"render_ms", st.render_ms},
                               {"rays", st.rays},
                               // Counted by the CPU tracer only: null on Vulkan, whose counters
                               // are in the "gpu" block.
                               {"hits", cpu_count(st.hits)},
                               {"evaluations", cpu_count(st.evaluations)},
                               {"instructions", cpu_count(st.instructions)},
                               {"cells_entered", cpu_count(st.cells_entered)},
                               {"variants", st.variants}});
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << s.width << " x " << s.height << ", "
            << std::lround(st.octree_ms) << " ms octree + " << std::lround(st.render_ms)
            << " ms tracing, " << st.variants << " variants)\n";
  return 0;
}

}  // namespace voxfield::cli

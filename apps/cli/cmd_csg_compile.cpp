// voxfield csg MODEL compile -o DIR: the voxel compiler's output — each variant's generated GLSL
// (and its SPIR-V, compiled in-process on worker threads), the cells' parameters and a manifest —
// written into a directory replaced whole, only when everything is ready.
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

int run_compile(const CsgSettings& s) {
  namespace fs = std::filesystem;
  const fs::path dir = s.out;
  // The directory is replaced whole, and only when everything is ready: a new one, an empty one or
  // an earlier compile's (with its manifest) — never a directory holding other files, or the model.
  if (fs::exists(dir)) {
    if (!fs::is_directory(dir)) throw UsageError("-o " + s.out + " exists and is not a directory");
    if (!fs::is_empty(dir) && !fs::exists(dir / "manifest.json"))
      throw UsageError(
          "-o " + s.out +
          " holds files that are not a compile's output; give a new or empty directory");
    const fs::path model = fs::weakly_canonical(s.model), target = fs::weakly_canonical(dir);
    if (std::mismatch(target.begin(), target.end(), model.begin(), model.end()).first ==
        target.end())
      throw UsageError("-o " + s.out + " contains the model " + s.model);
  }
  Outputs outputs({s.model});
  outputs.expect(s.stats, "--stats");
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  if (!fs::is_directory(parent))
    throw IoError("-o " + s.out + ": the directory " + parent.string() + " does not exist");
  const csg::Model model = load_model(s.model, s.facets);
  set_activity("compiling " + s.model);
  const csg::Tape tape = csg::compile_tape(model);
  csg::OctreeOptions o;
  o.depth = s.depth >= 0 ? s.depth : 6;
  const csg::Octree tree = csg::build_octree(tape, model, o);
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::pair<std::string, std::string>> files{{"prelude.glsl", csg::glsl_prelude()}};
  nlohmann::json variants = nlohmann::json::array();
  for (std::size_t i = 0; i < tree.variants.size(); ++i) {
    const csg::Variant& v = tree.variants[i];
    const csg::Tape& t = v.tape;
    const std::string name = "variant_" + std::to_string(i) + ".glsl";
    files.push_back({name, csg::glsl_variant(t, static_cast<int>(i))});
    variants.push_back({{"index", i},
                        {"file", name},
                        {"function", "vf_variant_" + std::to_string(i)},
                        {"cells", v.cells},
                        {"nodes", t.code.size()},
                        {"params_per_cell", t.params.size()}});
  }
  const double codegen_ms = ms_since(start);
  // --spirv: each variant's evaluation kernel compiled in-process on worker threads (glslang),
  // timed per variant; the binaries join the output files.
  std::vector<std::vector<std::uint32_t>> spirv(s.spirv ? tree.variants.size() : 0);
  std::vector<double> spirv_ms(spirv.size());
  const auto spirv_start = std::chrono::steady_clock::now();
  parallel_for(spirv.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::string name = "variant_" + std::to_string(i);
      spirv[i] = gpu::compile_compute_shader(
          name, csg::glsl_variant_kernel(tree.variants[i].tape, static_cast<int>(i)));
      spirv_ms[i] = ms_since(t0);
    }
  });
  const double spirv_wall_ms = ms_since(spirv_start);
  for (std::size_t i = 0; i < spirv.size(); ++i) {
    const std::string name = "variant_" + std::to_string(i) + ".spv";
    files.push_back(
        {name, std::string(reinterpret_cast<const char*>(spirv[i].data()), spirv[i].size() * 4)});
    variants[i]["spirv"] = name;
  }
  // Every surface cell's constants, float32 in order, and where each cell's start.
  std::vector<float> params;
  nlohmann::json cells = nlohmann::json::array();
  for (const csg::OctreeLeaf& l : tree.leaves) {
    nlohmann::json c{{"box", bounds_json(tree.leaf_box(l))},
                     {"level", l.level},
                     {"state", csg::cell_state_name(l.state)}};
    if (l.state == csg::CellState::kSurface) {
      c["variant"] = l.variant;
      c["param_offset"] = params.size();
      for (double p : tree.leaf_params(l)) params.push_back(static_cast<float>(p));
    }
    cells.push_back(std::move(c));
  }
  const nlohmann::json manifest{
      {"model", s.model},          {"depth", o.depth},       {"root", bounds_json(tree.root)},
      {"prelude", "prelude.glsl"}, {"params", "params.f32"}, {"params_count", params.size()},
      {"variants", variants},      {"cells", cells},         {"compile", compile_json(tree.stats)}};
  // Written into a fresh directory beside the target, then swapped in.
  const fs::path fresh = dir.string() + ".tmp." + std::to_string(::getpid());
  try {
    fs::remove_all(fresh);
    fs::create_directory(fresh);
    for (const auto& [name, text] : files)
      write_file_atomic(fresh / name,
                        std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    write_file_atomic(fresh / "params.f32",
                      std::span(reinterpret_cast<const std::uint8_t*>(params.data()),
                                params.size() * sizeof(float)));
    const std::string m = manifest.dump(2) + "\n";
    write_file_atomic(fresh / "manifest.json",
                      std::span(reinterpret_cast<const std::uint8_t*>(m.data()), m.size()));
    if (fs::exists(dir)) fs::remove_all(dir);
    fs::rename(fresh, dir);
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(fresh, ignored);
    throw;
  }
  nlohmann::json stats{
      {"model", s.model}, {"depth", o.depth}, {"compile", compile_json(tree.stats)}};
  stats["compile"]["codegen_ms"] = codegen_ms;
  if (s.spirv) {
    std::size_t bytes = 0;
    for (const auto& w : spirv) bytes += w.size() * 4;
    stats["compile"]["spirv"] = {
        {"variants", spirv.size()},
        {"wall_ms", spirv_wall_ms},
        {"threads", max_threads()},
        {"mean_ms", spirv.empty() ? 0.0
                                  : std::accumulate(spirv_ms.begin(), spirv_ms.end(), 0.0) /
                                        static_cast<double>(spirv.size())},
        {"max_ms", spirv.empty() ? 0.0 : *std::max_element(spirv_ms.begin(), spirv_ms.end())},
        {"first_ms", spirv.empty() ? 0.0 : spirv_ms.front()},
        {"bytes", bytes}};
  }
  outputs.stage_json(s.stats, stats);
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << "/ (" << tree.variants.size() << " variants over "
            << tree.stats.surface << " surface cells, " << params.size() << " parameters)\n";
  return 0;
}

}  // namespace voxfield::cli

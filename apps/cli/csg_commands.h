// voxfield csg — what the csg subcommands share (private to the CLI): their settings and the
// model loading and JSON helpers. Each subcommand's body lives in cmd_csg*.cpp.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"

namespace voxfield::cli {

struct CsgSettings {
  std::string model, stats;
  bool facets = false;  // OpenSCAD spheres and cylinders as its polytopes
  // info / compile
  int depth = -1;
  bool spirv = false;  // compile: each variant's kernel to SPIR-V too
  // eval
  std::string points, out;
  bool pruned = false;
  // voxelize
  double voxel_size = 0;
  std::vector<double> box;
  std::optional<double> max_distance;
  std::string field;
  bool whole = false;
  int threads = 0;
  // render
  std::string camera = "auto", view = "shaded", backend = "cpu", evaluators = "when-ready";
  int width = 640, height = 480;
  bool no_shadows = false;
  // mesh
  std::string algorithm = "dc";
  int chunk = 32;
  bool sampled = false;
};

// The model of a file (any notation csg::load_model reads), saying what it does on a terminal.
csg::Model load_model(const std::string& path, bool facets);
nlohmann::json bounds_json(const std::optional<csg::Bounds>& b);
nlohmann::json compile_json(const csg::CompileStats& s);
// --box x0,y0,z0,x1,y1,z1, or none.
std::optional<csg::Bounds> parse_box(const std::vector<double>& v);

// csg MODEL compile -o DIR: each variant's GLSL (and SPIR-V), the cells and a manifest.
int run_compile(const CsgSettings& s);
// csg MODEL render -o PNG: a picture by sphere tracing, on the CPU or on Vulkan.
int run_render(const CsgSettings& s);

}  // namespace voxfield::cli

// voxfield csg MODEL SUBCOMMAND: the voxel compiler from the command line — a model's facts, its
// values at points (whole or through the octree), voxelisation into worlds and fields, and the
// generated GLSL of its variants.
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
#include "voxfield/csg_mesh.h"
#include "voxfield/csg_render.h"
#include "voxfield/file.h"
#include "voxfield/gpu.h"
#include "voxfield/gpu_render.h"
#include "voxfield/mesh_files.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"
#include "voxfield/png.h"

namespace voxfield::cli {

csg::Model load_model(const std::string& path, bool facets) {
  set_activity("reading " + path);
  csg::OpenScadOptions o;
  o.facets = facets;
  return csg::load_model(path, o);
}

nlohmann::json bounds_json(const std::optional<csg::Bounds>& b) {
  if (!b) return nullptr;
  return {{b->lo.x, b->lo.y, b->lo.z}, {b->hi.x, b->hi.y, b->hi.z}};
}

nlohmann::json compile_json(const csg::CompileStats& s) {
  return {{"cells_visited", s.cells_visited},
          {"leaves", s.leaves},
          {"empty", s.empty},
          {"full", s.full},
          {"surface", s.surface},
          {"variants", s.variants},
          {"whole_nodes", s.whole_nodes},
          {"mean_nodes", s.mean_nodes},
          {"max_nodes", s.max_nodes},
          {"octree_ms", s.octree_ms}};
}

std::optional<csg::Bounds> parse_box(const std::vector<double>& v) {
  if (v.empty()) return std::nullopt;
  if (v.size() != 6) throw UsageError("--box takes six numbers: x0,y0,z0,x1,y1,z1");
  const csg::Bounds b{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  if (b.empty()) throw UsageError("--box: each of x1, y1, z1 must be at least x0, y0, z0");
  return b;
}

namespace {

int run_info(const CsgSettings& s) {
  Outputs outputs({s.model});
  outputs.expect(s.stats, "--stats");
  const csg::Model model = load_model(s.model, s.facets);
  const csg::ModelInfo info = csg::model_info(model);
  nlohmann::json j{{"model", s.model},
                   {"nodes", info.nodes},
                   {"unique_nodes", info.unique_nodes},
                   {"shapes", info.shapes},
                   {"label", csg::label_name(info.label)},
                   {"bounds", bounds_json(info.bounds)}};
  std::cout << s.model << ": " << info.nodes << " nodes (" << info.unique_nodes << " stored), "
            << info.shapes << " shapes, " << csg::label_name(info.label) << "\n";
  if (info.bounds)
    std::cout << "  bounds " << info.bounds->lo.x << "," << info.bounds->lo.y << ","
              << info.bounds->lo.z << " .. " << info.bounds->hi.x << "," << info.bounds->hi.y << ","
              << info.bounds->hi.z << "\n";
  else
    std::cout << "  unbounded\n";
  if (s.depth >= 0) {
    set_activity("compiling " + s.model);
    const csg::Tape tape = csg::compile_tape(model);
    csg::OctreeOptions o;
    o.depth = s.depth;
    const csg::Octree tree = csg::build_octree(tape, model, o);
    const auto start = std::chrono::steady_clock::now();
    std::size_t glsl_bytes = csg::glsl_prelude().size();
    for (const csg::Variant& v : tree.variants) glsl_bytes += csg::glsl_variant(v.tape, 0).size();
    const double codegen_ms = ms_since(start);
    const csg::CompileStats& c = tree.stats;
    std::cout << "  depth " << s.depth << ": " << c.leaves << " leaves (" << c.surface
              << " surface, " << c.empty << " empty, " << c.full << " full), " << c.variants
              << " variants; nodes per surface cell: mean " << c.mean_nodes << ", largest "
              << c.max_nodes << ", whole tree " << c.whole_nodes << "; octree " << c.octree_ms
              << " ms, GLSL " << codegen_ms << " ms (" << glsl_bytes << " bytes)\n";
    j["depth"] = s.depth;
    j["compile"] = compile_json(c);
    j["compile"]["codegen_ms"] = codegen_ms;
    j["compile"]["glsl_bytes"] = glsl_bytes;
  }
  outputs.stage_json(s.stats, j);
  outputs.commit();
  return 0;
}

int run_eval(const CsgSettings& s) {
  Outputs outputs({s.model, s.points});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  const csg::Model model = load_model(s.model, s.facets);
  set_activity("reading " + s.points);
  NpyReadOptions ro;
  ro.rank = 2;
  const NpyVolume pts = read_npy(s.points, ro);
  if (pts.dims.y != 3 || pts.dtype != DType::kFloat64)
    throw FormatError(s.points, 0,
                      std::string("expected float64 points of shape (N, 3), got ") +
                          dtype_name(pts.dtype) + " (" + std::to_string(pts.dims.x) + ", " +
                          std::to_string(pts.dims.y) + ")");
  const std::int64_t n = pts.dims.x;
  std::vector<Vec3d> points(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    const Vec3d p{pts.value(i), pts.value(i + n), pts.value(i + 2 * n)};
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(p[a]))
        throw FormatError(s.points, pts.file_offset_of(i + a * n),
                          "point " + std::to_string(i) + " has a coordinate that is not finite");
    points[static_cast<std::size_t>(i)] = p;
  }
  set_activity("evaluating " + s.model);
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  const auto start = std::chrono::steady_clock::now();
  const csg::Tape tape = csg::compile_tape(model);
  std::vector<double> values(points.size());
  nlohmann::json j{{"model", s.model}, {"points", n}, {"pruned", s.pruned}};
  if (s.pruned) {
    csg::OctreeOptions o;
    o.depth = s.depth >= 0 ? s.depth : 6;
    const csg::Octree tree = csg::build_octree(tape, model, o);
    parallel_for(points.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) values[i] = tree.evaluate(points[i]);
    });
    j["depth"] = o.depth;
    j["compile"] = compile_json(tree.stats);
  } else {
    parallel_for(points.size(), 4096, [&](std::size_t b, std::size_t e) {
      csg::evaluate(tape, std::span(points).subspan(b, e - b), std::span(values).subspan(b, e - b));
    });
  }
  j["ms"] = ms_since(start);
  NpyVolume out = make_npy(DType::kFloat64, {static_cast<std::int32_t>(n), 1, 1}, values.data());
  out.rank = 1;
  outputs.stage(s.out, encode_npy(out));
  outputs.stage_json(s.stats, j);
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << n << " values)\n";
  return 0;
}

int run_voxelize(const CsgSettings& s) {
  Outputs outputs({s.model});
  outputs.expect_world(s.out, "-o");
  outputs.expect(s.field, "--field");
  outputs.expect(s.stats, "--stats");
  if (!s.field.empty() && std::filesystem::path(s.field).extension() != ".npy")
    throw UsageError("--field writes a float32 .npy, not " + s.field);
  const csg::Model model = load_model(s.model, s.facets);
  csg::VoxelizeOptions o;
  o.voxel_size = s.voxel_size;
  o.box = parse_box(s.box);
  if (s.max_distance) o.max_distance = *s.max_distance;
  o.field = !s.field.empty();
  o.prune = !s.whole;
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  set_activity("voxelising " + s.model);
  const csg::Voxelized v = csg::voxelize(model, o);
  set_activity("writing " + s.out);
  const Box3i extent = Box3i::from_size(v.dims);
  outputs.stage(s.out, encode_world(v.world, extent, world_format_of(s.out)));
  note_frame_left_out(v.world, s.out);
  if (o.field)
    outputs.stage(s.field, encode_npy(make_npy(DType::kFloat32, v.dims, v.field.data())));
  const csg::VoxelizeStats& st = v.stats;
  const double mvox_per_s = st.ms > 0 ? static_cast<double>(st.voxels) / st.ms / 1e3 : 0;
  outputs.stage_json(s.stats, {{"model", s.model},
                               {"output", s.out},
                               {"dims", {v.dims.x, v.dims.y, v.dims.z}},
                               {"box", bounds_json(v.box)},
                               {"voxel_size", s.voxel_size},
                               {"pruned", o.prune},
                               {"threads", max_threads()},
                               {"voxels", st.voxels},
                               {"solid", v.world.solid_count()},
                               {"evaluated", st.evaluated},
                               {"cells", st.cells},
                               {"empty_cells", st.empty_cells},
                               {"full_cells", st.full_cells},
                               {"surface_cells", st.surface_cells},
                               {"mean_nodes", st.mean_nodes},
                               {"max_nodes", st.max_nodes},
                               {"whole_nodes", st.whole_nodes},
                               {"ms", st.ms},
                               {"mvox_per_s", mvox_per_s}});
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << v.dims.x << " x " << v.dims.y << " x "
            << v.dims.z << ", " << v.world.solid_count() << " solid, " << std::lround(st.ms)
            << " ms, " << std::lround(mvox_per_s) << " Mvox/s)\n";
  return 0;
}

int run_mesh(const CsgSettings& s) {
  Outputs outputs({s.model});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  const MeshFormat format = mesh_format_of(s.out);
  const csg::Model model = load_model(s.model, s.facets);
  CsgMeshOptions o;
  o.voxel_size = s.voxel_size;
  o.box = parse_box(s.box);
  o.mesh.algorithm = parse_mesher(s.algorithm);
  o.mesh.chunk_edge = s.chunk;
  o.exact_gradients = !s.sampled;
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  set_activity("meshing " + s.model);
  const auto start = std::chrono::steady_clock::now();
  const Mesh mesh = mesh_csg(model, o);
  const double ms = ms_since(start);
  set_activity("writing " + s.out);
  outputs.stage(s.out, encode_mesh(mesh, format));
  const MeshStats st = mesh_stats(mesh);
  outputs.stage_json(s.stats, {{"model", s.model},
                               {"output", s.out},
                               {"algorithm", mesher_name(o.mesh.algorithm)},
                               {"voxel_size", s.voxel_size},
                               {"exact_gradients", o.exact_gradients},
                               {"threads", max_threads()},
                               {"ms", ms},
                               {"vertices", st.vertices},
                               {"triangles", st.triangles},
                               {"watertight", st.watertight()},
                               {"euler_characteristic", st.euler_characteristic},
                               {"area_units2", st.area_units2},
                               {"volume_units3", st.signed_volume_units3}});
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << st.triangles << " triangles, "
            << mesher_name(o.mesh.algorithm) << ", " << std::lround(ms) << " ms"
            << (st.watertight() ? ", watertight" : "") << ")\n";
  return 0;
}

}  // namespace

void add_csg(CLI::App& app, Action& action) {
  auto s = std::make_shared<CsgSettings>();
  CLI::App* cmd = app.add_subcommand(
      "csg",
      "The voxel compiler: CSG models (.sdf S-expressions or .json, docs/csg.md) "
      "pruned per octree cell, voxelised, evaluated and compiled to GLSL");
  cmd->add_option("MODEL", s->model, "model file: .sdf (S-expressions), .json, or OpenSCAD's .csg")
      ->required();
  cmd->add_flag("--facets", s->facets,
                "OpenSCAD .csg: spheres and cylinders as OpenSCAD's polytopes ($fn/$fa/$fs), not "
                "ideal shapes");
  cmd->fallthrough();  // --facets after the subcommand too
  cmd->require_subcommand(1);
  auto stats = [&](CLI::App* sub) {
    sub->add_option("--stats", s->stats, "write the figures as JSON");
  };
  auto threads = [&](CLI::App* sub) {
    sub->add_option("--threads", s->threads, "threads (default: all)")->check(CLI::Range(1, 1024));
  };

  CLI::App* info =
      cmd->add_subcommand("info", "nodes, labels and bounds; with --depth, the compile figures");
  info->add_option("--depth", s->depth, "build the octree to this depth (0..8) and report it")
      ->check(CLI::Range(0, 8));
  stats(info);
  info->callback([s, &action] { action = [s] { return run_info(*s); }; });

  CLI::App* eval = cmd->add_subcommand(
      "eval", "the model's value at points: P.npy float64 (N, 3) -> D.npy float64 (N,)");
  eval->add_option("--points", s->points, "float64 .npy of shape (N, 3), in model units")
      ->required();
  eval->add_option("-o,--output", s->out, "float64 .npy of shape (N,)")->required();
  eval->add_flag("--pruned", s->pruned,
                 "evaluate each point through its octree cell's pruned tape");
  eval->add_option("--depth", s->depth, "octree depth for --pruned (0..8, default 6)")
      ->check(CLI::Range(0, 8));
  threads(eval);
  stats(eval);
  eval->callback([s, &action] { action = [s] { return run_eval(*s); }; });

  CLI::App* vox =
      cmd->add_subcommand("voxelize", "solid where the value at the voxel centre is <= 0");
  vox->add_option("--voxel-size", s->voxel_size, "voxel edge in model units")
      ->required()
      ->check(finite_positive());
  vox->add_option("--box", s->box, "x0,y0,z0,x1,y1,z1 in model units (default: the model's bounds)")
      ->delimiter(',');
  vox->add_option("--max-distance", s->max_distance,
                  "clamp the field to +-D; cells farther are not evaluated")
      ->check(finite_positive());
  vox->add_option("-o,--output", s->out, "world: .vox, .npy (uint8 materials) or .vfw")->required();
  vox->add_option("--field", s->field, "also write the values at the voxel centres (float32 .npy)");
  vox->add_flag("--whole", s->whole, "evaluate the whole tree at every voxel (for comparison)");
  threads(vox);
  stats(vox);
  vox->callback([s, &action] { action = [s] { return run_voxelize(*s); }; });

  CLI::App* mesh = cmd->add_subcommand("mesh",
                                       "the surface as triangles: dual contouring (default), "
                                       "marching cubes or surface nets, with crossings "
                                       "and normals from the model itself");
  mesh->add_option("--voxel-size", s->voxel_size, "lattice spacing in model units")
      ->required()
      ->check(finite_positive());
  mesh->add_option("-o,--output", s->out, "output .ply, .obj, .stl or .glb")->required();
  mesh->add_option("--algorithm", s->algorithm, "dc (default), mc or sn")
      ->check(
          CLI::IsMember({"mc", "sn", "dc", "marching-cubes", "surface-nets", "dual-contouring"}));
  mesh->add_option("--box", s->box,
                   "x0,y0,z0,x1,y1,z1 in model units (default: the model's bounds)")
      ->delimiter(',');
  mesh->add_option("--chunk", s->chunk, "cells per chunk edge (2..256, default 32)")
      ->check(CLI::Range(2, 256));
  mesh->add_flag("--sampled", s->sampled,
                 "interpolate crossings and difference normals from the samples, as for any volume "
                 "(for comparison)");
  threads(mesh);
  stats(mesh);
  mesh->callback([s, &action] { action = [s] { return run_mesh(*s); }; });

  CLI::App* render =
      cmd->add_subcommand("render", "a picture by sphere tracing through the octree's cells");
  render->add_option("-o,--output", s->out, "output .png")->required();
  render
      ->add_option("--camera", s->camera,
                   "auto (default), top, or eye=x,y,z:target=x,y,z[:up=...][:fov=deg]")
      ->check(camera_spec());
  render
      ->add_option("--view", s->view,
                   "shaded (default) or variants (each cell coloured by its variant)")
      ->check(CLI::IsMember({"shaded", "variants"}));
  render->add_option("--width", s->width, "image width (default 640)")->check(CLI::Range(1, 16384));
  render->add_option("--height", s->height, "image height (default 480)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--depth", s->depth, "octree depth (0..8, default 6)")
      ->check(CLI::Range(0, 8));
  render
      ->add_option("--box", s->box,
                   "x0,y0,z0,x1,y1,z1: the box traced (default: the model's bounds)")
      ->delimiter(',');
  render->add_flag("--whole", s->whole,
                   "trace the whole tree instead of each cell's pruned tape (for comparison)");
  render->add_flag("--no-shadows", s->no_shadows, "no shadow rays");
  render
      ->add_option("--backend", s->backend,
                   "cpu (default), vulkan or auto: on Vulkan each variant is its own generated "
                   "kernel")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  render
      ->add_option("--evaluators", s->evaluators,
                   "Vulkan: when-ready (default; the interpreter until a variant's shader is "
                   "compiled), compiled or interpreter")
      ->check(CLI::IsMember({"when-ready", "compiled", "interpreter"}));
  threads(render);
  stats(render);
  render->callback([s, &action] { action = [s] { return run_render(*s); }; });

  CLI::App* comp =
      cmd->add_subcommand("compile", "each variant's GLSL, the cells' parameters and a manifest");
  comp->add_option("--depth", s->depth, "octree depth (0..8, default 6)")->check(CLI::Range(0, 8));
  comp->add_option("-o,--output", s->out, "directory to write (created)")->required();
  comp->add_flag(
      "--spirv", s->spirv,
      "also compile each variant's evaluation kernel to SPIR-V (variant_N.spv), on worker "
      "threads, timed in --stats");
  stats(comp);
  comp->callback([s, &action] { action = [s] { return run_compile(*s); }; });
}

}  // namespace voxfield::cli

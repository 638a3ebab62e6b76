// The showcase's voxel compiler: the example CSG models (a gear, a Menger sponge, a building,
// smooth blobs) compiled into octrees of small evaluators, pictured shaded and by variant, their
// figures against the whole tree, and two of them voxelised into MagicaVoxel files — pruned and
// whole-tree voxelisations checked equal.
#include <chrono>
#include <fstream>
#include <sstream>

#include "cli.h"
#include "showcase.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"
#include "voxfield/csg_files.h"
#include "voxfield/csg_mesh.h"
#include "voxfield/csg_render.h"
#include "voxfield/file.h"
#include "voxfield/gpu.h"
#include "voxfield/gpu_render.h"
#include "voxfield/mesh_files.h"
#include "voxfield/png.h"
#include "voxfield/vox.h"

namespace voxfield::cli {

namespace {

// The models drawn on Vulkan as Palecek proposes (each variant its own generated kernel, the
// interpreter meanwhile), against the CPU's pictures.
void showcase_csg_vulkan(const std::filesystem::path& examples, const std::filesystem::path& out,
                         int size, std::ostream& md, std::vector<Timing>& timings) {
  const std::shared_ptr<gpu::Context> ctx = showcase_vulkan(md);
  if (!ctx) return;
  md << "\nThe same models sphere-traced on Vulkan (" << ctx->device().name
     << (ctx->device().hardware ? "" : "; a CPU emulating a GPU, so its times are not GPU speed")
     << "): rays advance cell by cell in rounds, each variant's rays run that variant's own "
        "generated kernel, compiled on worker threads while the interpreter draws its cells "
        "(`voxfield csg MODEL render --backend vulkan`).\n\n"
     << "| model | variants | marches by compiled kernels / by the interpreter | rounds | "
        "dispatches | submits | pixels > 8 levels from the CPU's | ms |\n"
        "|---|---|---|---|---|---|---|---|\n";
  std::string pictures = "\n| model | CPU | Vulkan |\n|---|---|---|\n";
  for (const char* name : {"gear", "building"}) {
    const csg::Model model = csg::load_model(examples / "csg" / (std::string(name) + ".sdf"));
    CsgRenderOptions o;
    o.width = picture_pixels(480, size);
    o.height = picture_pixels(360, size);
    const Image cpu = render_csg(model, o);
    CsgRenderStats st;
    gpu::CsgGpuStats gs;
    const Image image = gpu::render_csg(*ctx, model, o, &st, {}, &gs);
    std::int64_t off = 0;
    for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3) {
      int worst = 0;
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(int{image.rgb[i + c]} - int{cpu.rgb[i + c]}));
      off += worst > 8;
    }
    write_png(image, out / (std::string("csg-") + name + "-vulkan.png"));
    md << "| " << name << " | " << gs.variants << " | " << gs.compiled_dispatches << " / "
       << gs.interpreted_dispatches << " | " << gs.rounds << " | " << gs.dispatches << " | "
       << gs.submits << " | " << off << " of " << image.rgb.size() / 3 << " | "
       << fixed(st.render_ms, 0) << " |\n";
    pictures += std::string("| ") + name + " | ![cpu](csg-" + name + ".png) | ![vulkan](csg-" +
                name + "-vulkan.png) |\n";
    timings.push_back({std::string("CSG ") + name + ": render " + std::to_string(o.width) + "x" +
                           std::to_string(o.height) + " on Vulkan",
                       st.render_ms, std::to_string(gs.dispatches) + " dispatches"});
  }
  md << pictures;
}

}  // namespace

void showcase_csg(const std::filesystem::path& examples, const std::filesystem::path& out, int size,
                  std::ostream& md, std::vector<Timing>& timings) {
  namespace fs = std::filesystem;
  md << "\n## The voxel compiler: CSG models\n\n";
  if (!fs::is_directory(examples)) {
    md << "The example models were not found at `" << examples.string()
       << "` (give `--examples`).\n";
    return;
  }
  md << "Models written as S-expressions (docs/csg.md), compiled as Palecek's \"A Better Approach "
        "to SDF "
        "Decomposition\" proposes: transforms folded into the shapes, the tree clipped per octree "
        "cell "
        "(depth 6) to the branches that can matter there, and the pruned trees grouped into "
        "*variants* "
        "by structure. Pictures are sphere-traced through the octree, each cell with its own "
        "pruned "
        "tape; the variant view colours each cell by its variant.\n\n"
     << "| model | nodes | variants | nodes per surface cell (mean / whole) | octree ms | render "
        "ms | "
        "tape instructions run, whole / pruned |\n|---|---|---|---|---|---|---|\n";
  std::string pictures = "| model | shaded | variants |\n|---|---|---|\n";
  for (const char* name : {"gear", "building", "blobs", "menger"}) {
    const fs::path path = examples / "csg" / (std::string(name) + ".sdf");
    const csg::Model model = csg::load_model(path);
    CsgRenderOptions o;
    o.width = picture_pixels(480, size);
    o.height = picture_pixels(360, size);
    const std::string picture = std::to_string(o.width) + "x" + std::to_string(o.height);
    CsgRenderStats st, whole_st, var_st, small_st;
    const Image shaded = render_csg(model, o, &st);
    o.view = CsgRenderOptions::View::kVariants;
    const Image variants = render_csg(model, o, &var_st);
    o.view = CsgRenderOptions::View::kShaded;
    // The whole tape traced at a fifth of the size (it costs up to 100 times more per ray), against
    // the pruned tapes at the same size: the instructions per picture compare like with like.
    o.width = o.width / 5;
    o.height = o.height / 5;
    (void)render_csg(model, o, &small_st);
    o.prune = false;
    (void)render_csg(model, o, &whole_st);
    write_png(shaded, out / (std::string("csg-") + name + ".png"));
    write_png(variants, out / (std::string("csg-") + name + "-variants.png"));
    const csg::Tape tape = csg::compile_tape(model);
    csg::OctreeOptions oo;
    oo.depth = 6;
    const csg::Octree tree = csg::build_octree(tape, model, oo);
    timings.push_back({std::string("CSG ") + name + ": octree + render " + picture,
                       st.octree_ms + st.render_ms, std::to_string(st.variants) + " variants"});
    md << "| " << name << " | " << csg::model_info(model).nodes << " | " << tree.stats.variants
       << " | " << fixed(tree.stats.mean_nodes, 2) << " / " << tree.stats.whole_nodes << " | "
       << fixed(tree.stats.octree_ms, 0) << " | " << fixed(st.render_ms, 0) << " | "
       << fixed(static_cast<double>(whole_st.instructions) /
                    static_cast<double>(std::max<std::int64_t>(small_st.instructions, 1)),
                1)
       << "× |\n";
    pictures += std::string("| ") + name + " | ![" + name + "](csg-" + name + ".png) | ![" + name +
                " variants](csg-" + name + "-variants.png) |\n";
  }
  md << "\n" << pictures;

  // Voxelised into worlds: pruned and whole-tree evaluation give the same voxels.
  md << "\n| voxelised | voxels | solid | pruned ms | whole-tree ms | equal "
        "|\n|---|---|---|---|---|---|\n";
  for (const auto& [name, voxel] : {std::pair{"building", 0.1}, std::pair{"gear", 0.1}}) {
    const fs::path path = examples / "csg" / (std::string(name) + ".sdf");
    const csg::Model model = csg::load_model(path);
    csg::VoxelizeOptions vo;
    vo.voxel_size = voxel;
    const csg::Voxelized pruned = csg::voxelize(model, vo);
    vo.prune = false;
    const csg::Voxelized whole = csg::voxelize(model, vo);
    const auto a = encode_vox(pruned.world), b = encode_vox(whole.world);
    write_file_atomic(out / (std::string(name) + ".vox"), a);
    md << "| `" << name << ".vox` | " << pruned.dims.x << "×" << pruned.dims.y << "×"
       << pruned.dims.z << " | " << pruned.world.solid_count() << " | " << fixed(pruned.stats.ms, 0)
       << " | " << fixed(whole.stats.ms, 0) << " | " << (a == b ? "yes" : "**no**") << " |\n";
    timings.push_back({std::string("CSG ") + name + ": voxelise pruned", pruned.stats.ms,
                       fixed(whole.stats.ms / std::max(pruned.stats.ms, 1e-3), 1) +
                           "x faster than the whole tree"});
    if (a != b)
      throw Error("showcase: pruned and whole-tree voxelisations of " + path.string() + " differ");
  }
  // Meshed by dual contouring with crossings and normals from the model itself: the slots' corners
  // stay sharp where sampled normals would round them.
  {
    const csg::Model gear = csg::load_model(examples / "csg" / "gear.sdf");
    CsgMeshOptions mo;
    mo.voxel_size = 0.1;
    mo.mesh.algorithm = Mesher::kDualContouring;
    const auto start = std::chrono::steady_clock::now();
    const Mesh mesh = mesh_csg(gear, mo);
    const double ms = ms_since(start);
    write_file_atomic(out / "gear.glb", encode_mesh(mesh, MeshFormat::kGlb));
    const MeshStats st = mesh_stats(mesh);
    md << "\nThe gear meshed by dual contouring at 0.1 mm with crossings found on the model and "
          "its exact "
          "normals (`gear.glb`): "
       << st.triangles << " triangles, " << (st.watertight() ? "watertight" : "**not watertight**")
       << ", volume " << fixed(st.signed_volume_units3, 1) << " mm³, " << fixed(ms, 0) << " ms.\n";
    timings.push_back(
        {"CSG gear: dual contouring at 0.1", ms, std::to_string(st.triangles) + " triangles"});
  }
  // The gear's variants as generated shaders, compiled to SPIR-V in-process (glslang), and the
  // interpreter that stands in for a variant until its shader is ready.
  if (gpu::built_with_vulkan()) {
    const csg::Model gear = csg::load_model(examples / "csg" / "gear.sdf");
    const csg::Tape tape = csg::compile_tape(gear);
    csg::OctreeOptions o;
    o.depth = 6;
    const csg::Octree tree = csg::build_octree(tape, gear, o);
    const auto start = std::chrono::steady_clock::now();
    std::size_t words =
        gpu::compile_compute_shader("interpreter", csg::glsl_interpreter_kernel()).size();
    for (std::size_t v = 0; v < tree.variants.size(); ++v)
      words += gpu::compile_compute_shader(
                   "variant", csg::glsl_variant_kernel(tree.variants[v].tape, static_cast<int>(v)))
                   .size();
    const double ms = ms_since(start);
    md << "\nThe gear's " << tree.variants.size()
       << " variants as generated compute shaders, and the interpreter that runs any variant's "
          "tape until its shader is ready, compiled to SPIR-V in-process: "
       << words * 4 / 1024 << " KiB in " << fixed(ms, 0) << " ms (one thread).\n";
    timings.push_back({"CSG gear: SPIR-V of its variants and the interpreter", ms,
                       std::to_string(tree.variants.size() + 1) + " shaders"});
    showcase_csg_vulkan(examples, out, size, md, timings);
  }
  md << "\nOpen `building.vox` and `gear.vox` in MagicaVoxel; `voxfield csg MODEL compile -o DIR "
        "[--spirv]` writes each variant's GLSL (and SPIR-V), the cells' parameters and a "
        "manifest.\n";
}

}  // namespace voxfield::cli

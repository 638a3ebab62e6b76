// voxfield generate SCENE -o OUT: write a generated scene (terrain, spheres) as .vox or .npy.
#include <iostream>

#include "cli.h"
#include "progress.h"
#include "voxfield/scene.h"

namespace voxfield::cli {
namespace {

struct GenerateSettings {
  std::string scene = "terrain";
  std::vector<int> size{128};
  std::uint64_t seed = 6683787;
  int chunk_edge = 32;
  std::string out;
};

}  // namespace

Vec3i parse_size(const std::vector<int>& v) {
  if (v.size() == 1) return Vec3i::splat(v[0]);
  if (v.size() == 3) return {v[0], v[1], v[2]};
  throw InvalidArgument("--size takes N or X,Y,Z");
}

void add_generate(CLI::App& app, Action& action) {
  auto s = std::make_shared<GenerateSettings>();
  CLI::App* cmd = app.add_subcommand("generate", "Write a deterministic generated scene");
  cmd->add_option("SCENE", s->scene, "terrain or spheres")
      ->check(CLI::IsMember({"terrain", "spheres"}));
  cmd->add_option("--size", s->size, "N or X,Y,Z voxels")->delimiter(',')->expected(1, 3);
  cmd->add_option("--seed", s->seed, "random seed");
  cmd->add_option("--chunk", s->chunk_edge, "chunk edge (8..128)")
      ->check(CLI::IsMember({8, 16, 32, 64, 128}));
  cmd->add_option("-o,--output", s->out, "output .vox, .npy or .vfw")->required();
  cmd->callback([s, &action] {
    action = [s] {
      Outputs outputs;
      outputs.expect_world(s->out, "-o");
      SceneOptions o;
      o.size = parse_size(s->size);
      o.seed = s->seed;
      o.chunk_edge = s->chunk_edge;
      const auto t0 = std::chrono::steady_clock::now();
      const World w = make_scene(s->scene, o, progress());
      const double gen_ms = ms_since(t0);
      outputs.stage(s->out, encode_world(w, Box3i::from_size(o.size), world_format_of(s->out)));
      outputs.commit();
      std::cerr << "voxfield: " << s->scene << " " << to_string(o.size) << " generated in "
                << gen_ms << " ms, " << w.solid_count() << " solid voxels, wrote " << s->out
                << "\n";
      return 0;
    };
  });
}

}  // namespace voxfield::cli

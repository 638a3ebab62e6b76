// voxfield convert IN OUT: between .vox and .npy (in an .npy, non-zero = that material).
#include <iostream>

#include "cli.h"

namespace voxfield::cli {
namespace {

struct ConvertSettings {
  std::string in, out;
};

int run_convert(const ConvertSettings& s) {
  const LoadedWorld w = load_world(s.in, 32);
  save_world(w.world, w.extent, s.out);
  std::cerr << "voxfield: wrote " << s.out << " (" << w.world.solid_count() << " solid voxels)\n";
  return 0;
}

}  // namespace

void add_convert(CLI::App& app, Action& action) {
  auto s = std::make_shared<ConvertSettings>();
  CLI::App* cmd = app.add_subcommand("convert", "Convert a world between .vox and .npy (chosen by "
                                                "extension); the output is written atomically");
  cmd->add_option("IN", s->in, "input .vox or .npy")->required();
  cmd->add_option("OUT", s->out, "output .vox or .npy")->required();
  cmd->callback([s, &action] { action = [s] { return run_convert(*s); }; });
}

}  // namespace voxfield::cli

// voxfield convert IN OUT: between .vox, .npy and .vfw (in an .npy, non-zero = that material), and
// to .vdb (an OpenVDB Int32 grid of materials; vdb.h).
#include <iostream>

#include "cli.h"

namespace voxfield::cli {
namespace {

struct ConvertSettings {
  std::string in, out;
};

int run_convert(const ConvertSettings& s) {
  // Converting a file onto itself is safe: the input is read whole before the output is written.
  Outputs outputs({s.in});
  outputs.expect_world(s.out, "OUT", /*may_be_input=*/true);
  set_activity("loading " + s.in);
  LoadOptions lo;
  lo.chunk_edge = 0;  // a .vfw keeps the chunk edge it was saved with
  const LoadedWorld w = load_world(s.in, lo);
  set_activity("writing " + s.out);
  outputs.stage(s.out, encode_world(w.world, w.extent, world_format_of(s.out)));
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << w.world.solid_count() << " solid voxels)\n";
  return 0;
}

}  // namespace

void add_convert(CLI::App& app, Action& action) {
  auto s = std::make_shared<ConvertSettings>();
  CLI::App* cmd = app.add_subcommand("convert",
                                     "Convert a world between .vox, .npy and .vfw, or to .vdb "
                                     "(chosen by extension); the output is written atomically");
  cmd->add_option("IN", s->in, "input .vox, .npy or .vfw")->required();
  cmd->add_option("OUT", s->out, "output .vox, .npy, .vfw or .vdb")->required();
  cmd->callback([s, &action] { action = [s] { return run_convert(*s); }; });
}

}  // namespace voxfield::cli

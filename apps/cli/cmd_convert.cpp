// voxfield convert IN OUT: between .vox, .npy and .vfw (in an .npy, non-zero = that material), and
// to .vdb (an OpenVDB Int32 grid of materials; vdb.h); a triangle mesh (.obj, .ply, .stl, .off)
// is voxelised by its generalized winding number (mesh_voxelize.h) at --voxel-size, in the mesh's
// units as its frame. A world written to .vfw or .vdb can be given a frame (--voxel-size,
// --origin; docs/frames.md).
#include <iostream>

#include "cli.h"
#include "field_args.h"
#include "progress.h"
#include "voxfield/mesh_read.h"

namespace voxfield::cli {
namespace {

struct ConvertSettings {
  std::string in, out;
  std::vector<double> voxel_size;  // one edge (a mesh's, or a world's cubic voxels) or three
  std::vector<double> origin;      // x, y, z: where a world's voxel corner (0, 0, 0) lies
  std::vector<double> rotate;      // degrees, then the axis x, y, z
  std::string grid;
};

// The frame --voxel-size and --origin give a world read from a file, over the one it came with
// (docs/frames.md); what they do not give stays.
void set_frame(World& world, const ConvertSettings& s) {
  if (s.voxel_size.size() == 1) world.frame.voxel_size_world = Vec3d{1, 1, 1} * s.voxel_size[0];
  if (s.voxel_size.size() == 3)
    world.frame.voxel_size_world = {s.voxel_size[0], s.voxel_size[1], s.voxel_size[2]};
  if (s.origin.size() == 3) world.frame.origin_world = {s.origin[0], s.origin[1], s.origin[2]};
  if (s.rotate.size() == 4)
    world.frame.rotation = rotation_about(s.rotate[0], {s.rotate[1], s.rotate[2], s.rotate[3]});
}

int run_convert(const ConvertSettings& s) {
  check_grid_input(s.in, s.grid);
  // Converting a file onto itself is safe: the input is read whole before the output is written.
  Outputs outputs({s.in});
  outputs.expect_world(s.out, "OUT", /*may_be_input=*/true);
  if (s.voxel_size.size() == 2) throw UsageError("--voxel-size takes one edge or three (sx,sy,sz)");
  if (mesh_input_format_of(s.in)) {
    if (s.voxel_size.size() != 1)
      throw UsageError(s.in + ": a mesh needs --voxel-size (one edge, in its units)");
    if (!s.origin.empty() || !s.rotate.empty())
      throw UsageError("--origin, --rotate: a voxelised mesh's frame is the mesh's own units");
    set_activity("reading " + s.in);
    const TriangleMesh mesh = read_mesh(s.in);
    MeshVoxelOptions o;
    o.voxel_size = s.voxel_size[0];
    o.padding_voxels = 0;
    o.interrupter = progress();
    set_activity("voxelising " + s.in);
    const World world = voxelize_mesh(mesh, o);
    set_activity("writing " + s.out);
    outputs.stage(s.out, encode_world(world, *world.voxels.bounds(), world_format_of(s.out)));
    outputs.commit();
    std::cerr << "voxfield: wrote " << s.out << " (" << mesh.triangles.size() << " triangles, "
              << world.solid_count() << " solid voxels in "
              << to_string(world.voxels.bounds()->size()) << ")\n";
    note_frame_left_out(world, s.out);
    return 0;
  }
  if ((!s.voxel_size.empty() || !s.origin.empty() || !s.rotate.empty()) &&
      world_format_of(s.out) != WorldFormat::kVfw && world_format_of(s.out) != WorldFormat::kVdb)
    throw UsageError("--voxel-size, --origin and --rotate set the world's frame, which " + s.out +
                     " cannot keep (.vfw and .vdb keep it)");
  if (!s.rotate.empty() && Vec3d{s.rotate[1], s.rotate[2], s.rotate[3]}.length() == 0)
    throw UsageError("--rotate DEG,AX,AY,AZ: the axis must not be zero");
  set_activity("loading " + s.in);
  LoadOptions lo;
  lo.chunk_edge = 0;  // a .vfw keeps the chunk edge it was saved with
  lo.vdb_grid = s.grid;
  LoadedWorld w = load_world(s.in, lo);
  set_frame(w.world, s);
  set_activity("writing " + s.out);
  outputs.stage(s.out, encode_world(w.world, w.extent, world_format_of(s.out)));
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << w.world.solid_count() << " solid voxels)\n";
  note_frame_left_out(w.world, s.out);
  return 0;
}

}  // namespace

void add_convert(CLI::App& app, Action& action) {
  auto s = std::make_shared<ConvertSettings>();
  CLI::App* cmd = app.add_subcommand("convert",
                                     "Convert a world between .vox, .npy and .vfw, or to .vdb, or "
                                     "voxelise a mesh (chosen by extension); the output is written "
                                     "atomically");
  cmd->add_option("IN", s->in, "input .vox, .npy, .vfw or .vdb, or a mesh: .obj, .ply, .stl, .off")
      ->required();
  add_grid_option(cmd, s->grid);
  cmd->add_option("--voxel-size", s->voxel_size,
                  "for a mesh: the voxels' edge in the mesh's units (solid where the generalized "
                  "winding number at a voxel's centre is >= 1/2); for a world written to .vfw or "
                  ".vdb: its voxels' size in world units, S or SX,SY,SZ (its frame)")
      ->delimiter(',')
      ->expected(1, 3)
      ->check(finite_positive());
  cmd->add_option("--origin", s->origin,
                  "for a world written to .vfw or .vdb: X,Y,Z, where its voxel corner (0,0,0) "
                  "lies in world units (its frame)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite_number());
  cmd->add_option("--rotate", s->rotate,
                  "for a world written to .vfw or .vdb: DEG,AX,AY,AZ, its frame's rotation set to "
                  "DEG degrees about the axis (AX,AY,AZ), replacing the one read")
      ->delimiter(',')
      ->expected(4)
      ->check(finite_number());
  cmd->add_option("OUT", s->out, "output .vox, .npy, .vfw or .vdb")->required();
  cmd->callback([s, &action] { action = [s] { return run_convert(*s); }; });
}

}  // namespace voxfield::cli

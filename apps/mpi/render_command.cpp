// voxfield-mpi render (render_command.h).
#include "render_command.h"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "rank_stats.h"
#include "read_option.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/mpi.h"
#include "voxfield/parallel.h"
#include "voxfield/png.h"
#include "voxfield/render_relay.h"

namespace voxfield::mpi_cli {

CLI::App* add_render_command(CLI::App& app, RenderSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "render", "a frame of a world, as `voxfield render` (each rank walks the rays in its slab)");
  cmd->add_option("IN", s.in, "input .npy (read a slab per rank), .vox or .vfw")->required();
  cmd->add_option("-o,--output", s.out, "output .png (written by rank 0)")->required();
  cmd->add_option("--width", s.width, "image width in pixels")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", s.height, "image height in pixels")->check(CLI::Range(1, 16384));
  cmd->add_option("--camera", s.camera,
                  "auto | top | eye=x,y,z:target=x,y,z[:up=x,y,z][:fov=deg][:ortho=height] (z up; "
                  "voxel units, or the world's with --camera-frame world)");
  cmd->add_option(
         "--camera-frame", s.camera_frame,
         "voxels (default) or world: an eye=...:target=... camera in the world's frame "
         "(a .vfw's origin, voxel size and rotation, of any voxel shape); auto and top frame "
         "the content either way")
      ->check(CLI::IsMember({"voxels", "world"}));
  cmd->add_option("--view", s.view,
                  "shaded | chunks | distance (the error view's approximations run on one process: "
                  "voxfield render)")
      ->check(CLI::IsMember({"shaded", "chunks", "distance"}));
  cmd->add_option("--slice", s.slice, "distance view: z of the cut plane (default: the middle)");
  cmd->add_option("--metric", s.metric,
                  "field rays skip by: manhattan (default), chebyshev, euclidean")
      ->check(CLI::IsMember({"manhattan", "chebyshev", "euclidean"}));
  cmd->add_option("--skip", s.skip, "none (plain DDA), chunks, distance (default)")
      ->check(CLI::IsMember({"none", "chunks", "distance"}));
  cmd->add_flag("--no-shadows", s.no_shadows, "no soft shadows");
  cmd->add_flag("--no-ao", s.no_ao, "no ambient occlusion");
  cmd->add_option("--fog", s.fog, "fog density per voxel (0 = none)")->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--chunk", s.chunk, "chunk edge: 8, 16, 32, 64 or 128; slabs are cut on chunks")
      ->check(CLI::IsMember({8, 16, 32, 64, 128}));
  cmd->add_option("--threads", s.threads, "threads per rank (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--stats", s.stats, "timings, ray counters and exchange figures as JSON");
  add_read_options(cmd, s.read);
  cmd->add_option("--repeat", s.repeat, "draw the frame N times, report the median time")
      ->check(CLI::Range(1, 1000));
  return cmd;
}

int run_render(MPI_Comm comm, const RenderSettings& s) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  RenderSceneOptions so;
  so.skip_metric = parse_metric(s.metric);
  so.lighting_field = !(s.no_shadows && s.no_ao);
  RenderOptions o;
  o.width = s.width;
  o.height = s.height;
  o.view = parse_render_view(s.view);
  o.skip = parse_skip_mode(s.skip);
  o.soft_shadows = !s.no_shadows;
  o.ambient_occlusion = !s.no_ao;
  o.fog_density = s.fog;
  o.slice_z = s.slice;
  mpi::check_outputs(comm, {}, {s.out, s.stats}, {s.in});
  const double t0 = MPI_Wtime();
  // Each rank holds its slab and the slices its lighting reads beyond it.
  const mpi::WorldSlab slab =
      mpi::load_world_slab(comm, s.in, s.chunk, relay_ghost_slices(so), slab_read_options(s.read));
  const double load_ms = max_over(comm, (MPI_Wtime() - t0) * 1e3);
  const Box3i& domain = slab.partition.domain;
  // Automatic cameras frame what is there, as voxfield render's do: the content, within the
  // file's extent.
  const Box3i content = mpi::content_bounds(comm, slab.partition, slab.world);
  const Camera camera = mpi::collectively(comm, [&] {
    return Camera::parse(s.camera, s.camera == "top" || content.empty() ? domain : content,
                         static_cast<double>(s.width) / s.height,
                         s.camera_frame == "world" ? &slab.world.frame : nullptr);
  });
  // With --repeat, the whole frame (fields, scene, walks, composite) is drawn several times and
  // the median time reported, as voxfield render does; the counters, exchange and phases are the
  // last frame's (every frame is the same).
  std::vector<double> times;
  Image image;
  mpi::ExchangeStats ex;
  RenderStats st;
  mpi::RenderPhases phases;
  for (int r = 0; r < s.repeat; ++r) {
    ex = {};
    st = {};
    phases = {};
    MPI_Barrier(comm);  // the frame's time starts together on every rank
    const double t1 = MPI_Wtime();
    image = mpi::render(comm, slab.partition, slab.world, so, camera, o, &st, &ex, &phases);
    times.push_back(max_over(comm, (MPI_Wtime() - t1) * 1e3));
  }
  const std::vector<double> each_ms = times;
  std::sort(times.begin(), times.end());
  const double render_ms = times[times.size() / 2];
  const nlohmann::json per_rank_phases = phases_json(comm, phases);
  const auto counters = [&](const TraversalCounters& c) {
    return nlohmann::json{
        {"rays", sum_over(comm, static_cast<std::uint64_t>(c.rays))},
        {"steps", sum_over(comm, static_cast<std::uint64_t>(c.steps))},
        {"voxel_reads", sum_over(comm, static_cast<std::uint64_t>(c.voxel_reads))},
        {"chunk_skips", sum_over(comm, static_cast<std::uint64_t>(c.chunk_skips))},
        {"distance_skips", sum_over(comm, static_cast<std::uint64_t>(c.distance_skips))}};
  };
  const nlohmann::json primary = counters(st.primary), shadow = counters(st.shadow);
  const nlohmann::json exchange = exchange_json(comm, ex);
  mpi::collectively(comm, [&] {
    if (rank != 0) return;
    FileTransaction outputs;
    // The frame's content hash as voxfield render --stats prints it, to compare the two.
    std::ostringstream hash_text;
    hash_text << std::hex << std::setw(16) << std::setfill('0') << content_hash(image);
    outputs.stage(s.out, encode_png(image));
    if (!s.stats.empty()) {
      nlohmann::json j{{"input", s.in},
                       {"output", s.out},
                       {"ms", render_ms},
                       {"ms_each", each_ms},
                       {"load_ms_max", load_ms},
                       {"image_hash", hash_text.str()},
                       {"width", s.width},
                       {"height", s.height},
                       {"view", s.view},
                       {"skip", s.skip},
                       {"skip_metric", s.metric},
                       {"ranks", size},
                       {"threads", max_threads()},
                       {"read_in_parts", slab.read_in_parts},
                       {"read", read_name(slab.read_by)},
                       {"slabs", slab.partition.z},
                       {"primary", primary},
                       {"shadow", shadow}};
      j["exchange"] = exchange;
      j["phases"] = per_rank_phases;
      outputs.stage(s.stats, j.dump(2) + "\n");
    }
    outputs.commit();
  });
  if (rank == 0)
    std::cerr << "voxfield-mpi: wrote " << s.out << " (" << s.width << "x" << s.height << ", "
              << s.view << " view, " << size << " ranks, " << render_ms << " ms)\n";
  return 0;
}

}  // namespace voxfield::mpi_cli

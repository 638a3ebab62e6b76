// voxfield-mpi: exact distance fields, meshes and frames of volumes split over the processes of
// an MPI job.
//
//   mpirun -np N voxfield-mpi field IN -o OUT.{npy,vdb} [--metric M] [--signed] [--max-distance D]
//          [--storage S] [--spacing sx,sy,sz] [--sites S.npy] [--packed P.npy] [--stats S.json]
//          [--chunk C] [--threads T] [--read every|rank0] [--grid G] [--memory-limit B]
//          [--backend cpu|vulkan|auto] [--device-per-rank]
//   mpirun -np N voxfield-mpi edit IN -e EDITS.jsonl -o OUT.npy [field options] [--stats S.json]
//          [--balance volume|content|edits] [--save-world W.vfw|W.npy] [--read every|rank0]
//          [--grid G] [--mesh M.{ply,obj,stl,glb}] [--mesh-algorithm mc|sn|dc]
//   mpirun -np N voxfield-mpi bench --size X,Y,Z [--spheres K] [--repeat R] [field options]
//   mpirun -np N voxfield-mpi mesh IN -o OUT.{ply,obj,stl,glb} [--algorithm mc|sn|dc]
//          [--iso V] [--inside below|above] [--spacing sx,sy,sz] [--chunk C]
//          [--balance content|count] [--threads T] [--stats S.json]
//          (a world IN: [--metric M] [--read every|rank0] [--grid G], iso 0 only)
//   mpirun -np N voxfield-mpi render IN -o OUT.png [--width W] [--height H] [--camera C]
//          [--view shaded|chunks|distance] [--slice Z] [--metric M] [--skip S] [--no-shadows]
//          [--no-ao] [--fog F] [--chunk C] [--threads T] [--repeat N] [--read every|rank0]
//          [--grid G] [--stats S.json]
//
// `field` writes byte for byte what `voxfield field` writes for the same input and options; each
// rank holds only its slab of a .npy input and of the field. `edit` writes what `voxfield edit`
// writes: every rank applies every edit of the script to its slab and the slices a clamped value
// can reach beyond it, with incremental updates of its own field. `bench` generates a world of
// random spheres slab by slab (no file) and prints, per run, the time, the rate and the bytes
// exchanged. `mesh` meshes a float volume or a world's surface, each rank the chunk layers of its
// planes (mpi.h), and writes the file `voxfield mesh` writes, byte for byte; `edit --mesh` writes
// that file for the edited world. `render` draws the frame `voxfield render` draws, byte for byte,
// each rank walking its stretch of every primary ray and the shadow rays that cross its slab,
// handing those on (render_relay.h). Every rank parses the same command
// line; rank 0 alone prints. A failure on any rank is reported by rank 0 as "voxfield-mpi: rank R:
// ..." and every rank exits with 1 (2 for usage errors).
#include <mpi.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numeric>

#include "backend_option.h"
#include "bench_world.h"
#include "mesh_command.h"
#include "rank_stats.h"
#include "read_option.h"
#include "render_command.h"
#include "voxfield/distance.h"
#include "voxfield/distance_executor.h"
#include "voxfield/distance_slab.h"
#include "voxfield/edit_script.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/mpi.h"
#include "voxfield/parallel.h"
#include "voxfield/vdb.h"

namespace {

using namespace voxfield;

struct FieldSettings {
  std::string metric = "manhattan", storage = "f32";
  mpi_cli::BackendSettings backend;  // --backend, --device-per-rank
  bool is_signed = false;
  double max_distance = 0;
  std::vector<double> spacing;
  int chunk = 32, threads = 0;
  mpi_cli::ReadSettings read;  // --read and --grid (field and edit)

  void add_to(CLI::App* cmd) {
    cmd->add_option("--metric", metric, "manhattan, chebyshev or euclidean")
        ->check(CLI::IsMember({"manhattan", "chebyshev", "euclidean"}))
        ->capture_default_str();
    cmd->add_flag("--signed", is_signed, "negative distances inside solids");
    cmd->add_option("--max-distance", max_distance, "clamp D (0 = no clamp)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--storage", storage, "u8, u16 or f32")
        ->check(CLI::IsMember({"u8", "u16", "f32"}))
        ->capture_default_str();
    cmd->add_option("--spacing", spacing, "voxel size sx,sy,sz (euclidean only)")
        ->delimiter(',')
        ->expected(3)
        ->check(CLI::PositiveNumber);
    cmd->add_option("--chunk", chunk, "chunk edge: 8, 16, 32, 64 or 128; slabs are cut on chunks")
        ->check(CLI::IsMember({8, 16, 32, 64, 128}));
    cmd->add_option("--threads", threads, "threads per rank (default: all cores)")
        ->check(CLI::Range(1, 1024));
    mpi_cli::add_backend_option(cmd, backend);
  }
  DistanceOptions options() const {
    DistanceOptions o;
    o.metric = parse_metric(metric);
    o.signed_distance = is_signed;
    o.max_distance = max_distance;
    o.storage = parse_storage(storage);
    if (!spacing.empty()) o.spacing = {spacing[0], spacing[1], spacing[2]};
    return o;
  }
  // Collective (the devices' counters are summed over the ranks).
  nlohmann::json describe(MPI_Comm comm, const DistanceOptions& o, Vec3i dims, int ranks,
                          const Executor& executor, const gpu::Counters& since = {}) const {
    return {{"metric", metric_name(o.metric)},
            {"backend", executor.on_gpu() ? "vulkan" : "cpu"},
            {"gpu", mpi_cli::gpu_json_over(comm, executor, since)},
            {"signed", o.signed_distance},
            {"max_distance", o.max_distance},
            {"storage", storage_name(o.storage)},
            {"dims", {dims.x, dims.y, dims.z}},
            {"threads", max_threads()},
            {"chunk", chunk},
            {"ranks", ranks}};
  }
};

using mpi_cli::exchange_json;
using mpi_cli::max_over;
using mpi_cli::peak_rss_bytes;
using mpi_cli::sum_over;

int run_field(MPI_Comm comm, const FieldSettings& f, const std::string& in, const std::string& out,
              const std::string& sites, const std::string& packed, const std::string& stats) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::optional<ThreadLimit> limit;
  if (f.threads > 0) limit.emplace(f.threads);
  DistanceOptions o = f.options();
  o.nearest_sites = !sites.empty();
  const std::string out_ext = lowercase_extension(out);
  if (out_ext != ".npy" && out_ext != ".vdb")
    throw InvalidArgument(out + ": voxfield-mpi writes fields as .npy or .vdb");
  const bool vdb_output = out_ext == ".vdb";
  // Everything that can be wrong with the outputs is found before the world is loaded.
  mpi::check_outputs(comm, {out, sites, packed}, {stats}, {in});
  const Executor executor = mpi_cli::choose_rank_executor(comm, f.backend);
  const double t0 = MPI_Wtime();
  const mpi::WorldSlab slab =
      mpi::load_world_slab(comm, in, f.chunk, 0, mpi_cli::slab_read_options(f.read));
  const double load_ms = (MPI_Wtime() - t0) * 1e3;
  // A .vdb level set holds world distances: a world of anisotropic voxels is measured in its
  // voxel size unless --spacing says otherwise, as voxfield field does.
  const Vec3d voxel = slab.world.frame.voxel_size_world;
  if (vdb_output && f.spacing.empty() && o.metric == Metric::kEuclidean &&
      !(voxel.x == voxel.y && voxel.y == voxel.z)) {
    o.spacing = {voxel.x, voxel.y, voxel.z};
    if (rank == 0)
      std::cerr << "voxfield-mpi: measuring in the world's voxel size " << voxel.x << " x "
                << voxel.y << " x " << voxel.z << " (--spacing), so that " << out
                << " holds distances in its units (--max-distance too)\n";
  }
  // The .vdb's refusals before the field is computed (every rank reaches the same verdict).
  if (vdb_output)
    mpi::collectively(comm, [&] { check_vdb_field_output(o, slab.world.frame, out); });
  mpi::ExchangeStats ex;
  MPI_Barrier(comm);  // the field's time starts together on every rank
  const double t1 = MPI_Wtime();
  DistanceField field =
      mpi::compute_distance_field(comm, slab.partition, slab.world, o, executor, &ex);
  field.frame = slab.world.frame;  // where a .vdb places it
  const double field_ms = max_over(comm, (MPI_Wtime() - t1) * 1e3);
  const Box3i& domain = slab.partition.domain;
  nlohmann::json j = f.describe(comm, o, domain.size(), size, executor);
  j.update(nlohmann::json{{"algorithm", "exact"},
                          {"ms", field_ms},
                          {"mvox_per_s", static_cast<double>(domain.volume()) / (field_ms * 1e3)},
                          {"load_ms_max", max_over(comm, load_ms)},
                          {"format", slab.format},
                          {"read_in_parts", slab.read_in_parts},
                          {"read", mpi_cli::read_name(slab.read_by)},
                          {"slabs", slab.partition.z}});
  j["exchange"] = exchange_json(comm, ex);
  // A .vdb is joined on rank 0 and staged with the other outputs: written all or nothing.
  std::optional<FileTransaction> outputs;
  if (rank == 0) outputs.emplace();
  FileTransaction* tx = outputs ? &*outputs : nullptr;
  if (vdb_output) {
    mpi::ExchangeStats vdb_ex;
    std::vector<std::uint8_t> vdb = mpi::encode_vdb_field(comm, slab.partition, field, &vdb_ex);
    j["vdb_exchange"] = exchange_json(comm, vdb_ex);
    mpi::collectively(comm, [&] {
      if (tx) tx->stage(out, std::move(vdb));
    });
  }
  mpi::FieldFiles files{
      vdb_output ? std::string() : out, sites, stats, j.dump(2) + "\n", packed, &slab.world, {}};
  mpi::write_field_npy(comm, slab.partition, field, files, nullptr, tx);
  mpi::collectively(comm, [&] {
    if (tx) tx->commit();
  });
  if (rank == 0) {
    const Vec3i d = domain.size();
    std::cerr << "voxfield-mpi: exact " << metric_name(o.metric) << " field of " << d.x << "x"
              << d.y << "x" << d.z << " on " << size << " ranks in " << field_ms << " ms, wrote "
              << out << "\n";
  }
  return 0;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1,
                    static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

int run_edit(MPI_Comm comm, const FieldSettings& f, const std::string& in,
             const std::string& edits_path, const std::string& out, const std::string& stats,
             const std::string& save_world, const std::string& balance, const std::string& mesh,
             const std::string& mesh_algorithm) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::optional<ThreadLimit> limit;
  if (f.threads > 0) limit.emplace(f.threads);
  const DistanceOptions o = f.options();
  const std::string world_ext = lowercase_extension(save_world);
  if (!save_world.empty() && world_ext != ".vfw" && world_ext != ".npy")
    throw InvalidArgument("--save-world " + save_world +
                          ": voxfield-mpi writes worlds as .vfw or .npy (each rank its slab); "
                          "voxfield convert turns either into .vox");
  const Mesher mesher = parse_mesher(mesh_algorithm);
  if (!mesh.empty()) (void)mesh_format_of(mesh);  // an unknown extension before any work
  mpi::check_outputs(comm, {out, save_world, mesh}, {stats}, {in, edits_path});
  // With --mesh the ranks keep the slices beyond their slabs that meshing the edited world reads.
  const int kept = mesh.empty() ? 0 : mesh_world_slab_reach(mesher);
  // The script and the ghost slices are checked on every rank before the world is loaded.
  // (Two named values, not a structured binding: the loop's lambda below captures the script,
  // and clang 14, which CI's sanitizer builds use, cannot capture a binding.)
  const auto script_and_ghost = mpi::collectively(comm, [&] {
    EditScriptOptions eo;
    eo.chunk_edge = f.chunk;
    return std::make_pair(read_edit_script(edits_path, eo), mpi::edit_ghost_slices(o));
  });
  const std::vector<Edit>& edits = script_and_ghost.first;
  const int ghost = script_and_ghost.second;
  const bool unclamped = !std::isfinite(effective_clamp(o));  // f32: kept by refresh()
  if (unclamped && balance == "edits")
    throw InvalidArgument(
        "--balance edits weighs each slab by the field updates the edits bring it; an unclamped "
        "f32 "
        "field is computed again whole after the script, at a cost that follows the volume "
        "(--balance volume, the default)");
  const double l0 = MPI_Wtime();
  const mpi::SlabReadOptions read = mpi_cli::slab_read_options(f.read);
  mpi::WorldSlab slab = [&] {
    // By the script's edits: what each unit of slices will recompute, known before any reading.
    if (balance == "edits")
      return mpi::load_world_slab(
          comm, in, f.chunk, std::max(ghost, kept),
          [&](const Box3i& domain) {
            return mpi::partition_slabs(domain, size, f.chunk,
                                        mpi::edit_unit_weights(domain, f.chunk, edits, ghost));
          },
          read);
    // By content: the chunks holding air and solid (the surface).
    if (balance == "content")
      return mpi::load_world_slab_by_content(comm, in, f.chunk, std::max(ghost, kept), read);
    return mpi::load_world_slab(comm, in, f.chunk, std::max(ghost, kept), read);
  }();
  const double load_ms = max_over(comm, (MPI_Wtime() - l0) * 1e3);
  const Executor executor = mpi_cli::choose_rank_executor(comm, f.backend);
  const double t0 = MPI_Wtime();
  mpi::SlabEditor editor(comm, slab.partition, slab.world, o, executor, kept);
  slab.world = World();  // the editor holds its own copy
  const double build_ms = max_over(comm, (MPI_Wtime() - t0) * 1e3);
  // Local work only: a failure on one rank is agreed on after the loop.
  std::vector<double> edit_ms(edits.size(), 0.0);
  std::uint64_t reached = 0, recomputed = 0;
  mpi::collectively(comm, [&] {
    for (std::size_t i = 0; i < edits.size(); ++i) {
      const double e0 = MPI_Wtime();
      const mpi::SlabEditor::Result r = editor.apply(edits[i]);
      edit_ms[i] = (MPI_Wtime() - e0) * 1e3;
      reached += r.reached ? 1 : 0;
      recomputed += static_cast<std::uint64_t>(r.voxels_recomputed);
    }
  });
  // An unclamped f32 field follows the script's solids in one transform over the ranks, after it.
  mpi::ExchangeStats refresh_exchange;
  std::int64_t refreshed_voxels = 0;
  const double r0 = MPI_Wtime();
  const bool refreshed = editor.refresh(comm, &refresh_exchange, &refreshed_voxels);
  const double refresh_ms = max_over(comm, (MPI_Wtime() - r0) * 1e3);
  recomputed += static_cast<std::uint64_t>(refreshed_voxels);
  // An edit is done when the slowest rank is.
  std::vector<double> slowest(edit_ms.size());
  MPI_Allreduce(edit_ms.data(), slowest.data(), static_cast<int>(edit_ms.size()), MPI_DOUBLE,
                MPI_MAX, comm);
  const double total = std::accumulate(slowest.begin(), slowest.end(), 0.0);
  // The ranks run through the script without waiting for each other: the stream takes as long as
  // the rank with the most work.
  const double stream_ms = max_over(comm, std::accumulate(edit_ms.begin(), edit_ms.end(), 0.0));
  // (On a device the field is read back here, before the counters are read: a failure on one rank
  // reaches every rank.)
  const DistanceField* const final_field = mpi::collectively(comm, [&] { return &editor.field(); });
  nlohmann::json j = f.describe(comm, o, slab.partition.domain.size(), size, executor);
  j.update(nlohmann::json{
      {"load_ms", load_ms},
      {"build_ms", build_ms},
      {"balance", balance},
      {"read", mpi_cli::read_name(slab.read_by)},
      {"edits", edits.size()},
      {"ghost_slices", ghost},
      {"edit_ms", slowest},
      {"total_ms", total},
      {"stream_ms", stream_ms},
      {"p50_ms", percentile(slowest, 0.5)},
      {"p99_ms", percentile(slowest, 0.99)},
      {"ranks_reached_per_edit", edits.empty() ? 0.0
                                               : static_cast<double>(sum_over(comm, reached)) /
                                                     static_cast<double>(edits.size())},
      {"voxels_recomputed_all_ranks", sum_over(comm, recomputed)},
      // "incremental": each rank's field follows every edit (a clamped field); "refresh": the
      // edits change materials and the field is computed again over the ranks after the script.
      {"field_update", unclamped ? "refresh" : "incremental"},
      {"refresh_ms", refresh_ms},
      {"refreshed", refreshed},
      {"slabs", slab.partition.z}});
  if (refreshed) j["refresh_exchange"] = exchange_json(comm, refresh_exchange);
  // Every output in one transaction of rank 0's: written all or nothing.
  std::optional<FileTransaction> outputs;
  if (rank == 0) outputs.emplace();
  FileTransaction* tx = outputs ? &*outputs : nullptr;
  if (!mesh.empty())
    j["mesh"] =
        mpi_cli::write_edited_world_mesh(comm, slab.partition, editor.world(), mesher, mesh, tx);
  const bool world_npy = world_ext == ".npy";
  mpi::write_field_npy(comm, slab.partition, *final_field,
                       {out,
                        {},
                        stats,
                        j.dump(2) + "\n",
                        {},
                        &editor.world(),
                        world_npy ? save_world : std::string()},
                       nullptr, tx);
  if (!save_world.empty() && !world_npy)
    mpi::save_world_vfw(comm, slab.partition, editor.world(), save_world, nullptr, tx);
  mpi::collectively(comm, [&] {
    if (tx) tx->commit();
  });
  if (rank == 0)
    std::cerr << "voxfield-mpi: " << edits.size() << " edits on " << size << " ranks, " << total
              << " ms in all (p50 " << percentile(slowest, 0.5) << " ms, p99 "
              << percentile(slowest, 0.99) << " ms)"
              << (refreshed ? ", the unclamped field recomputed after them in " +
                                  std::to_string(refresh_ms) + " ms"
                            : std::string())
              << ", wrote " << out << "\n";
  return 0;
}

int run_bench(MPI_Comm comm, const FieldSettings& f, const std::vector<int>& dims, int spheres,
              int repeat) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::optional<ThreadLimit> limit;
  if (f.threads > 0) limit.emplace(f.threads);
  const DistanceOptions o = f.options();
  const Box3i domain = Box3i::from_size({dims[0], dims[1], dims[2]});
  const mpi::SlabPartition partition = mpi::partition_slabs(domain, size, f.chunk);
  const Executor executor = mpi_cli::choose_rank_executor(comm, f.backend);
  const World world = mpi::collectively(comm, [&] {
    return mpi_bench::sphere_world_slab(domain, partition.slab(rank), spheres, f.chunk);
  });
  for (int r = 0; r < repeat; ++r) {
    mpi::ExchangeStats ex;
    const gpu::Counters before =
        executor.on_gpu() ? executor.device()->counters() : gpu::Counters{};  // per run
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    const DistanceField field =
        mpi::compute_distance_field(comm, partition, world, o, executor, &ex);
    const double ms = max_over(comm, (MPI_Wtime() - t0) * 1e3);
    nlohmann::json j = f.describe(comm, o, domain.size(), size, executor, before);
    j.update(nlohmann::json{
        {"run", r},
        {"ms", ms},
        {"mvox_per_s", static_cast<double>(domain.volume()) / (ms * 1e3)},
        {"column_bytes", 16.0 * domain.size().x * domain.size().y},
        {"peak_rss_mb_max", max_over(comm, static_cast<double>(peak_rss_bytes()) / 1048576.0)}});
    j["exchange"] = exchange_json(comm, ex);
    if (rank == 0) std::cout << j.dump() << std::endl;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm comm = MPI_COMM_WORLD;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (provided < MPI_THREAD_FUNNELED) {
    // voxfield's thread pool works between MPI calls, which only the main thread makes.
    if (rank == 0)
      std::cerr << "voxfield-mpi: this MPI library gives no MPI_THREAD_FUNNELED support\n";
    MPI_Finalize();
    return 1;
  }
  voxfield::install_signal_cleanup();
  CLI::App app{
      "voxfield-mpi: exact distance fields, meshes and frames over the processes of an MPI job"};
  app.require_subcommand(1);
  std::string memory_limit;
  app.add_option("--memory-limit", memory_limit,
                 "memory limit per rank (bytes, or with K/M/G; default: $VOXFIELD_MEMORY_LIMIT, "
                 "else half of physical memory)");
  FieldSettings f;
  std::string in, out, sites, packed, stats;
  CLI::App* field = app.add_subcommand("field", "a distance field of a world, as `voxfield field`");
  field->add_option("IN", in, "input .npy (read a slab per rank), .vox or .vfw")->required();
  field
      ->add_option("-o,--output", out,
                   "output .npy (every rank its slices) or .vdb (joined on rank 0)")
      ->required();
  field->add_option("--sites", sites, "also write nearest-site offsets, int16 a[x, y, z, 3]");
  field->add_option("--packed", packed,
                    "also write the dissertation's packed uint32 voxels to this .npy");
  field->add_option("--stats", stats, "timing and exchange figures as JSON");
  f.add_to(field);
  mpi_cli::add_read_options(field, f.read);
  FieldSettings fe;
  std::string edit_in, edit_script, edit_out, edit_stats, edit_save, edit_balance = "volume";
  std::string edit_mesh, edit_mesh_algorithm = "mc";
  CLI::App* edit = app.add_subcommand(
      "edit", "scripted edits with incremental exact updates, as `voxfield edit`");
  edit->add_option("IN", edit_in, "input .npy (read a slab per rank), .vox or .vfw")->required();
  edit->add_option("-e,--edits", edit_script,
                   "edit script, one JSON object per line (as voxfield edit)")
      ->required();
  edit->add_option("-o,--output", edit_out, "output .npy of the final field")->required();
  edit->add_option("--stats", edit_stats, "per-edit latency of the slowest rank, as JSON");
  edit->add_option("--save-world", edit_save,
                   "also write the edited world as one .vfw or .npy (every rank its slab)");
  edit->add_option("--balance", edit_balance,
                   "cut the slabs by volume (default), by content (the chunks holding air and "
                   "solid, counted in a first reading) or by the script's edits (what each will "
                   "recompute)")
      ->check(CLI::IsMember({"volume", "content", "edits"}));
  edit->add_option("--mesh", edit_mesh,
                   "also write the edited world's surface (.ply, .obj, .stl, .glb): the file "
                   "`voxfield mesh` writes for the edited world, every rank its slab's share");
  edit->add_option("--mesh-algorithm", edit_mesh_algorithm, "mc (default), sn or dc")
      ->check(
          CLI::IsMember({"mc", "sn", "dc", "marching-cubes", "surface-nets", "dual-contouring"}));
  fe.add_to(edit);
  mpi_cli::add_read_options(edit, fe.read);
  std::vector<int> dims;
  int spheres = 200, repeat = 3;
  FieldSettings fb;
  CLI::App* bench = app.add_subcommand("bench", "time the field of generated spheres");
  bench->add_option("--size", dims, "X,Y,Z")
      ->delimiter(',')
      ->expected(3)
      ->required()
      ->check(CLI::Range(1, 1 << 16));
  bench->add_option("--spheres", spheres, "random spheres in the world")
      ->check(CLI::Range(0, 1 << 20));
  bench->add_option("--repeat", repeat, "runs")->check(CLI::Range(1, 1000));
  fb.add_to(bench);
  mpi_cli::MeshSettings mesh_settings;
  CLI::App* mesh = mpi_cli::add_mesh_command(app, mesh_settings);
  mpi_cli::RenderSettings render_settings;
  CLI::App* render = mpi_cli::add_render_command(app, render_settings);
  int code = 0;
  try {
    app.parse(argc, argv);
    if (!memory_limit.empty())
      voxfield::set_default_memory_limit(voxfield::parse_byte_size(memory_limit, "--memory-limit"));
    if (field->parsed()) {
      code = run_field(comm, f, in, out, sites, packed, stats);
    } else if (edit->parsed()) {
      code = run_edit(comm, fe, edit_in, edit_script, edit_out, edit_stats, edit_save, edit_balance,
                      edit_mesh, edit_mesh_algorithm);
    } else if (mesh->parsed()) {
      code = mpi_cli::run_mesh(comm, mesh_settings);
    } else if (render->parsed()) {
      code = mpi_cli::run_render(comm, render_settings);
    } else {
      code = run_bench(comm, fb, dims, spheres, repeat);
    }
  } catch (const CLI::ParseError& e) {
    // Every rank parsed the same line: rank 0 alone speaks.
    if (rank == 0)
      code = app.exit(e);
    else
      code = e.get_exit_code() == 0 ? 0 : 2;
    if (code != 0) code = 2;
  } catch (const std::exception& e) {
    if (rank == 0) std::cerr << "voxfield-mpi: " << e.what() << "\n";
    code = 1;
  }
  MPI_Finalize();
  return code;
}

// voxfield-mpi mesh (mesh_command.h).
#include "mesh_command.h"

#include <cmath>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "rank_stats.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mpi.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"

namespace voxfield::mpi_cli {

CLI::App* add_mesh_command(CLI::App& app, MeshSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "mesh",
      "the iso-surface of a float .npy volume or the surface of a world, as `voxfield mesh` (each "
      "rank reads its planes)");
  cmd->add_option("IN", s.in,
                  "input float32/float64 .npy volume, or world (.vox, .vfw, .vdb, integer .npy: "
                  "its surface, through its exact signed field, as `voxfield mesh` meshes it)")
      ->required();
  cmd->add_option("-o,--output", s.out,
                  "output .ply, .obj, .stl or .glb (each rank writes its share)")
      ->required();
  cmd->add_option("--algorithm", s.algorithm,
                  "mc (marching cubes), sn (surface nets) or dc (dual contouring)")
      ->check(
          CLI::IsMember({"mc", "sn", "dc", "marching-cubes", "surface-nets", "dual-contouring"}));
  cmd->add_option("--iso", s.iso, "iso value (default 0)");
  cmd->add_option("--inside", s.inside, "which values are inside: below (default) or above iso")
      ->check(CLI::IsMember({"below", "above"}));
  cmd->add_option("--spacing", s.spacing, "sample spacing sx,sy,sz (a[x,y,z] at (x,y,z) * spacing)")
      ->delimiter(',')
      ->expected(3)
      ->check(CLI::PositiveNumber);
  cmd->add_option("--chunk", s.chunk,
                  "cells per chunk edge (2..256, default 32); ranks mesh whole layers of chunks")
      ->check(CLI::Range(2, 256));
  cmd->add_option("--threads", s.threads, "threads per rank (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--balance", s.balance,
                  "deal the chunk layers to the ranks by content (default: each rank about as many "
                  "crossed edges, read in a first pass) or by count")
      ->check(CLI::IsMember({"content", "count"}));
  cmd->add_option("--metric", s.metric,
                  "a world's field: euclidean (default), chebyshev or manhattan (at iso 0 the "
                  "vertices lie on the voxels' faces for every metric; the normals follow the "
                  "field)")
      ->check(CLI::IsMember({"euclidean", "chebyshev", "manhattan"}));
  add_read_options(cmd, s.read);
  cmd->add_option("--stats", s.stats, "counts, timings and exchange figures as JSON");
  return cmd;
}

int run_mesh(MPI_Comm comm, const MeshSettings& s) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  MeshOptions options;
  options.algorithm = parse_mesher(s.algorithm);
  options.iso = s.iso;
  options.inside_above = s.inside == "above";
  options.chunk_edge = s.chunk;
  (void)mesh_format_of(s.out);  // an unknown extension is refused before any work
  mpi::check_outputs(comm, {}, {s.out, s.stats}, {s.in});
  // Every rank reads the header: a float .npy is a volume; any other input is a world.
  const std::optional<NpyVolume> header = mpi::collectively(comm, [&] {
    std::optional<NpyVolume> h;
    if (lowercase_extension(s.in) == ".npy") h = read_npy_header(s.in);
    if (h && h->dtype != DType::kFloat32 && h->dtype != DType::kFloat64) h.reset();
    return h;
  });
  if (!header) return run_world_mesh(comm, s);
  if (s.metric)
    throw InvalidArgument("--metric is for worlds (meshed through their exact signed field); " +
                          s.in + " is a float volume, meshed as it is");
  if (s.read.by != "every" || !s.read.grid.empty())
    throw InvalidArgument("--read and --grid are for worlds; each rank reads its planes of " +
                          s.in);
  ScalarVolume frame{header->dims, nullptr};
  if (!s.spacing.empty()) frame.spacing_units = {s.spacing[0], s.spacing[1], s.spacing[2]};
  const double t0 = MPI_Wtime();
  // Planes [z0, z1) of the file as floats (a value past float's range refused, as voxfield mesh
  // refuses it).
  const auto read_planes = [&](int z0, int z1) {
    return mpi::collectively(comm, [&] {
      return z1 > z0 ? float_samples(read_npy_part(s.in, z0, z1), s.in) : std::vector<float>{};
    });
  };
  mpi::ExchangeStats ex;
  const mpi::MeshLayers layers = [&] {
    if (s.balance == "count")
      return mpi::collectively(
          comm, [&] { return mpi::partition_mesh_layers(header->dims, s.chunk, size); });
    // By content: a first pass over equal shares of the planes counts each layer's crossings.
    const int z0 = static_cast<int>(static_cast<std::int64_t>(header->dims.z) * rank / size);
    const int z1 = static_cast<int>(static_cast<std::int64_t>(header->dims.z) * (rank + 1) / size);
    const std::vector<double> weights = [&] {
      const std::vector<float> share = read_planes(z0, z1);
      return mpi::mesh_layer_weights(comm, header->dims, z0, z1, share.data(), options, &ex);
    }();
    return mpi::collectively(
        comm, [&] { return mpi::partition_mesh_layers(header->dims, s.chunk, size, weights); });
  }();
  std::vector<float> planes = [&] {
    const auto [z0, z1] = layers.planes(rank);
    return read_planes(z0, z1);
  }();
  const double load_ms = max_over(comm, (MPI_Wtime() - t0) * 1e3);
  MPI_Barrier(comm);  // the mesh's time starts together on every rank
  const double t1 = MPI_Wtime();
  // Each rank writes its share of the file; rank 0 stages it in the outputs' transaction, which
  // commits it with the stats once every rank has written.
  std::optional<FileTransaction> outputs;
  if (rank == 0) outputs.emplace();
  const mpi::MeshFileSummary mesh = [&] {
    // The planes go when the file is written (the mesh is made from them first; a rank's peak is
    // its planes, its chunks' parts and its share of the mesh, encoded or not).
    const std::vector<float> held = std::move(planes);
    return mpi::write_mesh_volume(comm, layers, frame, held.empty() ? nullptr : held.data(),
                                  options, s.out, !s.stats.empty(), &ex,
                                  outputs ? &*outputs : nullptr);
  }();
  return finish_mesh(
      comm, s, mesh, t1, ex, outputs,
      {{"load_ms_max", load_ms}, {"chunk_layers", layers.layers}, {"balance", s.balance}});
}

int finish_mesh(MPI_Comm comm, const MeshSettings& s, const mpi::MeshFileSummary& mesh,
                double t_mesh, const mpi::ExchangeStats& ex,
                std::optional<FileTransaction>& outputs, nlohmann::json extra) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const Mesher algorithm = parse_mesher(s.algorithm);
  // The census (--stats only) is timed apart: "ms" is the mesh made and written.
  const double census_ms = max_over(comm, mesh.census_ms);
  const double mesh_ms = max_over(comm, (MPI_Wtime() - t_mesh) * 1e3 - mesh.census_ms);
  nlohmann::json exchange = exchange_json(comm, ex);
  const double peak_mb = max_over(comm, static_cast<double>(peak_rss_bytes()) / 1048576.0);
  mpi::collectively(comm, [&] {
    if (rank != 0) return;
    if (!s.stats.empty()) {
      const MeshStats& st = *mesh.census;
      nlohmann::json j{{"input", s.in},
                       {"output", s.out},
                       {"algorithm", mesher_name(algorithm)},
                       {"ms", mesh_ms},
                       {"census_ms_max", census_ms},
                       {"ranks", size},
                       {"threads", max_threads()},
                       {"chunk_edge", s.chunk},
                       {"vertices", st.vertices},
                       {"triangles", st.triangles},
                       {"watertight", st.watertight()},
                       {"boundary_edges", st.boundary_edges},
                       {"euler_characteristic", st.euler_characteristic},
                       {"peak_rss_mb_max", peak_mb}};
      j.update(extra);
      j["exchange"] = exchange;
      outputs->stage(s.stats, j.dump(2) + "\n");
    }
    outputs->commit();
  });
  if (rank == 0)
    std::cerr << "voxfield-mpi: wrote " << s.out << " (" << mesh.triangles << " triangles, "
              << mesh.vertices << " vertices, " << mesher_name(algorithm) << ", " << size
              << " ranks, " << std::lround(mesh_ms) << " ms)\n";
  return 0;
}

}  // namespace voxfield::mpi_cli

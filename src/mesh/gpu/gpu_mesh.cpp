// voxfield GPU backend — marching cubes with a HistoPyramid (gpu_mesh.h): the samples and the case
// table uploaded through the context's staging buffer, then classify, one reduction per pyramid
// level, the indirect arguments and the traversal recorded in one command buffer (every barrier
// derived by the recorder), one submit; the triangles are read back in a second.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "../cube_cases.h"
#include "../mesh_internal.h"
#include "../terrain_store.h"
#include "gpu/recorder.h"
#include "histopyramid.h"
#include "mesh_shaders.h"
#include "shaders/layout.h"
#include "voxfield/detail/assert.h"
#include "voxfield/error.h"
#include "voxfield/gpu_mesh.h"
#include "voxfield/limits.h"

namespace voxfield::gpu {

namespace L = layout;

namespace {

using mc::kUsage;
constexpr std::uint64_t kTriangleBytes = 3 * L::VF_MC_VERTEX_FLOATS * sizeof(float);

// The field as it travels: the samples packed in their width, the frame and the inside rule.
struct Field {
  Vec3i n;
  std::vector<std::uint32_t> words;
  int width = L::VF_MC_F32;
  double step = 0;
  std::array<double, 3> origin{}, spacing{};
  float iso = 0;
  bool negate = false;
};

}  // namespace

namespace mc {

std::vector<std::uint32_t> case_table() {
  using detail::mesh::CubeCase;
  using detail::mesh::CubeCases;
  const CubeCases& t = CubeCases::get();
  std::vector<std::uint32_t> out(L::VF_MC_CASES, 0);
  std::uint32_t next = 0;
  for (unsigned inside = 0; inside < 256; ++inside) {
    out[L::VF_MC_OFFSETS + inside] = next;
    out[L::VF_MC_AMBIGUOUS + inside] = t.ambiguous_faces(inside);
    const unsigned variants = 1u << std::popcount(t.ambiguous_faces(inside));
    for (unsigned joined = 0; joined < variants; ++joined) {
      const CubeCase& c = t.lookup(inside, joined);
      std::array<std::uint32_t, L::VF_MC_CASE_WORDS> r{};
      r[0] = c.triangle_count;
      for (int i = 0; i < 36; ++i)
        r[1 + static_cast<std::size_t>(i)] = c.edges[static_cast<std::size_t>(i)];
      r[37] = c.centre_count;
      r[38] = c.centre_sizes[0];
      r[39] = c.centre_sizes[1];
      for (std::size_t k = 0; k < 2; ++k)
        for (std::size_t i = 0; i < 12; ++i) r[40 + 12 * k + i] = c.centre_edges[k][i];
      out.insert(out.end(), r.begin(), r.end());
      ++next;
    }
  }
  for (int face = 0; face < 6; ++face) {
    const auto corners = CubeCases::face_corners(face);
    for (std::size_t k = 0; k < 4; ++k)
      out[static_cast<std::size_t>(L::VF_MC_FACES + 4 * face) + k] = corners[k];
  }
  const auto& edges = detail::mesh::cube_edges();
  for (std::size_t e = 0; e < 12; ++e) {
    out[L::VF_MC_EDGES + 2 * e] = edges[e].from;
    out[L::VF_MC_EDGES + 2 * e + 1] = edges[e].axis;
  }
  return out;
}

std::vector<L::ivec4> pyramid_levels(Vec3i cells, Pyramid kind, std::uint64_t& total) {
  std::vector<L::ivec4> levels;
  std::int64_t offset = 0;
  if (kind == Pyramid::kFourToOne) {
    std::int64_t count = static_cast<std::int64_t>(cells.x) * cells.y * cells.z;
    for (;;) {
      levels.push_back({static_cast<std::int32_t>(offset), static_cast<std::int32_t>(count), 1, 1});
      offset += count;
      if (count == 1) break;
      count = (count + 3) / 4;
    }
  } else {
    Vec3i d = cells;
    for (;;) {
      levels.push_back({static_cast<std::int32_t>(offset), d.x, d.y, d.z});
      offset += static_cast<std::int64_t>(d.x) * d.y * d.z;
      if (d.x == 1 && d.y == 1 && d.z == 1) break;
      d = {(d.x + 1) / 2, (d.y + 1) / 2, (d.z + 1) / 2};
    }
  }
  total = static_cast<std::uint64_t>(offset);
  return levels;
}

void check_lattice(Vec3i n, const std::array<double, 3>& origin,
                   const std::array<double, 3>& spacing) {
  // mesh_volume's checks of the lattice and its frame (sizes, spacing, origin and far corner),
  // then the GPU's own 32-bit limit on cells.
  ScalarVolume frame;
  frame.size = n;
  frame.origin_units = origin;
  frame.spacing_units = spacing;
  const std::function<void(const Box3i&, float*)> no_samples;  // only the frame is checked
  detail::mesh::checked_lattice(frame, MeshOptions{}, false, &no_samples);
  const std::uint64_t cells = static_cast<std::uint64_t>(n.x - 1) * (n.y - 1) * (n.z - 1);
  if (cells > static_cast<std::uint64_t>(INT32_MAX))
    throw ResourceLimitError("marching cubes on the GPU: " + to_string(n) +
                             " samples are more cells than 32-bit indices count");
}

void record_pyramid(Recorder& rec, Context::Impl& c, Recorder::Buffers buffers, L::MeshParams& p,
                    const std::vector<L::ivec4>& levels) {
  const int classify = rec.begin_pass();
  rec.dispatch_strided(c.kernel(shaders::mesh_classify()), buffers, p,
                       static_cast<std::uint64_t>(p.cells.x) * p.cells.y * p.cells.z);
  rec.end_pass(classify, "classify");
  const int reduce = rec.begin_pass();
  for (std::size_t l = 1; l < levels.size(); ++l) {
    p.pass.x = static_cast<std::int32_t>(l);
    const L::ivec4& lv = levels[l];
    rec.dispatch_strided(c.kernel(shaders::mesh_reduce()), buffers, p,
                         static_cast<std::uint64_t>(lv.y) * lv.z * lv.w);
  }
  rec.end_pass(reduce, "HistoPyramid");
}

}  // namespace mc

namespace {

using mc::case_table;
using mc::check_lattice;
using mc::pyramid_levels;

Mesh run(Context& context, const Field& f, const GpuMeshOptions& g, GpuMeshStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  Context::Impl& c = context.impl();
  c.require_device();
  if (!c.float64)
    throw GpuUnavailable(
        "Vulkan: marching cubes on the GPU needs the device feature shaderFloat64 (double "
        "precision in shaders, to give the CPU's triangles bit for bit), which " +
        c.info.name + " does not have");
  const Counters before = c.counters;
  const Vec3i cells{f.n.x - 1, f.n.y - 1, f.n.z - 1};
  const std::uint64_t cell_count = static_cast<std::uint64_t>(cells.x) * cells.y * cells.z;
  std::uint64_t pyramid_elements = 0;
  const std::vector<L::ivec4> levels = pyramid_levels(cells, g.pyramid, pyramid_elements);
  const VkDeviceSize range = c.limits.maxStorageBufferRange;
  const std::uint64_t sample_bytes = f.words.size() * 4;
  for (const auto& [what, bytes] : {std::pair<const char*, std::uint64_t>{"samples", sample_bytes},
                                    {"HistoPyramid", pyramid_elements * 4},
                                    {"cell cases", cell_count * 4}})
    if (bytes > range)
      throw ResourceLimitError("marching cubes on the GPU: the " + std::string(what) + " of " +
                               to_string(f.n) + " samples take " + std::to_string(bytes) +
                               " bytes, more than one storage buffer of " + c.info.name +
                               " holds (" + std::to_string(range) + ")");
  // The most triangles one storage buffer holds (or the caller allows): the vertex buffer is
  // allocated at the surface's own count, once the pyramid has counted it.
  const std::uint64_t capacity =
      g.max_triangles > 0 ? g.max_triangles : std::max<std::uint64_t>(1, range / kTriangleBytes);
  // (Vertex elements are 3 x sample + axis in 32 bits.)
  if (3 * static_cast<std::uint64_t>(f.n.x) * f.n.y * f.n.z >
      std::numeric_limits<std::uint32_t>::max())
    throw ResourceLimitError("marching cubes on the GPU: " + to_string(f.n) +
                             " samples are more than its 32-bit vertex elements count");
  if (capacity * kTriangleBytes > range || capacity > static_cast<std::uint64_t>(INT32_MAX))
    throw InvalidArgument("marching cubes on the GPU: " + std::to_string(capacity) +
                          " triangles do not fit one storage buffer of " + c.info.name);
  const std::vector<std::uint32_t> table = case_table();
  std::array<double, 8> frame{f.origin[0],  f.origin[1],  f.origin[2],  f.step,
                              f.spacing[0], f.spacing[1], f.spacing[2], 0};

  Buffer samples(c, std::max<std::uint64_t>(sample_bytes, 16), kUsage, false);
  Buffer tables(c, table.size() * 4, kUsage, false);
  Buffer frame_buf(c, sizeof frame, kUsage, false);
  Buffer level_buf(c, levels.size() * sizeof(L::ivec4), kUsage, false);
  Buffer pyramid(c, pyramid_elements * 4, kUsage, false);
  Buffer cases(c, cell_count * 4, kUsage, false);
  Buffer args(c, 16, kUsage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, true);
  Buffer vertices, keys;  // sized by the count (submit 2)
  Buffer unused_vertices(c, 16, kUsage, false), unused_keys(c, 16, kUsage, false);
  L::MeshParams p{};
  // Submit 1: one upload through the staging buffer (the samples, the table, the frame and the
  // levels), classify, the pyramid's levels and the traversal's arguments; the host reads the
  // count from the arguments (host-visible).
  {
    const std::uint64_t parts[4] = {sample_bytes, table.size() * 4, sizeof frame,
                                    levels.size() * sizeof(L::ivec4)};
    const void* data[4] = {f.words.data(), table.data(), frame.data(), levels.data()};
    Buffer* dst[4] = {&samples, &tables, &frame_buf, &level_buf};
    std::uint64_t total = 0;
    for (std::uint64_t b : parts) total += (b + 15) / 16 * 16;
    Buffer& staging = c.upload_buffer(total);
    Recorder rec(c);
    std::uint64_t at = 0;
    for (int i = 0; i < 4; ++i) {
      if (parts[i] == 0) continue;
      std::memcpy(static_cast<std::uint8_t*>(staging.mapped()) + at, data[i], parts[i]);
      rec.copy(staging, at, *dst[i], 0, parts[i]);
      at += (parts[i] + 15) / 16 * 16;
    }
    p.size = {f.n.x, f.n.y, f.n.z, f.width};
    p.cells = {cells.x, cells.y, cells.z,
               g.pyramid == Pyramid::kFourToOne ? L::VF_MC_PYRAMID_4 : L::VF_MC_PYRAMID_8};
    // Dispatches stay within the device's x limit of workgroups; the passes stride over the rest.
    const std::uint32_t max_groups = c.limits.maxComputeWorkGroupCount[0];
    p.pass = {0, static_cast<std::int32_t>(levels.size()), static_cast<std::int32_t>(capacity),
              static_cast<std::int32_t>(std::min<std::uint32_t>(max_groups, INT32_MAX))};

    p.iso = f.iso;
    p.negate = f.negate ? 1u : 0u;
    Binding all[9] = {&samples, &tables,          &frame_buf, &level_buf,  &pyramid,
                      &cases,   &unused_vertices, &args,      &unused_keys};
    const Recorder::Buffers list(all, 9);
    mc::record_pyramid(rec, c, list, p, levels);
    rec.dispatch(c.kernel(shaders::mesh_args()), list, p, 1);
    rec.submit();
  }
  std::uint32_t counts[4];
  std::memcpy(counts, args.mapped(), sizeof counts);
  const std::uint64_t triangles = counts[3];
  if (triangles > capacity)
    throw ResourceLimitError("marching cubes on the GPU: the surface has " +
                             std::to_string(triangles) + " triangles; the vertex buffer holds " +
                             std::to_string(capacity) + " (72 bytes each, and 24 of keys; " +
                             (g.max_triangles > 0 ? std::string("GpuMeshOptions::max_triangles")
                                                  : "one storage buffer of " + c.info.name) +
                             ")");
  Mesh mesh;
  if (triangles > 0) {
    // Submit 2: the traversal into buffers of the surface's size, and the triangles and their
    // vertices' elements read back; vertices of one element are one vertex (the GPU computed
    // them bit for bit alike, as the CPU's chunks do).
    const std::uint64_t vertex_bytes = triangles * kTriangleBytes, key_bytes = triangles * 3 * 8;
    require_memory(mul_sat(triangles, 3 * (24 + 8 + 4) + 96), 0, "marching cubes on the GPU",
                   std::to_string(triangles) + " triangles read back and shared");
    vertices = Buffer(c, vertex_bytes, kUsage, false);
    keys = Buffer(c, key_bytes, kUsage, false);
    Buffer& readback = c.readback_buffer(vertex_bytes + key_bytes);
    Recorder rec(c);
    Binding all[9] = {&samples, &tables,   &frame_buf, &level_buf, &pyramid,
                      &cases,   &vertices, &args,      &keys};
    const int traverse = rec.begin_pass();
    rec.dispatch_indirect(c.kernel(shaders::mesh_traverse()), Recorder::Buffers(all, 9), &p,
                          sizeof p, args, 0);
    rec.end_pass(traverse, "traverse");
    rec.copy(vertices, 0, readback, 0, vertex_bytes);
    rec.copy(keys, 0, readback, vertex_bytes, key_bytes);
    rec.submit();
    const float* v = static_cast<const float*>(readback.mapped());
    const auto* k = reinterpret_cast<const std::uint32_t*>(
        static_cast<const std::uint8_t*>(readback.mapped()) + vertex_bytes);
    std::unordered_map<std::uint64_t, std::uint32_t> shared;
    shared.reserve(static_cast<std::size_t>(triangles * 3 / 2));
    mesh.indices.resize(3 * triangles);
    for (std::size_t i = 0; i < 3 * triangles; ++i, v += L::VF_MC_VERTEX_FLOATS) {
      const std::uint64_t element = static_cast<std::uint64_t>(k[2 * i + 1]) << 32 | k[2 * i];
      const auto [it, fresh] =
          shared.emplace(element, static_cast<std::uint32_t>(mesh.positions.size()));
      if (fresh) {
        mesh.positions.push_back({v[0], v[1], v[2]});
        mesh.normals.push_back({v[3], v[4], v[5]});
      }
      // Every copy of a vertex is computed from the same samples by the same arithmetic: equal.
      VOXFIELD_ASSERT(std::memcmp(mesh.positions[it->second].data(), v, 12) == 0 &&
                      std::memcmp(mesh.normals[it->second].data(), v + 3, 12) == 0);
      mesh.indices[i] = it->second;
    }
  }
  if (stats) {
    const Counters& now = c.counters;
    stats->dispatches = now.dispatches - before.dispatches;
    stats->submits = now.submits - before.submits;
    stats->fence_waits = now.fence_waits - before.fence_waits;
    stats->bytes_uploaded = now.bytes_uploaded - before.bytes_uploaded;
    stats->bytes_downloaded = now.bytes_downloaded - before.bytes_downloaded;
    stats->samples_bytes = static_cast<std::int64_t>(sample_bytes);
    stats->pyramid_levels = static_cast<int>(levels.size());
    stats->triangles = triangles;
    stats->field_width = f.width == L::VF_MC_F32 ? "f32" : f.width == L::VF_MC_I16 ? "i16" : "i8";
    stats->ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return mesh;
}

}  // namespace

Mesh marching_cubes(Context& context, const ScalarVolume& volume, const MeshOptions& options,
                    const GpuMeshOptions& gpu, GpuMeshStats* stats) {
  if (options.gradient || options.value)
    throw InvalidArgument(
        "marching cubes on the GPU: MeshOptions::gradient and ::value are C++ functions, "
        "evaluated on the CPU only (use mesh_volume)");
  if (!volume.values) throw InvalidArgument("mesh: the volume has no samples");
  if (!(std::abs(options.iso) <= std::numeric_limits<float>::max()))
    throw InvalidArgument("mesh: iso must be a finite float");
  check_lattice(volume.size, volume.origin_units, volume.spacing_units);
  Field f;
  f.n = volume.size;
  f.origin = volume.origin_units;
  f.spacing = volume.spacing_units;
  f.iso = static_cast<float>(options.iso);
  f.negate = options.inside_above;
  const std::uint64_t count = static_cast<std::uint64_t>(volume.count());
  require_memory(count * 4, 0, "marching cubes on the GPU", "the samples' upload");
  f.words.resize(count);
  for (std::uint64_t i = 0; i < count; ++i) {
    if (!std::isfinite(volume.values[i]))
      throw InvalidArgument("mesh: sample " + std::to_string(i) + " (x fastest) is " +
                            (std::isnan(volume.values[i]) ? "NaN" : "infinite"));
    f.words[i] = std::bit_cast<std::uint32_t>(volume.values[i]);
  }
  return run(context, f, gpu, stats);
}

Mesh marching_cubes(Context& context, const TerrainField& terrain, const GpuMeshOptions& gpu,
                    GpuMeshStats* stats) {
  const TerrainOptions& o = terrain.options();
  check_lattice(o.samples, o.origin_units, {o.spacing_units, o.spacing_units, o.spacing_units});
  Field f;
  f.n = o.samples;
  f.origin = o.origin_units;
  f.spacing = {o.spacing_units, o.spacing_units, o.spacing_units};
  // The stored codes in their own width (TerrainField::read_codes: no decode and re-encode),
  // packed four (i8) or two (i16) per word as the device reads them. They are negative inside
  // whatever the field's convention; a positive-inside field is meshed from its decoded values
  // (inside above 0, s = 0 - v), so the device negates codes as it decodes to give the CPU's
  // signed zeros: the codes are uploaded negated — exactly, as their range is symmetric.
  const detail::terrain::Codec codec(o.storage, terrain.max_distance_units());
  f.step = codec.step;
  f.width = o.storage == TerrainStorage::kI8    ? L::VF_MC_I8
            : o.storage == TerrainStorage::kI16 ? L::VF_MC_I16
                                                : L::VF_MC_F32;
  const std::uint64_t count = static_cast<std::uint64_t>(Box3i::from_size(o.samples).volume());
  const int bytes = codec.bytes;
  require_memory((count * static_cast<std::uint64_t>(bytes) + 3) / 4 * 4, 0,
                 "marching cubes on the GPU", "the terrain's samples' upload");
  f.words.assign((count * static_cast<std::uint64_t>(bytes) + 3) / 4, 0);
  terrain.read_codes(Box3i::from_size(o.samples), f.words.data());
  f.negate = o.positive_inside;
  if (o.positive_inside) {
    auto* raw = reinterpret_cast<std::uint8_t*>(f.words.data());
    for (std::uint64_t i = 0; i < count; ++i) {
      std::uint32_t code = 0;
      std::memcpy(&code, raw + i * bytes, static_cast<std::size_t>(bytes));
      const std::uint32_t negated = codec.encode(-static_cast<double>(codec.decode(code)));
      std::memcpy(raw + i * bytes, &negated, static_cast<std::size_t>(bytes));
    }
  }
  return run(context, f, gpu, stats);
}

}  // namespace voxfield::gpu

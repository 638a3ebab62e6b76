// voxfield GPU backend — the vector-field passes of one volume (vector_engine.h): uploads through a
// reused staging buffer, then one dispatch per pass, every barrier derived by the recorder.
#include "vector_engine.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "../texel_codec.h"
#include "../vector_internal.h"
#include "gpu/split_buffer.h"
#include "shaders/layout.h"
#include "vectors_shaders.h"
#include "voxfield/error.h"

namespace voxfield::gpu {

namespace L = layout;
namespace vx = detail::vectors;

int vector_texel_bytes(VectorStorage storage) {
  return storage == VectorStorage::kRgba8 ? 4 : storage == VectorStorage::kRgba16f ? 8 : 16;
}

namespace {

// Splatting's bins may take this much before every voxel tests every source instead (the same
// texels: the bins only skip sources that cannot reach a voxel).
constexpr std::uint64_t kMaxTileBytes = 64ull << 20;

struct Dvec4 {
  double x, y, z, w;
};
Dvec4 d4(Vec3d v, double w = 0) {
  return {v.x, v.y, v.z, w};
}

// std430 mirror of vectors_seed.comp's SeedSpan.
struct SeedRecord {
  double t0, t1;
  std::uint32_t first, samples;
  std::uint32_t pad[2];
};
static_assert(sizeof(SeedRecord) == 32);

std::uint64_t align16(std::uint64_t n) {
  return (n + 15) / 16 * 16;
}

// Splatting's bins in CSR form: tile_count + 1 offsets, then per tile the sources (ascending, so
// ties go to the lower index) whose index box meets it — counted, then filled. False, with `out`
// untouched, when they would take more than `max_bytes`.
bool bin_sources(const VectorVolume& volume, std::span<const VectorSource> sources, Vec3i tiles,
                 std::uint64_t max_bytes, std::vector<std::uint32_t>& out) {
  const int edge = L::VF_VECTORS_TILE;
  const std::size_t n_tiles = static_cast<std::size_t>(tiles.x) * tiles.y * tiles.z;
  std::vector<vx::IndexBox> boxes(sources.size());
  std::uint64_t entries = 0;
  for (std::size_t s = 0; s < sources.size(); ++s) {
    boxes[s] = vx::index_box(volume, sources[s]);
    if (boxes[s].empty()) continue;
    std::uint64_t covered = 1;
    for (int a = 0; a < 3; ++a)
      covered *= static_cast<std::uint64_t>(boxes[s].hi[a] / edge - boxes[s].lo[a] / edge + 1);
    entries += covered;
  }
  if ((n_tiles + 1 + entries) * 4 > max_bytes) return false;
  auto for_tiles = [&](const vx::IndexBox& b, auto&& f) {
    for (int z = b.lo[2] / edge; z <= b.hi[2] / edge; ++z)
      for (int y = b.lo[1] / edge; y <= b.hi[1] / edge; ++y)
        for (int x = b.lo[0] / edge; x <= b.hi[0] / edge; ++x)
          f(static_cast<std::size_t>(x) +
            static_cast<std::size_t>(tiles.x) * (y + static_cast<std::size_t>(tiles.y) * z));
  };
  std::vector<std::uint32_t> counts(n_tiles + 1, 0);
  for (const vx::IndexBox& b : boxes)
    if (!b.empty()) for_tiles(b, [&](std::size_t tile) { ++counts[tile + 1]; });
  out.assign(n_tiles + 1 + entries, 0);
  out[0] = static_cast<std::uint32_t>(n_tiles + 1);
  for (std::size_t i = 0; i < n_tiles; ++i) out[i + 1] = out[i] + counts[i + 1];
  std::vector<std::uint32_t> fill(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n_tiles));
  for (std::size_t s = 0; s < sources.size(); ++s)
    if (!boxes[s].empty())
      for_tiles(boxes[s],
                [&](std::size_t tile) { out[fill[tile]++] = static_cast<std::uint32_t>(s); });
  return true;
}

}  // namespace

// The bytes one call uploads, by destination.
struct VectorEngine::Upload {
  std::vector<Dvec4> centres;  // only on the first call
  std::vector<float> decode;   // only on the first call
  std::vector<Dvec4> segments;
  std::vector<std::uint32_t> tiles;
  std::vector<SeedRecord> seeds;
  std::uint32_t samples = 0;
};

VectorEngine::VectorEngine(Context::Impl& c, const VectorVolume& volume, VectorStorage storage)
    : c_(c), volume_(volume), storage_(storage), sets_(c) {
  volume_.validate();
  if (!c.float64)
    throw GpuUnavailable(
        "Vulkan: the vector-field passes need the device feature shaderFloat64 (double precision "
        "in shaders, to match the CPU bit for bit), which " +
        c.info.name + " does not have");
  texture_bytes_ = static_cast<std::uint64_t>(volume_.voxel_count()) * vector_texel_bytes(storage_);
  if (texture_bytes_ > c.limits.maxStorageBufferRange)
    throw InvalidArgument(
        "vector field " + to_string(volume_.resolution) + " in " + vector_storage_name(storage_) +
        " takes " + std::to_string(texture_bytes_) + " bytes, more than one storage buffer of " +
        c.info.name + " holds (" + std::to_string(c.limits.maxStorageBufferRange) +
        "); use a smaller resolution or storage");
  unused_read_ = Buffer(c_, 16, kVectorBufferUsage, false);
  unused_write_ = Buffer(c_, 16, kVectorBufferUsage, false);
}

Buffer VectorEngine::make_texture() const {
  return Buffer(c_, texture_bytes_, kVectorBufferUsage, false);
}

Buffer& VectorEngine::grow(Buffer& b, VkDeviceSize bytes, bool host_visible) {
  if (b.handle() != VK_NULL_HANDLE && b.size() >= bytes) return b;
  // A replaced buffer may still be named by sets bound earlier in the command buffer being
  // recorded (a step before a picture in one frame): it is retired, alive, until settle().
  if (b.handle() != VK_NULL_HANDLE) retired_.push_back(std::move(b));
  b = Buffer(c_, std::max<VkDeviceSize>(bytes, 64), kVectorBufferUsage, host_visible);
  return b;
}

void VectorEngine::settle() {
  if (retired_.empty()) return;
  // Every earlier command has finished (record()'s precondition): the sets naming retired buffers
  // are recycled with all others before the buffers go, so no new buffer can reuse a handle a
  // cached set still names.
  sets_.reset();
  retired_.clear();
}

void VectorEngine::stage(Recorder& rec, const Upload& up, VectorGpuStats& stats) {
  struct Part {
    const void* data;
    std::uint64_t bytes;
    Buffer* dst;
  };
  std::vector<Part> parts;
  auto add = [&](const auto& v, Buffer& dst) {
    if (v.empty()) return;
    const std::uint64_t bytes = v.size() * sizeof(v[0]);
    grow(dst, bytes, false);
    parts.push_back({v.data(), bytes, &dst});
  };
  add(up.centres, centres_);
  add(up.decode, decode_);
  add(up.segments, segments_);
  add(up.tiles, tiles_);
  add(up.seeds, seeds_);
  std::uint64_t total = 0;
  for (const Part& p : parts) total += align16(p.bytes);
  if (total == 0) return;
  grow(staging_, total, true);
  std::vector<VkBufferCopy> regions(parts.size());
  std::vector<Recorder::Copy> copies;
  std::uint64_t at = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    std::memcpy(static_cast<std::uint8_t*>(staging_.mapped()) + at, parts[i].data, parts[i].bytes);
    regions[i] = {at, 0, parts[i].bytes};
    at += align16(parts[i].bytes);
  }
  for (std::size_t i = 0; i < parts.size(); ++i)
    rec.copy(staging_, *parts[i].dst, std::span<const VkBufferCopy>(&regions[i], 1));
  stats.bytes_uploaded += static_cast<std::int64_t>(total);  // the context's counters: the recorder
}

void VectorEngine::record(Recorder& rec, std::span<const VectorSource> sources,
                          const VectorOptions& options, const Targets& t, VectorGpuStats& stats) {
  validate_sources(sources);
  if (sources.size() > static_cast<std::size_t>(INT32_MAX))
    throw InvalidArgument("vector field: more than 2^31 - 1 sources");
  settle();
  const Vec3i n = volume_.resolution;
  const int count = static_cast<int>(sources.size());
  Upload up;
  if (!uploaded_tables_) {
    const vx::CentreTables tables(volume_);
    up.centres.push_back(d4(tables.centre));
    for (int a = 0; a < 3; ++a)
      up.centres.push_back(
          d4({volume_.rotation[0][a], volume_.rotation[1][a], volume_.rotation[2][a]}));
    up.centres.push_back(d4(volume_.size));
    for (const std::vector<Vec3d>* axis : {&tables.x, &tables.y, &tables.z})
      for (const Vec3d& o : *axis) up.centres.push_back(d4(o));
    const vx::Rgba8Tables& dec = vx::rgba8_tables();
    up.decode.assign(dec.direction.begin(), dec.direction.end());
    up.decode.insert(up.decode.end(), dec.strength.begin(), dec.strength.end());
  }
  const std::vector<vx::Segment> segments = vx::segments_of(sources);
  for (const vx::Segment& s : segments) {
    up.segments.push_back(d4(s.a, s.radius));
    up.segments.push_back(d4(s.ab, s.ab2));
  }
  const bool jfa =
      options.algorithm != VectorAlgorithm::kBrute && options.algorithm != VectorAlgorithm::kSplat;
  std::uint32_t search = jfa ? L::VF_VECTORS_WINNERS : L::VF_VECTORS_BRUTE;
  const Vec3i tiles{(n.x + L::VF_VECTORS_TILE - 1) / L::VF_VECTORS_TILE,
                    (n.y + L::VF_VECTORS_TILE - 1) / L::VF_VECTORS_TILE,
                    (n.z + L::VF_VECTORS_TILE - 1) / L::VF_VECTORS_TILE};
  if (options.algorithm == VectorAlgorithm::kSplat) {
    const std::uint64_t max_bytes =
        std::min<std::uint64_t>(kMaxTileBytes, c_.limits.maxStorageBufferRange);
    if (bin_sources(volume_, sources, tiles, max_bytes, up.tiles)) {
      search = L::VF_VECTORS_SPLAT;
      stats.tile_entries =
          static_cast<std::int64_t>(up.tiles.size() - up.tiles[0]);  // past the offsets
    } else {
      stats.splat_as_brute = true;
    }
  }
  if (jfa) {
    std::uint64_t total = 0;
    for (std::size_t s = 0; s < sources.size(); ++s) {
      const vx::SeedSpan span = vx::seed_span(volume_, sources[s], segments[s]);
      up.seeds.push_back({span.t0,
                          span.t1,
                          static_cast<std::uint32_t>(total),
                          static_cast<std::uint32_t>(span.samples),
                          {0, 0}});
      if (span.samples >= 0) total += static_cast<std::uint64_t>(span.samples) + 1;
      if (total > static_cast<std::uint64_t>(INT32_MAX))
        throw InvalidArgument(
            "vector field (jump flooding): the sources' seeds exceed 2^31 samples");
    }
    up.samples = static_cast<std::uint32_t>(total);
  }
  const bool need_winners = jfa || t.want_winners;
  if (need_winners) {
    const VkDeviceSize bytes = static_cast<VkDeviceSize>(volume_.voxel_count()) * 4;
    grow(winners_a_, bytes, false);
    if (jfa) grow(winners_b_, bytes, false);
  }
  stage(rec, up, stats);
  uploaded_tables_ = true;

  L::VectorParams p{};
  p.size = {n.x, n.y, n.z, count};
  p.tables = {L::VF_VECTORS_TABLES, L::VF_VECTORS_TABLES + n.x, L::VF_VECTORS_TABLES + n.x + n.y,
              0};
  p.tiles = {tiles.x, tiles.y, tiles.z, 0};
  p.rule = options.rule == VectorRule::kStrongest ? 0u : 1u;
  p.storage = static_cast<std::uint32_t>(storage_);
  p.decay = t.decay;
  Buffer* segs = count > 0 ? &segments_ : &unused_read_;
  Buffer* tile_buf = search == L::VF_VECTORS_SPLAT ? &tiles_ : &unused_read_;
  auto list = [&](Buffer* seeds, Buffer* in, Buffer* out) {
    return std::array<Binding, 10>{segs,
                                   &centres_,
                                   tile_buf,
                                   seeds,
                                   in,
                                   out,
                                   &decode_,
                                   t.current,
                                   t.previous ? t.previous : &unused_read_,
                                   t.next ? t.next : &unused_write_};
  };
  const std::uint64_t voxels = static_cast<std::uint64_t>(volume_.voxel_count());
  Buffer* in = &unused_read_;
  Buffer* out = &unused_write_;
  if (jfa) {
    const int ticket = rec.begin_pass();
    rec.fill(winners_a_, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);  // -1: no source yet
    if (up.samples > 0) {
      L::VectorParams seed = p;
      seed.pass = {static_cast<int>(up.samples), 0, 0, 0};
      const auto b = list(&seeds_, &winners_a_, &unused_write_);
      rec.dispatch_strided(c_.kernel(shaders::vectors_seed()), Recorder::Buffers(b), seed,
                           up.samples);
      ++stats.dispatches;
    }
    rec.end_pass(ticket, "seed");
    const int flood = rec.begin_pass();
    Buffer* a = &winners_a_;
    Buffer* b = &winners_b_;
    for (int step : vx::jfa_steps(volume_, options.algorithm == VectorAlgorithm::kJfa        ? 0
                                           : options.algorithm == VectorAlgorithm::kJfaPlus1 ? 1
                                                                                             : 2)) {
      L::VectorParams f = p;
      f.pass = {step, 0, 0, 0};
      const auto bufs = list(&unused_read_, a, b);
      rec.dispatch_strided(c_.kernel(shaders::vectors_flood()), Recorder::Buffers(bufs), f, voxels);
      std::swap(a, b);
      ++stats.dispatches;
      ++stats.flood_passes;
    }
    rec.end_pass(flood, "flood");
    in = a;
    winners_ = a;
  } else if (t.want_winners) {
    p.flags |= L::VF_VECTORS_WRITE_WINNERS;
    out = &winners_a_;
    winners_ = &winners_a_;
  }
  p.search = search;
  const int ticket = rec.begin_pass();
  const auto bufs = list(&unused_read_, in, out);
  const bool step = t.previous != nullptr;
  rec.dispatch_strided(c_.kernel(step ? shaders::vectors_step() : shaders::vectors_generate()),
                       Recorder::Buffers(bufs), p, voxels);
  ++stats.dispatches;
  rec.end_pass(ticket, step ? "step" : "generate");
}

Buffer& VectorEngine::record_view(Recorder& rec, Buffer& texels, const VectorViewOptions& view,
                                  bool bgra) {
  const VectorVolume& v = volume_;
  // The camera as visualise.cpp places it, in doubles, handed over as floats.
  const vx::ViewCamera cam = vx::view_camera(v, view);
  const Vec3d eye = cam.eye, forward = cam.forward, right = cam.right, true_up = cam.up;
  const double tan_half = cam.tan_half, aspect = cam.aspect, step = cam.step;
  // Pixel (x, y)'s ray: forward + right sx + up sy with sx, sy affine in x and y.
  const double sx0 = (1.0 / view.width - 1.0) * tan_half * aspect;
  const double sy0 = (1.0 - 1.0 / view.height) * tan_half;
  auto f4 = [](Vec3d a, double w = 0) {
    return L::vec4f{static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z),
                    static_cast<float>(w)};
  };
  L::VectorViewParams params{};
  params.centre = f4(v.centre);
  params.size = f4(v.size);
  params.axis_x = f4({v.rotation[0][0], v.rotation[1][0], v.rotation[2][0]});
  params.axis_y = f4({v.rotation[0][1], v.rotation[1][1], v.rotation[2][1]});
  params.axis_z = f4({v.rotation[0][2], v.rotation[1][2], v.rotation[2][2]});
  params.resolution = {v.resolution.x, v.resolution.y, v.resolution.z, static_cast<int>(storage_)};
  params.eye = f4(eye);
  params.dir00 = f4(forward + right * sx0 + true_up * sy0);
  params.dx = f4(right * (2.0 / view.width * tan_half * aspect));
  params.dy = f4(true_up * (-2.0 / view.height * tan_half));
  params.march = {static_cast<float>(step), static_cast<float>(cam.density),
                  static_cast<float>(4.0 * (v.resolution.x + v.resolution.y + v.resolution.z)), 0};
  params.sheet = {view.sheet ? 1.0f : 0.0f, static_cast<float>(view.sheet_height),
                  static_cast<float>(view.sheet_push / v.size.z), 0};
  params.image = {view.width, view.height, bgra ? 1 : 0, static_cast<int>(split_part_shift(c_))};
  // The shader writes the image through split_buffer.h's windows.
  const VkDeviceSize pixel_bytes = static_cast<VkDeviceSize>(view.width) * view.height * 4;
  check_split_binding(c_, pixel_bytes, "render_vectors: the image");
  grow(view_, sizeof params, false);
  grow(pixels_, pixel_bytes, false);
  rec.update(view_, 0, &params, sizeof params);
  const auto px = split_bindings(pixels_, c_);
  const std::array<Binding, 15> b{&unused_read_, &unused_read_,  &unused_read_, &unused_read_,
                                  &unused_read_, &unused_write_, &unused_read_, &texels,
                                  &unused_read_, &unused_write_, &view_,        px[0],
                                  px[1],         px[2],          px[3]};
  const int ticket = rec.begin_pass();
  rec.dispatch_strided(c_.kernel(shaders::vectors_view()), Recorder::Buffers(b), nullptr, 0,
                       static_cast<std::uint64_t>(view.width) * view.height);
  rec.end_pass(ticket, "view");
  return pixels_;
}

}  // namespace voxfield::gpu

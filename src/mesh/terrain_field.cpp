// voxfield — the terrain field's storage: chunks of quantised samples, uniform chunks stored once
// (terrain.h has the model; the brushes are in terrain_brush.cpp). Nässén & Leiborn (2019) kept
// one char per sample and re-sent the whole field every frame; here a chunk away from the surface
// costs a few bytes, and what an edit touches is known to the sample.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

#include "terrain_store.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield {

using detail::terrain::Chunk;

const char* terrain_storage_name(TerrainStorage s) {
  switch (s) {
    case TerrainStorage::kI8:
      return "i8";
    case TerrainStorage::kI16:
      return "i16";
    case TerrainStorage::kF32:
      return "f32";
  }
  return "?";
}

TerrainStorage parse_terrain_storage(const std::string& name) {
  if (name == "i8") return TerrainStorage::kI8;
  if (name == "i16") return TerrainStorage::kI16;
  if (name == "f32") return TerrainStorage::kF32;
  throw InvalidArgument("unknown terrain storage '" + name + "' (expected i8, i16 or f32)");
}

void TerrainField::Impl::compact(Chunk& c, const Box3i& samples) const {
  const Vec3i o = samples.begin;
  const auto scan = [&](auto&& same_as_first) {
    for (int z = o.z; z < samples.end.z; ++z)
      for (int y = o.y; y < samples.end.y; ++y)
        for (int x = o.x; x < samples.end.x; ++x)
          if (!same_as_first(local(x - o.x, y - o.y, z - o.z))) return false;
    return true;
  };
  if (!c.samples.empty()) {
    const std::uint32_t first = c.raw(0, codec.bytes);
    if (scan([&](std::size_t i) { return c.raw(i, codec.bytes) == first; })) {
      c.uniform = first;
      std::vector<std::uint8_t>().swap(c.samples);
    }
  }
  if (!c.materials.empty()) {
    const std::uint8_t first = c.materials[0];
    if (scan([&](std::size_t i) { return c.materials[i] == first; })) {
      c.uniform_material = first;
      std::vector<std::uint8_t>().swap(c.materials);
    }
  }
}

TerrainField::TerrainField(const TerrainOptions& options) : impl_(std::make_unique<Impl>()) {
  TerrainOptions o = options;
  for (int a = 0; a < 3; ++a)
    if (o.samples[a] < 2 || o.samples[a] > 65536)
      throw InvalidArgument("terrain: " + to_string(o.samples) +
                            " samples: each axis must hold 2..65536");
  if (o.chunk_edge < 4 || o.chunk_edge > 64)
    throw InvalidArgument("terrain: chunk edge " + std::to_string(o.chunk_edge) +
                          " is outside 4..64");
  if (!(o.spacing_units > 0) || !std::isfinite(o.spacing_units))
    throw InvalidArgument("terrain: the spacing must be finite and > 0");
  for (double v : o.origin_units)
    if (!std::isfinite(v)) throw InvalidArgument("terrain: the origin must be finite");
  if (o.max_distance_units == 0)
    o.max_distance_units = o.spacing_units * (o.storage == TerrainStorage::kI8 ? 2 : 4);
  if (!(o.max_distance_units > 0) || !std::isfinite(o.max_distance_units))
    throw InvalidArgument("terrain: the clamp must be finite and > 0 (0 picks the default)");
  Impl& s = *impl_;
  s.options = o;
  s.codec = detail::terrain::Codec(o.storage, o.max_distance_units);
  // The step must be a normal double (a clamp so small its step underflows cannot be encoded),
  // and an f32 clamp a finite float (else every sample would store infinity).
  if ((o.storage != TerrainStorage::kF32 && !std::isnormal(s.codec.step)) ||
      (o.storage == TerrainStorage::kF32 &&
       !(o.max_distance_units <= std::numeric_limits<float>::max() &&
         o.max_distance_units >= std::numeric_limits<float>::min())))
    throw InvalidArgument("terrain: a clamp of " + std::to_string(o.max_distance_units) +
                          " units cannot be stored in " + terrain_storage_name(o.storage));
  for (int a = 0; a < 3; ++a) s.chunks[a] = (o.samples[a] + o.chunk_edge - 1) / o.chunk_edge;
  const std::uint64_t count = static_cast<std::uint64_t>(s.chunks.x) *
                              static_cast<std::uint64_t>(s.chunks.y) *
                              static_cast<std::uint64_t>(s.chunks.z);
  require_memory(mul_sat(count, sizeof(Chunk)), 0, "terrain " + to_string(o.samples),
                 "its chunk table");
  s.chunk.resize(count);
  const std::uint32_t air = s.codec.encode(o.max_distance_units);
  for (Chunk& c : s.chunk) c.uniform = air;
}

TerrainField::~TerrainField() = default;
TerrainField::TerrainField(const TerrainField& o) : impl_(std::make_unique<Impl>(*o.impl_)) {}
TerrainField& TerrainField::operator=(const TerrainField& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}
TerrainField::TerrainField(TerrainField&&) noexcept = default;
TerrainField& TerrainField::operator=(TerrainField&&) noexcept = default;

const TerrainOptions& TerrainField::options() const {
  return impl_->options;
}
double TerrainField::max_distance_units() const {
  return impl_->codec.clamp;
}
double TerrainField::step_units() const {
  return impl_->codec.step;
}
Vec3i TerrainField::size() const {
  return impl_->options.samples;
}
Vec3i TerrainField::chunk_count() const {
  return impl_->chunks;
}

void TerrainField::assign(const std::function<double(const Vec3d&)>& value, std::uint8_t material) {
  const Impl& s = *impl_;
  assign_samples([&](int x, int y, int z) { return value(s.position(x, y, z)); }, material);
}

void TerrainField::assign_samples(const std::function<double(int, int, int)>& value,
                                  std::uint8_t material) {
  Impl& s = *impl_;
  const double sign = s.options.positive_inside ? -1 : 1;
  const std::size_t per_chunk = static_cast<std::size_t>(s.edge()) * s.edge() * s.edge();
  require_memory(mul_sat(s.chunk.size(), per_chunk * static_cast<std::size_t>(s.codec.bytes)), 0,
                 "terrain " + to_string(s.options.samples),
                 "its samples while they are assigned (before uniform chunks are compacted)");
  std::vector<Chunk> fresh(s.chunk.size());  // built aside: a NaN leaves the field as it was
  parallel_for(fresh.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      Chunk& c = fresh[i];
      const Box3i b = s.samples_of(s.chunk_coord(i));
      c.samples.assign(per_chunk * static_cast<std::size_t>(s.codec.bytes), 0);
      c.uniform_material = material;
      for (int z = b.begin.z; z < b.end.z; ++z)
        for (int y = b.begin.y; y < b.end.y; ++y)
          for (int x = b.begin.x; x < b.end.x; ++x) {
            const double v = value(x, y, z);
            if (std::isnan(v))
              throw InvalidArgument("terrain: the function gives NaN at sample " +
                                    to_string(Vec3i{x, y, z}));
            c.set_raw(s.local(x - b.begin.x, y - b.begin.y, z - b.begin.z), s.codec.bytes,
                      s.codec.encode(sign * v));
          }
      s.compact(c, b);
    }
  });
  s.chunk.swap(fresh);
}

void TerrainField::assign(const ScalarVolume& volume, std::uint8_t material) {
  const Impl& s = *impl_;
  if (!(volume.size == s.options.samples) || !volume.values)
    throw InvalidArgument("terrain: a volume of " + to_string(volume.size) +
                          " samples cannot fill a terrain of " + to_string(s.options.samples));
  assign_samples([&](int x, int y, int z) { return static_cast<double>(volume.at(x, y, z)); },
                 material);
}

namespace {

// `count` consecutive codes decoded into out, times sign: one loop per width, which the compiler
// vectorises (a decode per sample through the codec's switch was the terrain meshers' bottleneck).
// The same arithmetic as Codec::decode: code * step in double, rounded to float.
void decode_run(const detail::terrain::Codec& codec, const std::uint8_t* codes, std::size_t count,
                float sign, float* out) {
  const auto run = [&](auto zero, double scale) {
    using T = decltype(zero);
    for (std::size_t i = 0; i < count; ++i) {
      T v;
      std::memcpy(&v, codes + i * sizeof(T), sizeof(T));
      if constexpr (std::is_same_v<T, float>)
        out[i] = sign * v;
      else
        out[i] = sign * static_cast<float>(v * scale);
    }
  };
  switch (codec.storage) {
    case TerrainStorage::kI8:
      return run(std::int8_t{}, codec.step);
    case TerrainStorage::kI16:
      return run(std::int16_t{}, codec.step);
    case TerrainStorage::kF32:
      break;
  }
  run(float{}, 1.0);
}

void check_sample(const TerrainOptions& o, Vec3i p, const char* who) {
  if (!Box3i::from_size(o.samples).contains(p))
    throw InvalidArgument(std::string("terrain: ") + who + " of sample " + to_string(p) +
                          ", outside the " + to_string(o.samples) + " lattice");
}
}  // namespace

float TerrainField::value(Vec3i p) const {
  const Impl& s = *impl_;
  check_sample(s.options, p, "the value");
  const Vec3i c{p.x / s.edge(), p.y / s.edge(), p.z / s.edge()};
  const float v = s.codec.decode(s.chunk[s.chunk_index(c)].raw(
      s.local(p.x % s.edge(), p.y % s.edge(), p.z % s.edge()), s.codec.bytes));
  return s.options.positive_inside ? -v : v;
}

std::uint8_t TerrainField::material(Vec3i p) const {
  const Impl& s = *impl_;
  check_sample(s.options, p, "the material");
  const Vec3i c{p.x / s.edge(), p.y / s.edge(), p.z / s.edge()};
  return s.chunk[s.chunk_index(c)].material(
      s.local(p.x % s.edge(), p.y % s.edge(), p.z % s.edge()));
}

void TerrainField::decode(const Box3i& region, float* out) const {
  const Impl& s = *impl_;
  if (!Box3i::from_size(s.options.samples).contains(region))
    throw InvalidArgument("terrain: cannot decode samples outside the " +
                          to_string(s.options.samples) + " lattice");
  if (region.empty()) return;
  const float sign = s.options.positive_inside ? -1.0f : 1.0f;
  const int e = s.edge();
  const auto width = static_cast<std::size_t>(region.end.x - region.begin.x);
  for (int z = region.begin.z; z < region.end.z; ++z)
    for (int y = region.begin.y; y < region.end.y; ++y) {
      float* row = out + width * (static_cast<std::size_t>(y - region.begin.y) +
                                  static_cast<std::size_t>(region.end.y - region.begin.y) *
                                      static_cast<std::size_t>(z - region.begin.z));
      // Chunk by chunk along the row: a uniform chunk is one value; a dense one is decoded.
      for (int x = region.begin.x; x < region.end.x;) {
        const int cx = x / e, stop = std::min(region.end.x, (cx + 1) * e);
        const Chunk& c = s.chunk[s.chunk_index({cx, y / e, z / e})];
        if (c.samples.empty()) {
          std::fill(row, row + (stop - x), sign * s.codec.decode(c.uniform));
          row += stop - x;
          x = stop;
          continue;
        }
        const std::size_t first = s.local(x - cx * e, y % e, z % e);
        const auto count = static_cast<std::size_t>(stop - x);
        decode_run(s.codec, c.samples.data() + first * static_cast<std::size_t>(s.codec.bytes),
                   count, sign, row);
        row += count;
        x = stop;
      }
    }
}

void TerrainField::read_codes(const Box3i& region, void* codes, std::uint8_t* materials) const {
  const Impl& s = *impl_;
  if (!Box3i::from_size(s.options.samples).contains(region))
    throw InvalidArgument("terrain: cannot read the codes of samples outside the " +
                          to_string(s.options.samples) + " lattice");
  if (region.empty()) return;
  const int e = s.edge();
  const auto bytes = static_cast<std::size_t>(s.codec.bytes);
  const auto width = static_cast<std::size_t>(region.end.x - region.begin.x);
  auto* out = static_cast<std::uint8_t*>(codes);
  for (int z = region.begin.z; z < region.end.z; ++z)
    for (int y = region.begin.y; y < region.end.y; ++y) {
      const std::size_t row = width * (static_cast<std::size_t>(y - region.begin.y) +
                                       static_cast<std::size_t>(region.end.y - region.begin.y) *
                                           static_cast<std::size_t>(z - region.begin.z));
      std::uint8_t* code = out ? out + row * bytes : nullptr;
      std::uint8_t* material = materials ? materials + row : nullptr;
      // Chunk by chunk along the row: a uniform chunk repeats its one code; a dense one is copied.
      for (int x = region.begin.x; x < region.end.x;) {
        const int cx = x / e, stop = std::min(region.end.x, (cx + 1) * e);
        const Chunk& c = s.chunk[s.chunk_index({cx, y / e, z / e})];
        const auto count = static_cast<std::size_t>(stop - x);
        const std::size_t first = s.local(x - cx * e, y % e, z % e);
        if (code) {
          if (c.samples.empty())
            for (std::size_t i = 0; i < count; ++i)
              std::memcpy(code + i * bytes, &c.uniform, bytes);
          else
            std::memcpy(code, c.samples.data() + first * bytes, count * bytes);
          code += count * bytes;
        }
        if (material) {
          if (c.materials.empty())
            std::fill(material, material + count, c.uniform_material);
          else
            std::memcpy(material, c.materials.data() + first, count);
          material += count;
        }
        x = stop;
      }
    }
}

TerrainField::Memory TerrainField::memory() const {
  const Impl& s = *impl_;
  Memory m;
  m.chunks = static_cast<std::int64_t>(s.chunk.size());
  m.bytes = sizeof(Impl) + s.chunk.capacity() * sizeof(Chunk);
  for (const Chunk& c : s.chunk) {
    m.uniform_chunks += c.samples.empty() && c.materials.empty();
    m.bytes += c.samples.capacity() + c.materials.capacity();
  }
  return m;
}

}  // namespace voxfield

// voxfield — the terrain field's storage (internal to the mesh module): the sample codec of each
// storage width and the chunks, uniform or dense (terrain.h describes the model).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "voxfield/terrain.h"

namespace voxfield::detail::terrain {

// One storage width: raw codes (the sample's bytes, zero-extended into 32 bits) to and from
// values in world units, with the clamp.
struct Codec {
  TerrainStorage storage = TerrainStorage::kI16;
  double clamp = 1, step = 0;
  int bytes = 2;

  Codec() = default;
  Codec(TerrainStorage s, double max_distance_units)
      : storage(s),
        clamp(max_distance_units),
        step(s == TerrainStorage::kI8    ? max_distance_units / 127
             : s == TerrainStorage::kI16 ? max_distance_units / 32767
                                         : 0),
        bytes(s == TerrainStorage::kI8    ? 1
              : s == TerrainStorage::kI16 ? 2
                                          : 4) {}

  float decode(std::uint32_t raw) const {
    switch (storage) {
      case TerrainStorage::kI8:
        return static_cast<float>(static_cast<std::int8_t>(raw) * step);
      case TerrainStorage::kI16:
        return static_cast<float>(static_cast<std::int16_t>(raw) * step);
      case TerrainStorage::kF32:
        break;
    }
    return std::bit_cast<float>(raw);
  }
  // std::round (half away from zero) of |x| <= 2^31, inline: truncation, then the fraction (exact:
  // x and its truncation differ by less than 1) decides. Without SSE4.1 std::round is a call.
  static std::int32_t round_half_away(double x) {
    std::int32_t i = static_cast<std::int32_t>(x);
    const double fraction = x - i;
    if (fraction >= 0.5) ++i;
    if (fraction <= -0.5) --i;
    return i;
  }
  // v clamped to ±clamp, then rounded to the nearest code (half away from zero). v is finite.
  std::uint32_t encode(double v) const {
    const double c = v < -clamp ? -clamp : v > clamp ? clamp : v;
    switch (storage) {
      case TerrainStorage::kI8:
        return static_cast<std::uint8_t>(
            static_cast<std::int8_t>(std::clamp(round_half_away(c / step), -127, 127)));
      case TerrainStorage::kI16:
        return static_cast<std::uint16_t>(
            static_cast<std::int16_t>(std::clamp(round_half_away(c / step), -32767, 32767)));
      case TerrainStorage::kF32:
        break;
    }
    return std::bit_cast<std::uint32_t>(static_cast<float>(c));
  }
};

// A chunk of edge³ samples (the last chunks along an axis reach past the lattice; those samples
// are never read). Uniform parts are one value: `samples` or `materials` is empty then.
struct Chunk {
  std::vector<std::uint8_t> samples;  // edge³ codes of `bytes` bytes each, x fastest
  std::uint32_t uniform = 0;
  std::vector<std::uint8_t> materials;  // edge³, x fastest
  std::uint8_t uniform_material = 0;

  // Each width is its own fixed-size copy: a copy of `bytes` bytes compiles to a call to memcpy
  // per sample, which (with the store-forwarding stall of reading its result back) was the
  // largest cost of a brush.
  std::uint32_t raw(std::size_t i, int bytes) const {
    if (samples.empty()) return uniform;
    const std::uint8_t* p = samples.data() + i * static_cast<std::size_t>(bytes);
    if (bytes == 1) return *p;
    if (bytes == 2) {
      std::uint16_t r;
      std::memcpy(&r, p, 2);
      return r;
    }
    std::uint32_t r;
    std::memcpy(&r, p, 4);
    return r;
  }
  void set_raw(std::size_t i, int bytes, std::uint32_t r) {
    std::uint8_t* p = samples.data() + i * static_cast<std::size_t>(bytes);
    if (bytes == 1) {
      *p = static_cast<std::uint8_t>(r);
    } else if (bytes == 2) {
      const auto r16 = static_cast<std::uint16_t>(r);
      std::memcpy(p, &r16, 2);
    } else {
      std::memcpy(p, &r, 4);
    }
  }
  std::uint8_t material(std::size_t i) const {
    return materials.empty() ? uniform_material : materials[i];
  }
};

}  // namespace voxfield::detail::terrain

namespace voxfield {

struct TerrainField::Impl {
  TerrainOptions options;
  detail::terrain::Codec codec;
  Vec3i chunks;  // per axis
  std::vector<detail::terrain::Chunk> chunk;

  int edge() const { return options.chunk_edge; }
  std::size_t chunk_index(Vec3i c) const {
    return static_cast<std::size_t>(c.x) +
           static_cast<std::size_t>(chunks.x) *
               (static_cast<std::size_t>(c.y) +
                static_cast<std::size_t>(chunks.y) * static_cast<std::size_t>(c.z));
  }
  Vec3i chunk_coord(std::size_t i) const {
    const std::size_t nx = static_cast<std::size_t>(chunks.x),
                      ny = static_cast<std::size_t>(chunks.y);
    return {static_cast<int>(i % nx), static_cast<int>(i / nx % ny), static_cast<int>(i / nx / ny)};
  }
  // Sample (x, y, z) of the chunk at `origin` (its first sample), as an index into the chunk.
  std::size_t local(int x, int y, int z) const {
    const auto e = static_cast<std::size_t>(edge());
    return static_cast<std::size_t>(x) +
           e * (static_cast<std::size_t>(y) + e * static_cast<std::size_t>(z));
  }
  // The samples of chunk c that lie in the lattice.
  Box3i samples_of(Vec3i c) const {
    Box3i b;
    for (int a = 0; a < 3; ++a) {
      b.begin[a] = c[a] * edge();
      b.end[a] = std::min(options.samples[a], b.begin[a] + edge());
    }
    return b;
  }
  Vec3d position(int x, int y, int z) const {
    return {options.origin_units[0] + x * options.spacing_units,
            options.origin_units[1] + y * options.spacing_units,
            options.origin_units[2] + z * options.spacing_units};
  }
  // Collapses the chunk's samples and materials to one value each where its in-lattice samples
  // all hold the same.
  void compact(detail::terrain::Chunk& c, const Box3i& samples) const;
};

}  // namespace voxfield

// A step of the dynamic field (Hamlin, "Volumetric Interaction", section 3.3: decay and blend) and
// the fixed-step scheduler that drives it. The paper's "fixed time step" was a minimum interval
// that never caught up after a slow frame; FixedStepScheduler keeps an accumulator and runs whole
// steps, capped per frame so a stall cannot snowball.
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>

#include "texel_codec.h"
#include "vector_internal.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

namespace {

// The blend, inlined into the step's sweep; decay_s is decay_per_s * dt_s.
inline VectorTexel blend(const VectorTexel& current, const VectorTexel& previous, float decay_s) {
  // In float, as a shader blends (the texels are floats or narrower).
  const float sc = current.strength;
  const float sp = std::max(0.0f, previous.strength - decay_s);
  const float total = sc + sp;
  // Both gone (or decayed away): the zero texel, as where no source ever was — not the old
  // direction at strength 0, which would keep a stale direction in the texture.
  if (!(total > 0)) return {};
  // One side alone: its direction as stored (renormalising a decoded 8-bit direction every step
  // would let it drift), with the decayed strength.
  if (sp == 0) return current;
  if (sc == 0) return {previous.x, previous.y, previous.z, sp};
  const float w = sc / total;
  const float nx = w * current.x + (1 - w) * previous.x, ny = w * current.y + (1 - w) * previous.y,
              nz = w * current.z + (1 - w) * previous.z;
  const float length2 = nx * nx + ny * ny + nz * nz;
  VectorTexel out;
  if (length2 > 0) {
    const float inv = 1.0f / std::sqrt(length2);
    out.x = nx * inv;
    out.y = ny * inv;
    out.z = nz * inv;
  }
  out.strength = std::max(sc, sp);
  return out;
}

}  // namespace

VectorTexel blend_vector_texels(const VectorTexel& current, const VectorTexel& previous,
                                double decay_per_s, double dt_s) {
  return blend(current, previous, static_cast<float>(decay_per_s * dt_s));
}

// Per texture, one flag per row (j, k): whether any texel of the row has a non-zero strength.
// A row no source touches and whose previous row is all zero stays zero: the sweep writes it only
// if the texture it writes last held something there, so a step costs what the sources and their
// wakes cover, not the whole volume.
struct VectorSimulation::Scratch {
  detail::vectors::SplatScratch splat;
  std::vector<std::uint8_t> current_rows, field_rows, next_rows, touched_rows;
};

VectorSimulation::VectorSimulation(const VectorVolume& volume, VectorStorage storage,
                                   VectorOptions options, double decay_per_s)
    : volume_(volume),
      options_(options),
      decay_per_s_(decay_per_s),
      scratch_(std::make_unique<Scratch>()) {
  volume_.validate();
  if (!std::isfinite(decay_per_s) || decay_per_s < 0)
    throw InvalidArgument("vector simulation: the decay per second must be finite and >= 0");
  options_.interrupter = nullptr;  // never kept: step() is the long-lived object's only work
  // Three textures and splatting's scratch (winner and best score, 12 bytes) per voxel.
  const std::uint64_t texel_bytes = storage == VectorStorage::kRgba8     ? 4
                                    : storage == VectorStorage::kRgba16f ? 8
                                                                         : 16;
  require_memory(mul_sat(static_cast<std::uint64_t>(volume_.voxel_count()), 3 * texel_bytes + 12),
                 0, "vector simulation " + to_string(volume_.resolution),
                 "its three textures and scratch");
  current_ = VectorTexture(volume_.resolution, storage);
  field_ = VectorTexture(volume_.resolution, storage);
  next_ = VectorTexture(volume_.resolution, storage);
}

VectorSimulation::~VectorSimulation() = default;
VectorSimulation::VectorSimulation(VectorSimulation&&) noexcept = default;
VectorSimulation& VectorSimulation::operator=(VectorSimulation&&) noexcept = default;

namespace {

struct RowFlags {
  std::uint8_t* current;
  const std::uint8_t* previous;
  std::uint8_t* next;
  const std::uint8_t* touched;
  // rgba8: the strength byte after decay, as blend() then store() would give it alone (-1: the
  // decayed strength is exactly 0, which blends to the zero texel).
  const std::int16_t* decay8;
};

// A previous texel with no current source: its decayed self (blend with a zero current). In rgba8
// (most non-zero texels are such wakes) the blend keeps the stored direction bytes and decays the
// strength byte, which the step's table gives directly. Returns whether the result is non-zero.
template <class C>
bool decay_alone(const std::uint8_t* previous, std::uint8_t* next, float decay_s,
                 const std::int16_t* decay8) {
  if constexpr (std::is_same_v<C, detail::vectors::Codec<VectorStorage::kRgba8>>) {
    const std::int16_t decayed = decay8[previous[3]];
    if (decayed < 0) {
      C::store_zero(next);
      return false;
    }
    std::memcpy(next, previous, 3);
    next[3] = static_cast<std::uint8_t>(decayed);
    return decayed != 0;
  } else {
    C::store(next, blend(VectorTexel{}, C::load(previous), decay_s));
    return !C::zero_strength(next);
  }
}

// Conversion, decay and blend of one step in one sweep: each voxel's current texel from its
// winner (stored, then read back as stored), blended with the decayed previous texel into next.
template <class C>
void fused_step(const VectorVolume& v, std::span<const detail::vectors::Segment> segments,
                std::span<const std::int32_t> winners, float decay_s, std::uint8_t* current,
                const std::uint8_t* previous, std::uint8_t* next, RowFlags rows) {
  const detail::vectors::CentreTables centres(v);
  const Vec3i n = v.resolution;
  auto zero_row = [&](std::uint8_t* p) {
    for (int i = 0; i < n.x; ++i) C::store_zero(p + static_cast<std::size_t>(i) * C::kBytes);
  };
  detail::vectors::for_each_slab(v, nullptr, "vector step", [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < n.y; ++j) {
        const std::size_t row = static_cast<std::size_t>(j) + static_cast<std::size_t>(n.y) * k;
        const std::int64_t first = v.index(0, j, k);
        const std::size_t at0 = static_cast<std::size_t>(first) * C::kBytes;
        if (!rows.touched[row] && !rows.previous[row]) {
          if (rows.current[row]) zero_row(current + at0);
          if (rows.next[row]) zero_row(next + at0);
          rows.current[row] = rows.next[row] = 0;
          continue;
        }
        if (!rows.touched[row]) {
          // A wake with no source now: the current row is zero (cleared once), and each texel is
          // the previous one decayed.
          if (rows.current[row]) zero_row(current + at0);
          rows.current[row] = 0;
          bool any = false;
          for (int i = 0; i < n.x; ++i) {
            const std::size_t at = at0 + static_cast<std::size_t>(i) * C::kBytes;
            if (C::zero_strength(previous + at)) {
              C::store_zero(next + at);
            } else {
              any = decay_alone<C>(previous + at, next + at, decay_s, rows.decay8) || any;
            }
          }
          rows.next[row] = any;
          continue;
        }
        bool any_current = false, any_next = false;
        for (int i = 0; i < n.x; ++i) {
          const std::size_t at = at0 + static_cast<std::size_t>(i) * C::kBytes;
          const std::int32_t w = winners[static_cast<std::size_t>(first + i)];
          VectorTexel now{};
          if (w >= 0) {
            C::store(current + at,
                     detail::vectors::texel_of(detail::vectors::value_of(
                         segments[static_cast<std::size_t>(w)], centres.at(i, j, k), w)));
            now = C::load(current + at);
            any_current = true;
          } else {
            C::store_zero(current + at);
            if (C::zero_strength(previous + at)) {
              C::store_zero(next + at);
              continue;
            }
            any_next = decay_alone<C>(previous + at, next + at, decay_s, rows.decay8) || any_next;
            continue;
          }
          C::store(next + at, blend(now, C::load(previous + at), decay_s));
          any_next = any_next || !C::zero_strength(next + at);
        }
        rows.current[row] = any_current;
        rows.next[row] = any_next;
      }
  });
}

}  // namespace

void VectorSimulation::step(std::span<const VectorSource> sources, double dt_s) {
  if (!std::isfinite(dt_s) || dt_s <= 0)
    throw InvalidArgument("vector simulation: the time step must be finite and > 0");
  validate_sources(sources);
  VectorPassTimes t;
  const std::vector<detail::vectors::Segment> segments = detail::vectors::segments_of(sources);
  std::vector<std::int32_t> full;
  std::span<const std::int32_t> winners;
  std::int64_t start = detail::vectors::now_ns();
  if (options_.algorithm == VectorAlgorithm::kSplat) {
    detail::vectors::splat_winners(volume_, sources, segments, options_.rule, nullptr,
                                   scratch_->splat);
    winners = scratch_->splat.winners;
    t.search_ms = detail::vectors::ms_since(start);
  } else {
    full = vector_winners(volume_, sources, options_, &t);
    winners = full;
  }
  start = detail::vectors::now_ns();
  Scratch& sc = *scratch_;
  const std::size_t rows = static_cast<std::size_t>(volume_.resolution.y) * volume_.resolution.z;
  if (sc.field_rows.size() != rows || sc.current_rows.size() != rows ||
      sc.next_rows.size() != rows) {  // the first step: every texture is zero
    std::vector<std::uint8_t> c(rows, 0), f(rows, 0), x(rows, 0);  // built aside, then swapped
    sc.current_rows.swap(c);
    sc.field_rows.swap(f);
    sc.next_rows.swap(x);
  }
  // Rows a source may write: its index box's rows (splat), or any winner's (the others).
  sc.touched_rows.assign(rows, 0);
  const Vec3i n = volume_.resolution;
  if (options_.algorithm == VectorAlgorithm::kSplat) {
    for (const detail::vectors::IndexBox& b : sc.splat.boxes) {
      if (b.empty()) continue;
      for (int k = b.lo[2]; k <= b.hi[2]; ++k)
        std::fill_n(sc.touched_rows.begin() + b.lo[1] + static_cast<std::ptrdiff_t>(n.y) * k,
                    b.hi[1] - b.lo[1] + 1, std::uint8_t{1});
    }
  } else {
    for (std::size_t i = 0; i < winners.size(); ++i)
      if (winners[i] >= 0) sc.touched_rows[i / static_cast<std::size_t>(n.x)] = 1;
  }
  std::array<std::int16_t, 256> decay8{};
  const float decay_s = static_cast<float>(decay_per_s_ * dt_s);
  for (int b = 0; b < 256; ++b) {
    const VectorTexel t =
        blend(VectorTexel{}, {0, 0, 0, detail::vectors::rgba8_tables().strength[b]}, decay_s);
    decay8[b] =
        t.strength > 0 ? std::int16_t{detail::vectors::unorm8(t.strength)} : std::int16_t{-1};
  }
  detail::vectors::with_codec(field_.storage(), [&](auto codec) {
    fused_step<decltype(codec)>(volume_, segments, winners, decay_s, current_.data(),
                                field_.bytes().data(), next_.data(),
                                {sc.current_rows.data(), sc.field_rows.data(), sc.next_rows.data(),
                                 sc.touched_rows.data(), decay8.data()});
  });
  t.blend_ms = detail::vectors::ms_since(start);
  std::swap(field_, next_);
  std::swap(sc.field_rows, sc.next_rows);
  times_ = t;
  ++steps_;
}

FixedStepScheduler::FixedStepScheduler(double dt_s, int max_steps_per_frame)
    : dt_s_(dt_s), max_steps_(max_steps_per_frame) {
  if (!std::isfinite(dt_s) || dt_s <= 0)
    throw InvalidArgument("fixed step: the time step must be finite and > 0");
  if (max_steps_per_frame < 1)
    throw InvalidArgument("fixed step: at least one step per frame must be allowed");
}

int FixedStepScheduler::advance(double frame_s) {
  if (!std::isfinite(frame_s) || frame_s < 0)
    throw InvalidArgument("fixed step: a frame time must be finite and >= 0");
  accumulator_s_ += frame_s;
  const double due = std::floor(accumulator_s_ / dt_s_);
  const int steps = due >= max_steps_ ? max_steps_ : static_cast<int>(due);
  accumulator_s_ -= steps * dt_s_;
  if (accumulator_s_ >= dt_s_) {  // the cap held steps back: drop them, keep the fraction
    const double keep = std::fmod(accumulator_s_, dt_s_);
    dropped_s_ += accumulator_s_ - keep;
    accumulator_s_ = keep;
  }
  return steps;
}

}  // namespace voxfield

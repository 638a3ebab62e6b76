// A step of the dynamic field (Hamlin, "Volumetric Interaction", section 3.3: decay and blend) and
// the fixed-step scheduler that drives it. The paper's "fixed time step" was a minimum interval
// that never caught up after a slow frame; FixedStepScheduler keeps an accumulator and runs whole
// steps, capped per frame so a stall cannot snowball.
#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>

#include "blend.h"
#include "texel_codec.h"
#include "vector_internal.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

namespace {

using detail::vectors::blend;

}  // namespace

VectorTexel blend_vector_texels(const VectorTexel& current, const VectorTexel& previous,
                                double decay_per_s, double dt_s) {
  return blend(current, previous, static_cast<float>(decay_per_s * dt_s));
}

// Per texture, one span per row (j, k): the texels of the row that may differ from the zero texel
// (outside it, the row holds the zero texel). A step sweeps, per row, only the hull of the spans of
// the sources that touch the row, of the previous field and of the two textures it overwrites, so
// it costs what the sources and their wakes cover, not the whole volume.
using detail::vectors::RowSpan;

struct VectorSimulation::Scratch {
  detail::vectors::SlabPool splat;
  std::vector<RowSpan> current_rows, field_rows, next_rows, touched_rows;
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
  // Three textures per voxel (splatting's scratch is a few slabs, per thread).
  const std::uint64_t texel_bytes = storage == VectorStorage::kRgba8     ? 4
                                    : storage == VectorStorage::kRgba16f ? 8
                                                                         : 16;
  require_memory(mul_sat(static_cast<std::uint64_t>(volume_.voxel_count()), 3 * texel_bytes), 0,
                 "vector simulation " + to_string(volume_.resolution), "its three textures");
  current_ = VectorTexture(volume_.resolution, storage);
  field_ = VectorTexture(volume_.resolution, storage);
  next_ = VectorTexture(volume_.resolution, storage);
}

VectorSimulation::~VectorSimulation() = default;
VectorSimulation::VectorSimulation(VectorSimulation&&) noexcept = default;
VectorSimulation& VectorSimulation::operator=(VectorSimulation&&) noexcept = default;

namespace {

struct RowSpans {
  RowSpan* current;
  const RowSpan* previous;
  RowSpan* next;
  // rgba8: the strength byte after decay, as blend() then store() would give it alone (-1: the
  // decayed strength is exactly 0, which blends to the zero texel).
  const std::int16_t* decay8;
};

RowSpan hull(RowSpan a, RowSpan b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}

// Grows a span over the texels found to differ from the zero texel.
struct SpanTracker {
  int lo = INT32_MAX, hi = -1;
  void add(int i) {
    lo = std::min(lo, i);
    hi = std::max(hi, i);  // rgba8's four-lane blends report their texels late
  }
  RowSpan span() const {
    return hi < 0 ? RowSpan{}
                  : RowSpan{static_cast<std::uint16_t>(lo), static_cast<std::uint16_t>(hi + 1)};
  }
};

// The rows of one step's sweep. Each row works on restrict-qualified pointers of its own: a store
// through a byte pointer may alias anything, so without them the compiler reloads every captured
// variable after each texel it writes.
template <class C>
struct StepRows {
  static constexpr bool kRgba8 = std::is_same_v<C, detail::vectors::Codec<VectorStorage::kRgba8>>;
  const detail::vectors::Segment* segments;
  const Vec3d* xs;  // the voxel-centre offsets along x (CentreTables::x)
  int nx;
  float decay_s;
  // rgba8: the strength byte after decay, as blend() then store() would give it alone (-1: the
  // decayed strength is exactly 0, which blends to the zero texel).
  const std::int16_t* decay8;

  static constexpr std::uint32_t kZero8 = 0x00808080u;  // rgba8's zero texel, little-endian

  // A previous texel with no current source: its decayed self (blend with a zero current). In
  // rgba8 (most non-zero texels are such wakes) the blend keeps the stored direction bytes and
  // decays the strength byte, which the step's table gives directly (decay8[0] = -1: a zero
  // strength stays the zero texel). Returns whether the result differs from the zero texel — a
  // direction whose strength stored as 0 does, and is cleared by the next step.
  bool decay_alone(const std::uint8_t* __restrict previous, std::uint8_t* __restrict next) const {
    if constexpr (kRgba8) {
      std::uint32_t word;
      std::memcpy(&word, previous, 4);
      const std::int16_t decayed = decay8[word >> 24];
      const std::uint32_t out =
          decayed < 0 ? kZero8 : (word & 0x00ffffffu) | (static_cast<std::uint32_t>(decayed) << 24);
      std::memcpy(next, &out, 4);
      return out != kZero8;
    } else {
      if (C::zero_strength(previous)) {
        C::store_zero(next);
        return false;
      }
      alignas(16) std::uint8_t out[C::kBytes];
      C::store(out, blend(VectorTexel{}, C::load(previous), decay_s));
      std::memcpy(next, out, C::kBytes);
      return !is_zero_texel(out);
    }
  }

  static bool is_zero_texel(const std::uint8_t* p) {
    static constexpr std::uint8_t kZero[16] = {};
    if constexpr (kRgba8) {
      std::uint32_t word;
      std::memcpy(&word, p, 4);
      return word == kZero8;
    } else {
      return std::memcmp(p, kZero, C::kBytes) == 0;
    }
  }

  void zero_span(std::uint8_t* __restrict row, RowSpan span) const {
    for (int i = span.lo; i < span.hi; ++i)
      C::store_zero(row + static_cast<std::size_t>(i) * C::kBytes);
  }

  // A wake with no source now: each texel of `span` is the previous one decayed. Returns the span
  // of the results that differ from the zero texel.
  RowSpan decay_row(RowSpan span, const std::uint8_t* __restrict previous,
                    std::uint8_t* __restrict next) const {
    SpanTracker out;
    for (int i = span.lo; i < span.hi; ++i) {
      const std::size_t at = static_cast<std::size_t>(i) * C::kBytes;
      if (decay_alone(previous + at, next + at)) out.add(i);
    }
    return out.span();
  }

  // A row the sources touch, over `span`: each voxel's current texel from its winner (`found`:
  // the search's own values, else computed here; stored, then read back as stored), blended
  // with the decayed previous texel into next. Returns the spans of the current and next texels
  // that differ from the zero texel.
  std::pair<RowSpan, RowSpan> source_row(RowSpan span, const std::int32_t* __restrict winners,
                                         const VectorTexel* __restrict found, Vec3d row_base,
                                         std::uint8_t* __restrict current,
                                         const std::uint8_t* __restrict previous,
                                         std::uint8_t* __restrict next) const {
#if VOXFIELD_VECTORS_BLEND4
    if constexpr (kRgba8)
      return source_row8(span, winners, found, row_base, current, previous, next);
#endif
    SpanTracker now, later;
    for (int i = span.lo; i < span.hi; ++i) {
      const std::size_t at = static_cast<std::size_t>(i) * C::kBytes;
      const std::int32_t w = winners[i];
      if (w < 0) {
        C::store_zero(current + at);
        if (decay_alone(previous + at, next + at)) later.add(i);
        continue;
      }
      // Encoded into locals and copied out whole: reading back a texel just stored byte by byte
      // would stall on store forwarding.
      alignas(16) std::uint8_t texel[C::kBytes], blended[C::kBytes];
      C::store(texel, found ? found[i]
                            : detail::vectors::texel_of(detail::vectors::value_of(
                                  segments[static_cast<std::size_t>(w)], row_base + xs[i], w)));
      std::memcpy(current + at, texel, C::kBytes);
      now.add(i);
      C::store(blended, blend(C::load(texel), C::load(previous + at), decay_s));
      std::memcpy(next + at, blended, C::kBytes);
      if (!is_zero_texel(blended)) later.add(i);
    }
    return {now.span(), later.span()};
  }

#if VOXFIELD_VECTORS_BLEND4
  // source_row for rgba8, with the blends of texels that have both a current and a decayed
  // previous strength run four at a time (Rgba8Blend4) in a second pass over the row. A blend
  // with one side alone is that side's bytes — the current texel as stored, or the previous one
  // with its decayed strength byte (decay_alone) — and both gone is the zero texel, as blend()
  // then store() gives them.
  std::pair<RowSpan, RowSpan> source_row8(RowSpan span, const std::int32_t* __restrict winners,
                                          const VectorTexel* __restrict found, Vec3d row_base,
                                          std::uint8_t* __restrict current,
                                          const std::uint8_t* __restrict previous,
                                          std::uint8_t* __restrict next) const {
    SpanTracker now, later;
    std::uint16_t both[4096 + 3];  // the texels blended in the second pass (rows <= 4096)
    int count = 0;
    for (int i = span.lo; i < span.hi; ++i) {
      const std::size_t at = static_cast<std::size_t>(i) * 4;
      const std::int32_t w = winners[i];
      if (w < 0) {
        C::store_zero(current + at);
        if (decay_alone(previous + at, next + at)) later.add(i);
        continue;
      }
      alignas(4) std::uint8_t texel[4];
      C::store(texel, found ? found[i]
                            : detail::vectors::texel_of(detail::vectors::value_of(
                                  segments[static_cast<std::size_t>(w)], row_base + xs[i], w)));
      std::uint32_t word, before;
      std::memcpy(&word, texel, 4);
      std::memcpy(current + at, &word, 4);
      now.add(i);
      std::memcpy(&before, previous + at, 4);
      if (decay8[before >> 24] < 0) {  // the previous strength decays to 0: the current alone
        const std::uint32_t out = (word >> 24) == 0 ? kZero8 : word;
        std::memcpy(next + at, &out, 4);
        if (out != kZero8) later.add(i);
      } else if ((word >> 24) == 0) {  // no current strength: the previous one decayed
        if (decay_alone(previous + at, next + at)) later.add(i);
      } else {
        both[count++] = static_cast<std::uint16_t>(i);
      }
    }
    if (count == 0) return {now.span(), later.span()};
    for (int n = count; n % 4 != 0; ++n) both[n] = both[count - 1];  // pad: repeat the last
    for (int first = 0; first < count; first += 4) {
      std::uint32_t c[4], p[4], out[4];
      for (int n = 0; n < 4; ++n) {
        const std::size_t at = static_cast<std::size_t>(both[first + n]) * 4;
        std::memcpy(&c[n], current + at, 4);
        std::memcpy(&p[n], previous + at, 4);
      }
      detail::vectors::Rgba8Blend4::run(c, p, decay_s, out);
      for (int n = 0; n < std::min(4, count - first); ++n) {
        std::memcpy(next + static_cast<std::size_t>(both[first + n]) * 4, &out[n], 4);
        if (out[n] != kZero8) later.add(both[first + n]);
      }
    }
    return {now.span(), later.span()};
  }
#endif
};

// Conversion, decay and blend of one step in one sweep, row by row, over the hull of the row's
// spans: outside it every texture already holds the zero texel and keeps it. sweep(k0, k1) does
// the rows of z layers [k0, k1).
template <class C>
struct Sweep {
  const VectorVolume& v;
  const detail::vectors::CentreTables centres;
  const StepRows<C> pass;
  std::uint8_t* current;
  const std::uint8_t* previous;
  std::uint8_t* next;
  RowSpans rows;

  Sweep(const VectorVolume& volume, std::span<const detail::vectors::Segment> segments,
        float decay_s, std::uint8_t* current_texels, const std::uint8_t* previous_texels,
        std::uint8_t* next_texels, RowSpans spans)
      : v(volume),
        centres(volume),
        pass{segments.data(), centres.x.data(), volume.resolution.x, decay_s, spans.decay8},
        current(current_texels),
        previous(previous_texels),
        next(next_texels),
        rows(spans) {}

  // The rows of z layers [k0, k1): winners and found (optional) indexed from voxel (0, 0, k0),
  // touched (a span per row) from row ny k0.
  void operator()(int k0, int k1, const std::int32_t* winners, const VectorTexel* found,
                  const RowSpan* touched_rows) const {
    const Vec3i n = v.resolution;
    const std::int64_t slab_first = v.index(0, 0, k0);
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < n.y; ++j) {
        const std::size_t row = static_cast<std::size_t>(j) + static_cast<std::size_t>(n.y) * k;
        const std::int64_t first = v.index(0, j, k);
        const std::size_t at0 = static_cast<std::size_t>(first) * C::kBytes;
        const auto local = static_cast<std::size_t>(first - slab_first);
        RowSpan& current_span = rows.current[row];
        RowSpan& next_span = rows.next[row];
        const RowSpan touched = touched_rows[row - static_cast<std::size_t>(n.y) * k0],
                      previous_span = rows.previous[row];
        if (touched.empty()) {
          // No source now: the current row is zero, and each next texel the previous one decayed
          // (over the old next span too, which the decay of zero texels clears).
          pass.zero_span(current + at0, current_span);
          current_span = {};
          const RowSpan sweep = hull(previous_span, next_span);
          next_span = sweep.empty() ? RowSpan{} : pass.decay_row(sweep, previous + at0, next + at0);
          continue;
        }
        const RowSpan sweep = hull(hull(touched, previous_span), hull(current_span, next_span));
        const auto [now, later] =
            pass.source_row(sweep, winners + local, found ? found + local : nullptr,
                            centres.row(j, k), current + at0, previous + at0, next + at0);
        current_span = now;
        next_span = later;
      }
  }
};

}  // namespace

void VectorSimulation::step(std::span<const VectorSource> sources, double dt_s) {
  if (!std::isfinite(dt_s) || dt_s <= 0)
    throw InvalidArgument("vector simulation: the time step must be finite and > 0");
  validate_sources(sources);
  VectorPassTimes t;
  const std::vector<detail::vectors::Segment> segments = detail::vectors::segments_of(sources);
  Scratch& sc = *scratch_;
  const std::size_t rows = static_cast<std::size_t>(volume_.resolution.y) * volume_.resolution.z;
  if (sc.field_rows.size() != rows || sc.current_rows.size() != rows ||
      sc.next_rows.size() != rows) {                 // the first step: every texture is zero
    std::vector<RowSpan> c(rows), f(rows), x(rows);  // built aside, then swapped
    sc.current_rows.swap(c);
    sc.field_rows.swap(f);
    sc.next_rows.swap(x);
  }
  std::array<std::int16_t, 256> decay8{};
  const float decay_s = static_cast<float>(decay_per_s_ * dt_s);
  for (int b = 0; b < 256; ++b) {
    const VectorTexel d =
        blend(VectorTexel{}, {0, 0, 0, detail::vectors::rgba8_tables().strength[b]}, decay_s);
    decay8[b] =
        d.strength > 0 ? std::int16_t{detail::vectors::unorm8(d.strength)} : std::int16_t{-1};
  }
  const RowSpans spans{sc.current_rows.data(), sc.field_rows.data(), sc.next_rows.data(),
                       decay8.data()};
  const std::int64_t start = detail::vectors::now_ns();
  if (options_.algorithm == VectorAlgorithm::kSplat) {
    // Each z slab is splatted, then swept at once by the same thread while its rows are in the
    // cache; the rows splatting wrote are the sweep's sources.
    std::atomic<std::int64_t> splat_ns{0}, sweep_ns{0};
    detail::vectors::with_codec(field_.storage(), [&](auto codec) {
      const Sweep<decltype(codec)> sweep(volume_, segments, decay_s, current_.data(),
                                         field_.bytes().data(), next_.data(), spans);
      detail::vectors::splat_slabs(
          volume_, sources, segments, options_.rule, sc.splat,
          [&](const detail::vectors::SlabSplat& slab) {
            const std::int64_t slab_start = detail::vectors::now_ns();
            sweep(slab.k0, slab.k1, slab.winners, slab.texels, slab.won);
            sweep_ns += detail::vectors::now_ns() - slab_start;
          },
          &splat_ns);
    });
    // The wall time, apportioned between the two by the threads' time in each.
    const double total_ms = detail::vectors::ms_since(start);
    const double busy = static_cast<double>(splat_ns.load() + sweep_ns.load());
    t.search_ms = busy > 0 ? total_ms * static_cast<double>(splat_ns.load()) / busy : 0;
    t.blend_ms = total_ms - t.search_ms;
  } else {
    const std::vector<std::int32_t> winners = vector_winners(volume_, sources, options_, &t);
    const std::int64_t sweep_start = detail::vectors::now_ns();
    // The texels a source won: from every winner.
    sc.touched_rows.assign(rows, RowSpan{});
    const Vec3i n = volume_.resolution;
    for (std::size_t i = 0; i < winners.size(); ++i)
      if (winners[i] >= 0) {
        RowSpan& r = sc.touched_rows[i / static_cast<std::size_t>(n.x)];
        const auto x = static_cast<std::uint16_t>(i % static_cast<std::size_t>(n.x));
        r = hull(r, RowSpan{x, static_cast<std::uint16_t>(x + 1)});
      }
    detail::vectors::with_codec(field_.storage(), [&](auto codec) {
      const Sweep<decltype(codec)> sweep(volume_, segments, decay_s, current_.data(),
                                         field_.bytes().data(), next_.data(), spans);
      detail::vectors::for_each_slab(volume_, nullptr, "vector step", [&](int k0, int k1) {
        sweep(k0, k1, winners.data() + volume_.index(0, 0, k0), nullptr,
              sc.touched_rows.data() + static_cast<std::size_t>(n.y) * k0);
      });
    });
    t.blend_ms = detail::vectors::ms_since(sweep_start);
  }
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

// voxfield — a dense lattice's samples as rows of inside bits (see bit_rows.h).
#include "bit_rows.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "mesh_memory.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace voxfield::detail::mesh {

namespace {

// Inside bits of `count` samples into words (bit k of word w: sample 64 w + k); returns whether
// one is NaN or infinite (its exponent bits all set).
bool inside_bits(const float* v, int count, float iso, bool inside_above, std::uint64_t* out) {
  std::uint32_t bad = 0;
  int x = 0;
  std::uint64_t word = 0;
#if defined(__SSE2__)
  const __m128 iso4 = _mm_set1_ps(iso);
  const __m128i exponent = _mm_set1_epi32(0x7f800000);
  __m128i bad4 = _mm_setzero_si128();
  for (; x + 4 <= count; x += 4) {
    const __m128 s = _mm_loadu_ps(v + x);
    const __m128 in = inside_above ? _mm_cmpgt_ps(s, iso4) : _mm_cmplt_ps(s, iso4);
    word |= static_cast<std::uint64_t>(_mm_movemask_ps(in)) << (x & 63);
    bad4 =
        _mm_or_si128(bad4, _mm_cmpeq_epi32(_mm_and_si128(_mm_castps_si128(s), exponent), exponent));
    if ((x & 63) == 60) {
      out[x >> 6] = word;
      word = 0;
    }
  }
  bad = static_cast<std::uint32_t>(_mm_movemask_epi8(bad4));
#endif
  for (; x < count; ++x) {
    std::uint32_t bits;
    std::memcpy(&bits, &v[x], sizeof bits);
    bad |= static_cast<std::uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
    const bool in = inside_above ? v[x] > iso : v[x] < iso;
    word |= static_cast<std::uint64_t>(in) << (x & 63);
    if ((x & 63) == 63) {
      out[x >> 6] = word;
      word = 0;
    }
  }
  if (count & 63) out[count >> 6] = word;
  return bad != 0;
}

}  // namespace

InsideBits::InsideBits(const Lattice& lattice, Progress& progress, int z_offset)
    : ny_(lattice.n.y), planes_(static_cast<std::size_t>(lattice.n.z)) {
  const Vec3i n = lattice.n;
  const std::size_t rows = static_cast<std::size_t>(n.y) * static_cast<std::size_t>(n.z);
  words_ = static_cast<std::size_t>(n.x) / 64 + 1;
  require_memory(mul_sat(mul_sat(rows, words_), 8), 0, "mesh", "the lattice's inside bits");
  // On huge pages: their small pages' faults would cost more than the pass that fills them.
  resize_on_huge_pages(bits_, rows * words_);  // zeroed: the padding past each row stays 0
  uniform_.resize(rows);
  const float iso = static_cast<float>(lattice.iso);
  const bool above = lattice.sign < 0;
  // The first sample of each plane that is NaN or infinite, if any.
  std::vector<std::int64_t> first_bad(static_cast<std::size_t>(n.z), -1);
  for_each_plane(n.z, progress, [&](int z) {
    for (int y = 0; y < n.y; ++y) {
      const std::size_t at = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
      const float* values = lattice.values + at * static_cast<std::size_t>(n.x);
      std::int64_t& bad = first_bad[static_cast<std::size_t>(z)];
      std::uint64_t* row = bits_.data() + at * words_;
      if (inside_bits(values, n.x, iso, above, row) && bad < 0)
        for (int x = 0; x < n.x; ++x)
          if (!std::isfinite(values[x])) {
            bad = static_cast<std::int64_t>(at) * n.x + x;
            break;
          }
      const std::uint64_t inside = population(row, words_);
      uniform_[at] = inside == 0 ? 0 : inside == static_cast<std::uint64_t>(n.x) ? 1 : kMixed;
    }
  });
  for (const std::int64_t bad : first_bad)
    if (bad >= 0) {
      const int x = static_cast<int>(bad % n.x), y = static_cast<int>(bad / n.x % n.y),
                z = static_cast<int>(bad / n.x / n.y) + z_offset;
      throw InvalidArgument("mesh: sample (" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                            std::to_string(z) + ") is " +
                            (std::isnan(lattice.values[bad]) ? "NaN" : "infinite"));
    }
}

void for_each_plane(int planes, Progress& progress, const std::function<void(int z)>& f) {
  parallel_for(static_cast<std::size_t>(planes), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t z = begin; z < end; ++z) {
      if (!progress.keep_going()) return;
      f(static_cast<int>(z));
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
}

void count_rows(int planes, std::size_t rows, Progress& progress,
                const std::function<void(int z)>& count, std::vector<std::uint64_t>& first_vertex,
                std::vector<std::uint64_t>& first_index) {
  resize_on_huge_pages(first_vertex, rows + 1);
  resize_on_huge_pages(first_index, rows + 1);
  for_each_plane(planes, progress, count);
  for (std::size_t r = 0; r < rows; ++r) {
    first_vertex[r + 1] += first_vertex[r];
    first_index[r + 1] += first_index[r];
  }
  if (first_vertex[rows] > std::numeric_limits<std::uint32_t>::max() - 1)
    throw InvalidArgument("mesh: " + std::to_string(first_vertex[rows]) +
                          " vertices do not fit 32-bit indices; mesh a smaller volume");
}

}  // namespace voxfield::detail::mesh

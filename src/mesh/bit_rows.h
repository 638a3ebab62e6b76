// voxfield — a lattice's samples as rows of inside bits, for the meshers that run in Flying Edges'
// passes (internal to the mesh module; flying_edges.cpp, flying_dual.cpp).
//
// One bit per sample, 64 samples a word, a row (y, z) of `words()` words (nx / 64 + 1) whose bits
// past its last sample are zero. An edge crosses the surface where the bits of its
// two ends differ, so a row's x-, y- and z-edge crossings are XORs of whole words, and a crossing's
// place among its row's crossings — its number — is a population count.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "chunked_mesh.h"
#include "voxfield/interrupt.h"

namespace voxfield::detail::mesh {

// Set bits of a word: one POPCNT where the build has it (x86-64-v2, voxfield's default; other
// processors' popcount instructions). On the plain x86-64 baseline std::popcount compiles to a
// library call, so these dozen operations inline instead.
inline unsigned bit_count(std::uint64_t v) {
#if defined(__x86_64__) && !defined(__POPCNT__)
  v = v - (v >> 1 & 0x5555555555555555ull);
  v = (v & 0x3333333333333333ull) + (v >> 2 & 0x3333333333333333ull);
  v = (v + (v >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<unsigned>((v * 0x0101010101010101ull) >> 56);
#else
  return static_cast<unsigned>(std::popcount(v));
#endif
}

inline std::uint64_t low_bits(unsigned n) {  // n < 64
  return (std::uint64_t{1} << n) - 1;
}

// Bits x and x + 1 of a bit row (bit 0: x).
inline unsigned two_bits(const std::uint64_t* row, int x) {
  const std::size_t w = static_cast<std::size_t>(x) >> 6;
  const unsigned s = static_cast<unsigned>(x) & 63;
  std::uint64_t v = row[w] >> s;
  if (s == 63) v |= row[w + 1] << 1;
  return static_cast<unsigned>(v & 3);
}

// The crossings of a row's x-edges (bit x: the edge from x to x + 1).
inline void x_crossings(const std::uint64_t* b, std::size_t words, int nx, std::uint64_t* out) {
  for (std::size_t w = 0; w < words; ++w) {
    const std::uint64_t next = w + 1 < words ? b[w + 1] : 0;
    out[w] = b[w] ^ (b[w] >> 1 | next << 63);
  }
  // The last sample has no x-edge (its "neighbour" bit is the zero padding).
  out[static_cast<std::size_t>(nx - 1) >> 6] &= ~(std::uint64_t{1} << ((nx - 1) & 63));
}
// The crossings of the edges between two rows (bit x: the edge at x).
inline void differences(const std::uint64_t* a, const std::uint64_t* b, std::size_t words,
                        std::uint64_t* out) {
  for (std::size_t w = 0; w < words; ++w) out[w] = a[w] ^ b[w];
}
inline std::uint64_t population(const std::uint64_t* m, std::size_t words) {
  std::uint64_t n = 0;
  for (std::size_t w = 0; w < words; ++w) n += static_cast<std::uint64_t>(bit_count(m[w]));
  return n;
}

// K bit masks over one row with their running population counts: the number of bit x of mask k
// is base[k] plus the set bits before x. Mask k is the ranks' own (filled through mask(k)) unless
// borrow(k, row) points it at a row kept elsewhere.
class RowRanks {
 public:
  RowRanks(int masks, std::size_t words)
      : words_(words),
        bits_(static_cast<std::size_t>(masks) * words),
        before_(bits_.size()),
        base_(static_cast<std::size_t>(masks)),
        rows_(static_cast<std::size_t>(masks)) {
    for (int k = 0; k < masks; ++k) rows_[static_cast<std::size_t>(k)] = mask(k);
  }
  // rows_ may point into bits_: a copy would read the original's masks.
  RowRanks(const RowRanks&) = delete;
  RowRanks& operator=(const RowRanks&) = delete;
  std::uint64_t* mask(int k) { return bits_.data() + static_cast<std::size_t>(k) * words_; }
  // Mask k reads `row` (of the same words) until the next borrow.
  void borrow(int k, const std::uint64_t* row) { rows_[static_cast<std::size_t>(k)] = row; }
  void set_base(int k, std::uint64_t base) { base_[static_cast<std::size_t>(k)] = base; }
  std::uint64_t base(int k) const { return base_[static_cast<std::size_t>(k)]; }
  // After the masks are filled and their bases set: the running counts of each (from its base).
  void count() {
    for (std::size_t k = 0; k < base_.size(); ++k) {
      std::uint64_t sum = base_[k];
      for (std::size_t w = 0; w < words_; ++w) {
        before_[k * words_ + w] = sum;
        sum += bit_count(rows_[k][w]);
      }
    }
  }
  std::uint64_t id(int k, int x) const {
    const std::size_t kk = static_cast<std::size_t>(k), w = static_cast<std::size_t>(x) >> 6;
    return before_[kk * words_ + w] +
           bit_count(rows_[kk][w] & low_bits(static_cast<unsigned>(x) & 63));
  }
  // id(k, x) of masks 0 … K - 1 at once, whether bit x of each is set or not (where it is not,
  // the number the next set bit has): no branch per mask for callers that need most of them.
  template <std::size_t K>
  void ids_at(int x, std::array<std::uint64_t, K>& out) const {
    const std::size_t w = static_cast<std::size_t>(x) >> 6;
    const std::uint64_t below = low_bits(static_cast<unsigned>(x) & 63);
    for (std::size_t k = 0; k < K; ++k)
      out[k] = before_[k * words_ + w] + bit_count(rows_[k][w] & below);
  }

 private:
  std::size_t words_;
  std::vector<std::uint64_t> bits_, before_, base_;
  std::vector<const std::uint64_t*> rows_;
};

// Asks the cache for sample row (y, z) (0 <= y < n.y, 0 <= z < n.z) ahead of a writing pass's
// sparse reads around crossings, which the hardware does not prefetch (without this, one thread's
// marching cubes of a 256³ terrain spent a tenth of its time waiting for those loads).
inline void prefetch_row(const Lattice& lattice, int y, int z) {
  const float* row = lattice.values + static_cast<std::ptrdiff_t>(lattice.n.x) *
                                          (y + static_cast<std::ptrdiff_t>(lattice.n.y) * z);
  for (int x = 0; x < lattice.n.x; x += 16) __builtin_prefetch(row + x);  // 64-byte lines
}

// f(z) for every plane of the lattice, planes in parallel, one progress unit each; stops early
// and throws Cancelled when the operation is cancelled.
void for_each_plane(int planes, Progress& progress, const std::function<void(int z)>& f);

// Pass 2 of both Flying Edges meshers: sizes first_vertex and first_index to rows + 1 zeros, runs
// count(z) for every plane in parallel (one progress unit each), which puts each row r's vertex
// and index counts in first_vertex[r + 1] and first_index[r + 1], then turns them into prefix
// sums in place. Throws InvalidArgument when the vertices pass 32-bit indices, Cancelled when
// cancelled.
void count_rows(int planes, std::size_t rows, Progress& progress,
                const std::function<void(int z)>& count, std::vector<std::uint64_t>& first_vertex,
                std::vector<std::uint64_t>& first_index);

// Every sample of a dense lattice as an inside bit (pass 1 of both Flying Edges meshers).
class InsideBits {
 public:
  // Throws InvalidArgument naming the first NaN or infinite sample (its plane numbered from
  // `z_offset`: a slab's lattice names the whole one's planes), ResourceLimitError past the
  // memory limit, Cancelled when `progress` is cancelled (one unit per plane).
  InsideBits(const Lattice& lattice, Progress& progress, int z_offset = 0);
  std::size_t words() const { return words_; }
  const std::uint64_t* row(int y, int z) const {
    return bits_.data() + words_ * (static_cast<std::size_t>(y) +
                                    static_cast<std::size_t>(ny_) * static_cast<std::size_t>(z));
  }
  // Whether row (y, z) and its eight neighbours in y and z (those the lattice has) are all inside
  // or all outside alike: no edge between two of them crosses the surface, so no central
  // difference taken at one of the eight around a crossing reads row (y, z) — unless the crossing
  // is on an edge from them to a row further out, which the caller checks if it needs to.
  bool quiet_around(int y, int z) const {
    const int y0 = y > 0 ? y - 1 : y, z0 = z > 0 ? z - 1 : z;
    return quiet(y0, z0) && quiet(y0 + 1 < ny_ ? y0 + 1 : y0, z0) &&
           quiet(y0, static_cast<std::size_t>(z0) + 1 < planes_ ? z0 + 1 : z0) &&
           quiet(y0 + 1 < ny_ ? y0 + 1 : y0,
                 static_cast<std::size_t>(z0) + 1 < planes_ ? z0 + 1 : z0);
  }
  // Whether row (y, z) and the rows after it in y, in z and in both (those the lattice has) are
  // all inside or all outside alike: no edge starting on the row crosses the surface and no cell
  // of its cell row is crossed, so a pass may skip the row without looking at its words. (In a
  // scan, the rows through the air around the head: 37 % of the MRI's cell rows.)
  bool quiet(int y, int z) const {
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(ny_) * z;
    const std::uint8_t u = uniform_[r];
    if (u == kMixed) return false;
    const bool up_y = y + 1 < ny_, up_z = static_cast<std::size_t>(z) + 1 < planes_;
    const std::size_t plane = static_cast<std::size_t>(ny_);
    return (!up_y || uniform_[r + 1] == u) && (!up_z || uniform_[r + plane] == u) &&
           (!up_y || !up_z || uniform_[r + plane + 1] == u);
  }

 private:
  static constexpr std::uint8_t kMixed = 2;  // uniform_: else 0 (all outside) or 1 (all inside)
  std::size_t words_ = 0;
  int ny_ = 0;
  std::size_t planes_ = 0;
  std::vector<std::uint64_t> bits_;
  std::vector<std::uint8_t> uniform_;  // per row
};

}  // namespace voxfield::detail::mesh

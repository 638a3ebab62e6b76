// voxfield — the chunk partition, a chunk's sample block and the weld (see chunked_mesh.h).
#include "chunked_mesh.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

#include "voxfield/detail/vector_clones.h"
#include "voxfield/error.h"

namespace voxfield::detail::mesh {

ChunkGrid::ChunkGrid(Vec3i samples, int chunk_edge)
    : cells{samples.x - 1, samples.y - 1, samples.z - 1}, edge(chunk_edge) {
  for (int a = 0; a < 3; ++a) count[a] = (cells[a] + edge - 1) / edge;
}

Vec3i ChunkGrid::coord(std::int64_t i) const {
  const std::int64_t x = i % count.x, yz = i / count.x;
  return {static_cast<int>(x), static_cast<int>(yz % count.y), static_cast<int>(yz / count.y)};
}

Box3i ChunkGrid::cells_of(Vec3i chunk) const {
  Box3i b;
  for (int a = 0; a < 3; ++a) {
    b.begin[a] = chunk[a] * edge;
    b.end[a] = std::min(cells[a], b.begin[a] + edge);
  }
  return b;
}

int ChunkGrid::owner(int axis, int v) const {
  return std::min(v / edge, count[axis] - 1);
}

void Block::view(const Lattice& lattice) {
  lattice_ = &lattice;
  iso_ = static_cast<float>(lattice.iso);
  negate_ = lattice.sign < 0;
  lo_ = {0, 0, 0};
  hi_ = {lattice.n.x - 1, lattice.n.y - 1, lattice.n.z - 1};
  data_ = lattice.values;
  base_ = 0;
  sy_ = lattice.n.x;
  sz_ = sy_ * static_cast<std::ptrdiff_t>(lattice.n.y);
  signs_.clear();
  dy_ = 0;
}

void Block::view_planes(const Lattice& whole, const float* planes, int z_offset) {
  view(whole);
  data_ = planes;
  base_ = -sz_ * static_cast<std::ptrdiff_t>(z_offset);  // plane z_offset is planes[0]
}

bool Block::load(const Lattice& lattice, const Box3i& cells) {
  lattice_ = &lattice;
  iso_ = static_cast<float>(lattice.iso);
  negate_ = lattice.sign < 0;
  for (int a = 0; a < 3; ++a) {
    lo_[a] = std::max(cells.begin[a] - 1, 0);
    hi_[a] = std::min(cells.end[a] + 1, lattice.n[a] - 1);
  }
  if (lattice.values) {
    data_ = lattice.values;
    base_ = 0;
    sy_ = lattice.n.x;
    sz_ = sy_ * static_cast<std::ptrdiff_t>(lattice.n.y);
  } else {
    Box3i reads;
    for (int a = 0; a < 3; ++a) {
      reads.begin[a] = std::max(cells.begin[a] - 3, 0);
      reads.end[a] = std::min(cells.end[a] + 3, lattice.n[a]);
    }
    copy_.resize(static_cast<std::size_t>(reads.volume()));
    (*lattice.fill)(reads, copy_.data());
    data_ = copy_.data();
    sy_ = reads.end.x - reads.begin.x;
    sz_ = sy_ * (reads.end.y - reads.begin.y);
    base_ = -(reads.begin.x + sy_ * reads.begin.y + sz_ * reads.begin.z);
  }
  const std::size_t dx = static_cast<std::size_t>(hi_.x - lo_.x + 1);
  dy_ = static_cast<std::size_t>(hi_.y - lo_.y + 1);
  signs_.resize(dy_ * static_cast<std::size_t>(hi_.z - lo_.z + 1));
  std::uint8_t all = 0;
  std::uint8_t* signs = signs_.data();
  // Which signs a row holds, and whether it holds a NaN or an infinity (its exponent bits all
  // set): 32-bit flags OR-ed without an early exit, so the loop vectorises (bool flags and
  // std::isfinite kept it scalar, at about 2.5 ns a sample).
  const auto scan = [this, dx](const float* row, auto inside_above) {
    std::uint32_t in = 0, out = 0, bad = 0;
    const float iso = iso_;
    for (std::size_t i = 0; i < dx; ++i) {
      const float v = row[i];
      std::uint32_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      bad |= static_cast<std::uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
      const std::uint32_t inside =
          static_cast<std::uint32_t>(decltype(inside_above)::value ? v > iso : v < iso);
      in |= inside;
      out |= inside ^ 1u;
    }
    return std::array<std::uint32_t, 3>{in, out, bad};
  };
  for (int z = lo_.z; z <= hi_.z; ++z)
    for (int y = lo_.y; y <= hi_.y; ++y) {
      const float* row = this->row(lo_.x, y, z);
      const auto [in, out, nan] =
          negate_ ? scan(row, std::true_type{}) : scan(row, std::false_type{});
      if (nan)
        for (std::size_t i = 0; i < dx; ++i)
          if (!std::isfinite(row[i]))
            throw InvalidArgument("mesh: sample (" + std::to_string(lo_.x + static_cast<int>(i)) +
                                  ", " + std::to_string(y) + ", " + std::to_string(z) + ") is " +
                                  (std::isnan(row[i]) ? "NaN" : "infinite"));
      *signs = static_cast<std::uint8_t>(in | out << 1);
      all |= *signs++;
    }
  return all == 3;
}

std::array<double, 3> Block::gradient(int x, int y, int z) const {
  const Vec3i p{x, y, z};
  std::array<double, 3> g{};
  for (int a = 0; a < 3; ++a) {
    Vec3i lo = p, hi = p;
    if (p[a] > 0) --lo[a];
    if (p[a] < lattice_->n[a] - 1) ++hi[a];
    const double span = (hi[a] - lo[a]) * lattice_->spacing[static_cast<std::size_t>(a)];
    g[static_cast<std::size_t>(a)] =
        (static_cast<double>(s(hi.x, hi.y, hi.z)) - s(lo.x, lo.y, lo.z)) / span;
  }
  return g;
}

std::array<double, 3> Block::one_sided_gradient(int x, int y, int z) const {
  const Vec3i p{x, y, z};
  std::array<double, 3> g{};
  for (int a = 0; a < 3; ++a) {
    const int n = lattice_->n[a];
    auto at = [&](int offset) {
      Vec3i q = p;
      q[a] = std::clamp(p[a] + offset, 0, n - 1);
      return static_cast<double>(s(q.x, q.y, q.z));
    };
    const double h = lattice_->spacing[static_cast<std::size_t>(a)];
    const double s0 = at(0);
    const bool has_left = p[a] > 0, has_right = p[a] < n - 1;
    double d;
    if (!has_left) {
      d = at(1) - s0;
    } else if (!has_right) {
      d = s0 - at(-1);
    } else {
      const double left = s0 - at(-1), right = at(1) - s0;
      const double curve_left =
          p[a] > 1 ? std::abs(left - (at(-1) - at(-2))) : std::abs(right - left);
      const double curve_right =
          p[a] < n - 2 ? std::abs((at(2) - at(1)) - right) : std::abs(right - left);
      d = curve_left <= curve_right ? left : right;
    }
    g[static_cast<std::size_t>(a)] = d / h;
  }
  return g;
}

void ChunkPart::clear() {
  positions.clear();
  normals.clear();
  keys.clear();
  sources.clear();
  colors.clear();
  owned.clear();
  shared.clear();
  indices.clear();
}

std::uint32_t ChunkPart::add(const std::array<double, 3>& position, std::array<double, 3> normal,
                             std::uint64_t key, std::uint64_t source, bool is_owned,
                             bool is_shared) {
  positions.push_back({static_cast<float>(position[0]), static_cast<float>(position[1]),
                       static_cast<float>(position[2])});
  normals.push_back(unit_normal(normal));
  keys.push_back(key);
  sources.push_back(source);
  owned.push_back(is_owned);
  shared.push_back(is_shared);
  return static_cast<std::uint32_t>(positions.size() - 1);
}

VOXFIELD_AVX2_CLONE void unit_normals(const double* __restrict x, const double* __restrict y,
                                      const double* __restrict z, std::size_t count,
                                      std::array<float, 3>* __restrict out) {
  constexpr double kMax = std::numeric_limits<double>::max();
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
  for (std::size_t i = 0; i < count; ++i) {
    const double length = std::sqrt(x[i] * x[i] + y[i] * y[i] + z[i] * z[i]);
    const bool unit = length > 0 && length <= kMax;  // unit_normal's test (NaN fails both)
    const double inverse = 1 / length;               // unit_normal's arithmetic
    out[i] = {unit ? static_cast<float>(x[i] * inverse) : 0.0f,
              unit ? static_cast<float>(y[i] * inverse) : 0.0f,
              unit ? static_cast<float>(z[i] * inverse) : 1.0f};
  }
}

}  // namespace voxfield::detail::mesh

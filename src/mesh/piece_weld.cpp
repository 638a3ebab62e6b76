// voxfield — one piece's share of the joined mesh (mesh_pieces.h: PieceWeld). The chunked
// mesher's weld (weld.cpp) numbers owned vertices chunk by chunk, finds borrowed ones by their
// element's key and numbers orphans (vertices no owner used) after every owned one, in the order
// of their first user. A piece holds a run of chunk layers, so its owned vertices are one run of
// those numbers and its claimed orphans another; what it borrows across its end layers, and the
// orphans it shares with the piece before, are the only numbers it must learn from others. A
// vertex's element lies within one cell of every chunk that uses it, and every layer but the last
// is at least two cells deep (the chunk edge), so its owner and users span at most two adjacent
// layers: neighbours suffice.
#include <algorithm>
#include <limits>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "chunked_mesh.h"
#include "piece_parts.h"
#include "voxfield/error.h"
#include "voxfield/mesh_pieces.h"

namespace voxfield {

namespace {

// A vertex of a chunk, as the weld has placed it: its kind and its slot within the kind.
constexpr std::uint64_t kKindShift = 62;
constexpr std::uint64_t kOwned = 0, kOrphan = 1, kForeign = 2;
constexpr std::uint64_t kUnresolved = std::numeric_limits<std::uint64_t>::max();
constexpr std::uint64_t kSlotMask = (std::uint64_t{1} << kKindShift) - 1;
constexpr std::uint64_t kUnset = std::numeric_limits<std::uint64_t>::max();
// The largest vertex number join_mesh_pieces gives (its indices are 32-bit, and one value is
// its "unresolved" mark).
constexpr std::uint64_t kMaxNumber = std::numeric_limits<std::uint32_t>::max() - 1;

std::uint64_t code(std::uint64_t kind, std::uint64_t slot) {
  return kind << kKindShift | slot;
}

// Where a vertex's data lives: chunk and index within it.
struct Source {
  std::uint32_t chunk = 0, vertex = 0;
};

}  // namespace

struct PieceWeld::Impl {
  detail::mesh::PieceParts piece;
  std::size_t per_layer = 0;
  std::vector<std::vector<std::uint64_t>> codes;  // per chunk, per vertex
  std::uint64_t owned = 0;
  std::vector<Source> orphans;  // claimed, numbered in this order
  struct Foreign {
    std::uint64_t number;
    Source source;
  };
  std::vector<Foreign> foreign;
  std::unordered_map<std::uint64_t, std::uint64_t> foreign_slot;  // key -> slot in `foreign`
  std::uint64_t first_vertex = kUnset, first_orphan = kUnset;
  bool colored = false;

  template <class Fn>
  void each_vertex(Fn&& fn) {
    for (std::size_t c = 0; c < codes.size(); ++c)
      for (std::size_t i = 0; i < codes[c].size(); ++i) fn(c, i, codes[c][i]);
  }
};

PieceWeld::PieceWeld(std::span<const std::uint8_t> bytes)
    : PieceWeld(detail::mesh::decode_piece(bytes, 0, "PieceWeld")) {}

PieceWeld::PieceWeld(const ScalarVolume& frame, int planes_z0, int plane_count, const float* planes,
                     const MeshOptions& options, int first_layer, int end_layer)
    : PieceWeld(detail::mesh::mesh_piece_parts(frame, planes_z0, plane_count, planes, options,
                                               first_layer, end_layer)) {}

PieceWeld::PieceWeld(detail::mesh::PieceParts&& piece) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.piece = std::move(piece);
  const detail::mesh::ChunkGrid grid(m.piece.samples, m.piece.chunk_edge);
  m.per_layer = static_cast<std::size_t>(grid.count.x) * static_cast<std::size_t>(grid.count.y);
  const auto& parts = m.piece.parts;
  for (const auto& p : parts) m.colored |= !p.colors.empty();
  if (m.colored)
    for (const auto& p : parts)
      if (p.colors.empty() && !p.positions.empty())
        throw InvalidArgument("PieceWeld: some chunks have colours and some do not");
  // Owned vertices numbered chunk by chunk; the shared ones found by key for their borrowers.
  m.codes.resize(parts.size());
  std::unordered_map<std::uint64_t, std::uint64_t> by_key;
  for (std::size_t c = 0; c < parts.size(); ++c) {
    m.codes[c].assign(parts[c].positions.size(), kUnresolved);
    for (std::size_t i = 0; i < parts[c].positions.size(); ++i) {
      if (!parts[c].owned[i]) continue;
      if (parts[c].shared[i]) by_key.emplace(parts[c].keys[i], m.owned);
      m.codes[c][i] = code(kOwned, m.owned++);
    }
  }
  m.each_vertex([&](std::size_t c, std::size_t i, std::uint64_t& v) {
    if (v != kUnresolved) return;
    const auto it = by_key.find(parts[c].keys[i]);
    if (it != by_key.end()) v = code(kOwned, it->second);
  });
}

PieceWeld::~PieceWeld() = default;
PieceWeld::PieceWeld(PieceWeld&&) noexcept = default;
PieceWeld& PieceWeld::operator=(PieceWeld&&) noexcept = default;

int PieceWeld::first_layer() const {
  return impl_->piece.first_layer;
}
int PieceWeld::end_layer() const {
  return impl_->piece.end_layer;
}
std::uint64_t PieceWeld::owned_vertices() const {
  return impl_->owned;
}

std::vector<WeldKey> PieceWeld::lend(std::uint64_t first_vertex) {
  Impl& m = *impl_;
  m.first_vertex = first_vertex;
  std::vector<WeldKey> out;
  const std::size_t chunks = m.piece.parts.size();
  const auto lend_chunk = [&](std::size_t c) {
    const auto& p = m.piece.parts[c];
    for (std::size_t i = 0; i < p.positions.size(); ++i)
      if (p.owned[i] && p.shared[i])
        out.push_back({p.keys[i], first_vertex + (m.codes[c][i] & kSlotMask)});
  };
  // The first layer's chunks and the last's (one layer when the piece holds one).
  const std::size_t first_end = std::min(chunks, m.per_layer);
  for (std::size_t c = 0; c < first_end; ++c) lend_chunk(c);
  for (std::size_t c = std::max(first_end, chunks - first_end); c < chunks; ++c) lend_chunk(c);
  return out;
}

void PieceWeld::borrow(std::span<const WeldKey> keys) {
  Impl& m = *impl_;
  std::unordered_map<std::uint64_t, std::uint64_t> number;
  number.reserve(keys.size());
  for (const WeldKey& k : keys) number.emplace(k.key, k.number);
  m.each_vertex([&](std::size_t c, std::size_t i, std::uint64_t& v) {
    if (v != kUnresolved) return;
    const std::uint64_t key = m.piece.parts[c].keys[i];
    const auto it = number.find(key);
    if (it == number.end()) return;
    const auto [slot, added] = m.foreign_slot.emplace(key, m.foreign.size());
    if (added)
      m.foreign.push_back(
          {it->second, {static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i)}});
    v = code(kForeign, slot->second);
  });
}

std::vector<std::uint64_t> PieceWeld::orphan_keys() const {
  std::vector<std::uint64_t> keys;
  std::unordered_set<std::uint64_t> seen;
  impl_->each_vertex([&](std::size_t c, std::size_t i, std::uint64_t v) {
    const std::uint64_t key = impl_->piece.parts[c].keys[i];
    if (v == kUnresolved && seen.insert(key).second) keys.push_back(key);
  });
  return keys;
}

void PieceWeld::claim_orphans(std::span<const std::uint64_t> taken_before) {
  Impl& m = *impl_;
  const std::unordered_set<std::uint64_t> taken(taken_before.begin(), taken_before.end());
  std::unordered_map<std::uint64_t, std::uint64_t> slot_of;
  m.each_vertex([&](std::size_t c, std::size_t i, std::uint64_t& v) {
    if (v != kUnresolved) return;
    const std::uint64_t key = m.piece.parts[c].keys[i];
    if (taken.count(key)) return;  // the piece before numbers it
    const auto [slot, added] = slot_of.emplace(key, m.orphans.size());
    if (added) m.orphans.push_back({static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i)});
    v = code(kOrphan, slot->second);
  });
}

std::uint64_t PieceWeld::claimed_orphans() const {
  return impl_->orphans.size();
}

std::vector<WeldKey> PieceWeld::number_orphans(std::uint64_t first_orphan) {
  Impl& m = *impl_;
  m.first_orphan = first_orphan;
  std::vector<WeldKey> out;
  out.reserve(m.orphans.size());
  for (std::size_t j = 0; j < m.orphans.size(); ++j)
    out.push_back({m.piece.parts[m.orphans[j].chunk].keys[m.orphans[j].vertex], first_orphan + j});
  return out;
}

Mesh PieceWeld::part() const {
  const Impl& m = *impl_;
  const auto& parts = m.piece.parts;
  const std::uint64_t orphans = m.orphans.size();
  const std::uint64_t total = m.owned + orphans + m.foreign.size();
  if (total > kMaxNumber)
    throw InvalidArgument("PieceWeld: the piece's " + std::to_string(total) +
                          " vertices do not fit 32-bit indices");
  std::size_t indices = 0;
  for (const auto& p : parts) indices += p.indices.size();
  Mesh mesh;
  mesh.positions.resize(total);
  mesh.normals.resize(total);
  if (m.colored) mesh.colors.resize(total);
  mesh.indices.reserve(indices);
  const auto put = [&](std::uint64_t at, Source s) {
    const auto& p = parts[s.chunk];
    mesh.positions[at] = p.positions[s.vertex];
    mesh.normals[at] = p.normals[s.vertex];
    if (m.colored) mesh.colors[at] = p.colors[s.vertex];
  };
  const auto local = [&](std::uint64_t v) {
    const std::uint64_t slot = v & kSlotMask;
    switch (v >> kKindShift) {
      case kOwned:
        return slot;
      case kOrphan:
        return m.owned + slot;
      default:
        return m.owned + orphans + slot;
    }
  };
  for (std::size_t c = 0; c < parts.size(); ++c) {
    for (std::size_t i = 0; i < parts[c].positions.size(); ++i) {
      if (m.codes[c][i] == kUnresolved)
        throw InvalidArgument("PieceWeld: chunk " + std::to_string(c) + "'s vertex " +
                              std::to_string(i) + " was never numbered (a step missed)");
      if (parts[c].owned[i])
        put(m.codes[c][i] & kSlotMask,
            {static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i)});
    }
    for (const std::uint32_t v : parts[c].indices)
      mesh.indices.push_back(static_cast<std::uint32_t>(local(m.codes[c][v])));
  }
  for (std::uint64_t j = 0; j < orphans; ++j) put(m.owned + j, m.orphans[j]);
  for (std::uint64_t f = 0; f < m.foreign.size(); ++f)
    put(m.owned + orphans + f, m.foreign[f].source);
  return mesh;
}

std::vector<std::uint32_t> PieceWeld::global() const {
  const Impl& m = *impl_;
  if (m.first_vertex == kUnset || (!m.orphans.empty() && m.first_orphan == kUnset))
    throw InvalidArgument("PieceWeld: the piece's first vertex or orphan number is not known yet");
  std::vector<std::uint32_t> numbers;
  numbers.reserve(m.owned + m.orphans.size() + m.foreign.size());
  const auto add = [&](std::uint64_t n) {
    if (n > kMaxNumber)
      throw InvalidArgument("PieceWeld: vertex number " + std::to_string(n) +
                            " does not fit 32-bit indices; mesh a smaller volume");
    numbers.push_back(static_cast<std::uint32_t>(n));
  };
  for (std::uint64_t o = 0; o < m.owned; ++o) add(m.first_vertex + o);
  for (std::uint64_t j = 0; j < m.orphans.size(); ++j) add(m.first_orphan + j);
  for (const auto& f : m.foreign) add(f.number);
  return numbers;
}

}  // namespace voxfield

// A mesh built in pieces, each from only the sample planes it reads (mesh_pieces.h), against the
// chunked mesher over the whole lattice: equal arrays, whatever the cut; damaged or mismatched
// pieces refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <span>

#include "../fuzz/weld_in_turn.h"
#include "error_text.h"
#include "mesh_compare.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/mesh_pieces.h"
#include "voxfield/parallel.h"
#include "wave_volume.h"

using namespace voxfield;

namespace {

constexpr Mesher kPieceMeshers[] = {Mesher::kMarchingCubes, Mesher::kSurfaceNets,
                                    Mesher::kDualContouring};

// The planes [z0, z1) of a volume, copied: a piece sees nothing else.
std::vector<float> copied_planes(const ScalarVolume& vol, int z0, int z1) {
  const std::size_t plane = static_cast<std::size_t>(vol.size.x) * vol.size.y;
  return {vol.values + plane * static_cast<std::size_t>(z0),
          vol.values + plane * static_cast<std::size_t>(z1)};
}

std::vector<std::uint8_t> piece_of(const ScalarVolume& vol, const MeshOptions& o, int first,
                                   int end) {
  const auto [z0, z1] = mesh_layer_planes(vol.size, o.chunk_edge, first, end);
  const std::vector<float> planes = copied_planes(vol, z0, z1);
  ScalarVolume frame = vol;
  frame.values = nullptr;
  return mesh_piece(frame, z0, z1 - z0, planes.data(), o, first, end);
}

Mesh join_all(const std::vector<std::vector<std::uint8_t>>& pieces) {
  std::vector<std::span<const std::uint8_t>> spans(pieces.begin(), pieces.end());
  return join_mesh_pieces(spans);
}

void expect_equal_mesh_arrays(const Mesh& got, const Mesh& want) {
  ASSERT_EQ(got.positions.size(), want.positions.size());
  EXPECT_TRUE(got.positions == want.positions);
  EXPECT_TRUE(got.normals == want.normals);
  EXPECT_TRUE(got.colors == want.colors);
  EXPECT_TRUE(got.indices == want.indices);
}

}  // namespace

// Cuts of the layers into runs of every kind — one piece, a layer each, uneven runs — give the
// chunked mesher's arrays over the whole lattice, element for element, for every mesher, both
// inside conventions, an anisotropic frame away from the origin, and last layers of 7 cells, of a
// whole 13 and of 1.
TEST(MeshPieces, JoinedPiecesEqualTheWholeLatticesChunks) {
  const Vec3i n{21, 17, 40};  // 39 cells along z: layers of 8 leave a last one of 7
  const std::vector<float> v = test::wave_volume(n, 5, 4, 0.7, true);
  ScalarVolume vol{n, v.data()};
  vol.spacing_units = {0.5, 0.75, 1.3};
  vol.origin_units = {-3.1, 2.0, 0.7};
  for (Mesher m : kPieceMeshers)
    for (bool above : {false, true})
      for (int edge : {4, 8, 13, 19}) {
        SCOPED_TRACE(std::string(mesher_name(m)) + (above ? " above" : "") + " chunk edge " +
                     std::to_string(edge));
        MeshOptions o;
        o.algorithm = m;
        o.inside_above = above;
        o.chunk_edge = edge;
        const Mesh want = MeshChunks(vol, o).merged();
        ASSERT_GT(want.triangle_count(), 100u);
        const int layers = mesh_chunk_layers(n, edge);
        EXPECT_EQ(layers, (n.z - 1 + edge - 1) / edge);
        // One piece; one per layer (given in reverse: the order does not matter); uneven runs.
        std::vector<std::vector<std::uint8_t>> whole{piece_of(vol, o, 0, layers)}, each, runs;
        for (int k = layers - 1; k >= 0; --k) each.push_back(piece_of(vol, o, k, k + 1));
        for (int k = 0; k < layers;) {
          const int end = std::min(layers, k + 1 + k % 3);
          runs.push_back(piece_of(vol, o, k, end));
          k = end;
        }
        expect_equal_mesh_arrays(join_all(whole), want);
        expect_equal_mesh_arrays(join_all(each), want);
        ThreadLimit one(1);
        expect_equal_mesh_arrays(join_all(runs), want);
        // Welded share by share, each learning only from its neighbours (PieceWeld).
        const auto in_order = [](const std::vector<std::vector<std::uint8_t>>& p) {
          return std::vector<std::span<const std::uint8_t>>(p.begin(), p.end());
        };
        std::vector<std::span<const std::uint8_t>> each_in_order = in_order(each);
        std::reverse(each_in_order.begin(), each_in_order.end());
        expect_equal_mesh_arrays(test::weld_in_turn(in_order(whole)), want);
        expect_equal_mesh_arrays(test::weld_in_turn(each_in_order), want);
        expect_equal_mesh_arrays(test::weld_in_turn(in_order(runs)), want);
      }
}

// A flat surface in one layer: the other layers' chunks have no vertices, and their parts travel
// and join empty (UBSan caught a copy of no bytes into an empty part's null array).
TEST(MeshPieces, ChunksWithoutSurfaceJoin) {
  const Vec3i n{9, 8, 30};
  std::vector<float> v(static_cast<std::size_t>(n.x) * n.y * n.z);
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = static_cast<float>(static_cast<double>(i / 72) - 13.5);  // z - 13.5
  const ScalarVolume vol{n, v.data()};
  for (Mesher m : kPieceMeshers) {
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 4;
    std::vector<std::vector<std::uint8_t>> each;
    for (int k = 0; k < mesh_chunk_layers(n, 4); ++k) each.push_back(piece_of(vol, o, k, k + 1));
    const Mesh want = MeshChunks(vol, o).merged();
    ASSERT_GT(want.triangle_count(), 0u);
    expect_equal_mesh_arrays(join_all(each), want);
  }
}

// What a run of layers reads: three planes before its cells to two past its last corner, clipped
// to the lattice; a piece given fewer planes is refused before meshing.
TEST(MeshPieces, PlanesAreWhatTheLayersReadAndNoFewer) {
  const Vec3i n{9, 9, 40};
  EXPECT_EQ(mesh_layer_planes(n, 8, 0, 1), std::make_pair(0, 11));
  EXPECT_EQ(mesh_layer_planes(n, 8, 1, 3), std::make_pair(5, 27));
  EXPECT_EQ(mesh_layer_planes(n, 8, 4, 5), std::make_pair(29, 40));
  for (const auto& [first, end] : {std::pair{-1, 1}, {2, 2}, {3, 1}, {0, 6}})
    EXPECT_THROW(mesh_layer_planes(n, 8, first, end), InvalidArgument) << first << ", " << end;
  const std::vector<float> v = test::wave_volume(n, 6, 4, 0.7, true);
  ScalarVolume frame{n, nullptr};
  MeshOptions o;
  o.chunk_edge = 8;
  const std::size_t plane = 81;
  // Layers 1..2 read planes 5..26: one plane short on either side is refused.
  EXPECT_NO_THROW(mesh_piece(frame, 5, 22, v.data() + 5 * plane, o, 1, 3));
  const std::string low =
      test::error_of([&] { mesh_piece(frame, 6, 21, v.data() + 6 * plane, o, 1, 3); });
  EXPECT_NE(low.find("read sample planes [5, 27), the piece holds [6, 27)"), std::string::npos)
      << low;
  EXPECT_THROW(mesh_piece(frame, 5, 21, v.data() + 5 * plane, o, 1, 3), InvalidArgument);
  EXPECT_THROW(mesh_piece(frame, 5, 22, nullptr, o, 1, 3), InvalidArgument);
  // A NaN sample is named by its place in the whole lattice.
  std::vector<float> bad(v.begin() + 5 * static_cast<std::ptrdiff_t>(plane),
                         v.begin() + 27 * static_cast<std::ptrdiff_t>(plane));
  bad[(20 - 5) * plane + 4 * 9 + 3] = std::nanf("");
  const std::string nan = test::error_of([&] { mesh_piece(frame, 5, 22, bad.data(), o, 1, 3); });
  EXPECT_NE(nan.find("(3, 4, 20)"), std::string::npos) << nan;
}

// Damaged, mismatched, overlapping and missing pieces are refused, naming the piece and the cause.
TEST(MeshPieces, DamagedOrMismatchedPiecesAreRefusedByName) {
  const Vec3i n{12, 11, 20};
  const std::vector<float> v = test::wave_volume(n, 7, 4, 0.7, true);
  const ScalarVolume vol{n, v.data()};
  MeshOptions o;
  o.chunk_edge = 6;  // 19 cells: layers 0..3
  const std::vector<std::uint8_t> a = piece_of(vol, o, 0, 2), b = piece_of(vol, o, 2, 4);
  ASSERT_NO_THROW(join_all({a, b}));
  const auto refused = [](const std::vector<std::vector<std::uint8_t>>& pieces,
                          const std::string& words) {
    const std::string text = test::error_of([&] { join_all(pieces); });
    EXPECT_NE(text.find(words), std::string::npos) << "wanted '" << words << "' in: " << text;
  };
  refused({a}, "no piece holds chunk layer 2 of 4");
  refused({a, b, piece_of(vol, o, 1, 2)}, "piece 2 (byte");
  refused({a, b, piece_of(vol, o, 1, 2)}, "chunk layer 1 is in piece 0 too");
  MeshOptions other = o;
  other.iso = 0.25;
  refused({a, piece_of(vol, other, 2, 4)}, "piece 1 (byte");
  refused({a, piece_of(vol, other, 2, 4)}, "another lattice or with other options");
  refused({}, "no pieces");
  // Every prefix of a piece is refused (a piece cut short in transit); so are extra bytes.
  for (std::size_t cut = 0; cut < b.size(); cut += 1 + cut / 7) {
    const std::vector<std::uint8_t> short_b(b.begin(),
                                            b.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_THROW(join_all({a, short_b}), InvalidArgument) << "cut at " << cut;
  }
  std::vector<std::uint8_t> longer = b;
  longer.push_back(0);
  refused({a, longer}, "bytes past its last chunk");
  std::vector<std::uint8_t> marker = b;
  marker[0] = 'W';
  refused({a, marker}, "not a voxfield mesh piece");
  // An index past its chunk's vertices: the last four bytes are the last chunk's last index.
  std::vector<std::uint8_t> index = b;
  for (std::size_t k = index.size() - 4; k < index.size(); ++k) index[k] = 0xff;
  refused({a, index}, "an index past the chunk's vertices");
  // Forged headers that agree with each other: a lattice whose chunks the bytes cannot hold
  // (2^64 chunks in all: the count must not wrap), or past 2^30 samples along an axis.
  const auto forged = [&](std::vector<std::uint8_t> p, Vec3i samples, std::int32_t edge,
                          std::int32_t first, std::int32_t end) {
    for (int k = 0; k < 3; ++k)  // after the marker, version and byte order
      std::memcpy(p.data() + 12 + 4 * k, &samples[k], 4);
    std::memcpy(p.data() + 72, &edge, 4);   // after the lattice's origin and spacing
    std::memcpy(p.data() + 91, &first, 4);  // after the algorithm, iso and flags
    std::memcpy(p.data() + 95, &end, 4);
    return p;
  };
  const Vec3i huge{(1 << 23) + 1, (1 << 23) + 1, (1 << 21) + 1};
  refused({forged(a, huge, 2, 0, 1), forged(b, huge, 2, 1, 1 << 20)}, "more than its bytes hold");
  refused({forged(a, {1 << 30 | 1, 8, 8}, 4, 0, 1)}, "a lattice size outside 2..2^30");
  EXPECT_THROW(mesh_chunk_layers({(1 << 30) + 1, 4, 4}, 4), InvalidArgument);
  // Random bytes flipped: refused or joined, never a crash (ASan and UBSan watch this in CI).
  std::mt19937 rng(9);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<std::uint8_t> flipped = b;
    flipped[rng() % flipped.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
    try {
      join_all({a, flipped});
    } catch (const InvalidArgument&) {
    } catch (const ResourceLimitError&) {
    }
  }
}

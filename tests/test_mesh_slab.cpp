// Slabs of sample planes meshed by marching cubes, surface nets and dual contouring, each from only
// the planes it reads (mesh_slab.h), against mesh_volume over the whole lattice: the slabs' owned
// vertices and triangles laid end to end are its arrays bit for bit, whatever the cuts; bad slabs
// and planes refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "error_text.h"
#include "voxfield/error.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/parallel.h"
#include "wave_volume.h"

using namespace voxfield;

namespace {

// Slab [z0, z1) meshed from a copy of exactly the planes it reads (ASan catches a read past them).
MeshSlab slab_of(const ScalarVolume& vol, const MeshOptions& o, int z0, int z1) {
  const auto [p0, p1] = mesh_slab_planes(vol.size.z, z0, z1, o.algorithm);
  const std::size_t plane = static_cast<std::size_t>(vol.size.x) * vol.size.y;
  const std::vector<float> planes(vol.values + plane * static_cast<std::size_t>(p0),
                                  vol.values + plane * static_cast<std::size_t>(p1));
  ScalarVolume frame = vol;
  frame.values = nullptr;
  return mesh_slab(frame, p0, p1 - p0, planes.data(), o, z0, z1);
}

// The slabs cut at `cuts` (0 = c0 < c1 < ... < ck = n.z) laid end to end, as the ranks of
// voxfield-mpi lay them: owned vertices in order, triangles numbered by MeshSlab::number.
Mesh laid_end_to_end(const ScalarVolume& vol, const MeshOptions& o, const std::vector<int>& cuts) {
  Mesh all;
  std::optional<MeshSlab> before;
  const bool dual = o.algorithm != Mesher::kMarchingCubes;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const MeshSlab s = slab_of(vol, o, cuts[k], cuts[k + 1]);
    EXPECT_EQ(s.lent_from_before, dual);
    const std::size_t lent = s.part.positions.size() - s.owned_vertices;
    // The vertices a slab computes that its neighbour owns are the neighbour's, bit for bit, and
    // as many as the neighbour's seam says (an MPI rank's seam with its neighbour): marching cubes
    // lends the next slab's first plane (checked from the next slab), the dual meshers the slab
    // before's last cell plane.
    if (before) {
      const MeshSlab& lender = dual ? *before : s;
      const MeshSlab& user = dual ? s : *before;
      const std::size_t used = user.part.positions.size() - user.owned_vertices;
      const std::uint64_t seam = dual ? lender.last_plane_vertices : lender.first_plane_vertices;
      EXPECT_EQ(used, seam);
      EXPECT_LE(seam, lender.owned_vertices);
      if (seam > lender.owned_vertices) return all;
      const auto from = static_cast<std::ptrdiff_t>(dual ? lender.owned_vertices - seam : 0);
      const auto at = static_cast<std::ptrdiff_t>(user.owned_vertices);
      EXPECT_TRUE(std::equal(user.part.positions.begin() + at, user.part.positions.end(),
                             lender.part.positions.begin() + from));
      EXPECT_TRUE(std::equal(user.part.normals.begin() + at, user.part.normals.end(),
                             lender.part.normals.begin() + from));
    } else if (dual) {
      EXPECT_EQ(lent, 0u);  // the first slab borrows nothing
    }
    const std::size_t first = all.positions.size();
    // Its triangles use its own vertices and the lent ones, nothing else.
    for (const std::uint32_t i : s.part.indices) EXPECT_LT(i, s.part.positions.size());
    if (!dual && k + 2 == cuts.size()) {
      EXPECT_EQ(lent, 0u);  // the last slab lends nothing
    }
    all.positions.insert(all.positions.end(), s.part.positions.begin(),
                         s.part.positions.begin() + static_cast<std::ptrdiff_t>(s.owned_vertices));
    all.normals.insert(all.normals.end(), s.part.normals.begin(),
                       s.part.normals.begin() + static_cast<std::ptrdiff_t>(s.owned_vertices));
    for (const std::uint32_t i : s.part.indices)
      all.indices.push_back(static_cast<std::uint32_t>(s.number(i, first)));
    EXPECT_TRUE(s.part.colors.empty());
    before = s;
  }
  return all;
}

void expect_same_arrays(const Mesh& got, const Mesh& want) {
  ASSERT_EQ(got.positions.size(), want.positions.size());
  EXPECT_TRUE(got.positions == want.positions);
  EXPECT_TRUE(got.normals == want.normals);
  EXPECT_TRUE(got.indices == want.indices);
}

}  // namespace

// Every kind of cut — one slab, a plane each, uneven runs, a last slab of the top plane alone —
// gives mesh_volume's arrays, for both inside conventions, an anisotropic frame away from the
// origin, an iso through many samples (ties), and any thread count.
TEST(MeshSlab, SlabsLaidEndToEndAreTheWholeLatticesMesh) {
  const Vec3i n{23, 17, 29};
  const std::vector<float> v = test::wave_volume(n, 11, 4, 0.7, true);
  ScalarVolume vol{n, v.data()};
  vol.spacing_units = {0.5, 0.75, 1.3};
  vol.origin_units = {-3.1, 2.0, 0.7};
  std::vector<float> rounded(v);  // many samples exactly at the iso value 0
  for (float& s : rounded) s = static_cast<float>(std::round(s * 2) / 2);
  const ScalarVolume ties{n, rounded.data()};
  // A ball in air: most rows, and whole planes at both ends, are quiet (all outside, the passes
  // skip them), slabs' first and last planes among them.
  std::vector<float> ball(v.size());
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x)
        ball[static_cast<std::size_t>(x + n.x * (y + n.y * z))] =
            static_cast<float>(std::hypot(x - 11.3, y - 8.2, z - 14.6) - 6.4);
  const ScalarVolume in_air{n, ball.data()};
  for (const ScalarVolume* volume : std::vector<const ScalarVolume*>{&vol, &ties, &in_air})
    for (bool above : {false, true})
      for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
        SCOPED_TRACE(std::string(volume == &vol    ? "waves"
                                 : volume == &ties ? "ties"
                                                   : "ball") +
                     (above ? " above " : " ") + mesher_name(m));
        MeshOptions o;
        o.inside_above = above;
        o.algorithm = m;
        const Mesh want = mesh_volume(*volume, o);
        ASSERT_GT(want.triangle_count(), 200u);
        std::vector<int> each, runs{0};
        for (int z = 0; z <= n.z; ++z) each.push_back(z);
        for (int z = 0; z < n.z;) runs.push_back(z = std::min(n.z, z + 1 + z % 4));
        expect_same_arrays(laid_end_to_end(*volume, o, {0, n.z}), want);
        expect_same_arrays(laid_end_to_end(*volume, o, each), want);
        expect_same_arrays(laid_end_to_end(*volume, o, runs), want);
        expect_same_arrays(laid_end_to_end(*volume, o, {0, 1, 2, n.z - 2, n.z - 1, n.z}), want);
        ThreadLimit one(1);
        expect_same_arrays(laid_end_to_end(*volume, o, {0, 9, 10, 20, n.z}), want);
      }
}

// The smallest lattice along z (2 planes: one cell plane) cut after its first plane.
TEST(MeshSlab, TwoPlanes) {
  const Vec3i n{9, 8, 2};
  const std::vector<float> v = test::wave_volume(n, 3, 3, 0.9, false);
  const ScalarVolume vol{n, v.data()};
  const Mesh want = mesh_volume(vol, {});
  ASSERT_GT(want.triangle_count(), 0u);
  expect_same_arrays(laid_end_to_end(vol, {}, {0, 1, 2}), want);
  expect_same_arrays(laid_end_to_end(vol, {}, {0, 2}), want);
  MeshOptions sn;
  sn.algorithm = Mesher::kSurfaceNets;
  expect_same_arrays(laid_end_to_end(vol, sn, {0, 1, 2}), mesh_volume(vol, sn));
}

TEST(MeshSlab, BadSlabsPlanesAndOptionsAreRefused) {
  const Vec3i n{9, 8, 12};
  std::vector<float> v = test::wave_volume(n, 5, 3, 0.9, false);
  ScalarVolume frame{n, nullptr};
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  const MeshOptions o;
  const auto refused = [&](int z0, int count, const float* planes, const MeshOptions& opts, int b,
                           int e, const char* words) {
    SCOPED_TRACE(words);
    EXPECT_THROW((void)mesh_slab(frame, z0, count, planes, opts, b, e), InvalidArgument);
    EXPECT_NE(
        test::error_of([&] { (void)mesh_slab(frame, z0, count, planes, opts, b, e); }).find(words),
        std::string::npos)
        << test::error_of([&] { (void)mesh_slab(frame, z0, count, planes, opts, b, e); });
  };
  refused(0, n.z, v.data(), o, 4, 4, "are not a slab");
  refused(0, n.z, v.data(), o, -1, 3, "are not a slab");
  refused(0, n.z, v.data(), o, 3, 13, "are not a slab");
  // Slab [4, 6) reads [3, 9).
  refused(4, 5, v.data() + 4 * plane, o, 4, 6, "read sample planes [3, 9), the slab holds [4, 9)");
  refused(3, 5, v.data() + 3 * plane, o, 4, 6, "read sample planes [3, 9), the slab holds [3, 8)");
  refused(0, n.z, nullptr, o, 4, 6, "read sample planes");
  // The dual meshers read three planes before: slab [4, 6) reads [1, 9).
  MeshOptions dc;
  dc.algorithm = Mesher::kDualContouring;
  refused(2, 7, v.data() + 2 * plane, dc, 4, 6, "read sample planes [1, 9), the slab holds [2, 9)");
  MeshOptions analytic;
  analytic.value = [](const std::array<double, 3>&) { return 0.0; };
  refused(0, n.z, v.data(), analytic, 4, 6, "analytic");
  // A NaN is named by its place in the whole lattice, not the slab's.
  v[2 + n.x * 3 + plane * 7] = std::numeric_limits<float>::quiet_NaN();
  refused(3, 6, v.data() + 3 * plane, o, 4, 6, "sample (2, 3, 7) is NaN");
  frame.spacing_units = {0, 1, 1};
  refused(0, n.z, v.data(), o, 0, 2, "spacing");
}

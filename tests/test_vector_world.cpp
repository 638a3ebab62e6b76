// Vector fields of a world's solid voxels (vector_world.h) against the brute-force definition:
// every solid voxel a source, the strength from its exact distance, the direction away from a
// nearest solid; edits keep the field equal to a rebuild.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "error_text.h"
#include "voxfield/error.h"
#include "voxfield/vector_world.h"
#include "voxfield/vectors.h"

namespace voxfield {
namespace {

using test::error_of;

// A world of scattered solid voxels and blocks in a 40 x 32 x 24 box.
World scattered_world(std::uint32_t seed) {
  World w(8, Box3i::from_size({40, 32, 24}));
  std::mt19937 rng(seed);
  for (int i = 0; i < 60; ++i)
    w.voxels.set(
        {static_cast<int>(rng() % 40), static_cast<int>(rng() % 32), static_cast<int>(rng() % 24)},
        1);
  for (int z = 5; z < 9; ++z)
    for (int y = 10; y < 20; ++y)
      for (int x = 12; x < 15; ++x) w.voxels.set({x, y, z}, 2);
  return w;
}

// Against the definition with every solid voxel a source of radius `reach`: the strength must be
// the brute-force one, and the direction must point away from a solid voxel at that distance (the
// nearest solid may be one of several at the same distance).
void expect_world_vectors(const World& w, const Box3i& box, double reach, const VectorTexture& t) {
  std::vector<Vec3d> solids;
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x)
        if (w.voxels.get({x, y, z})) solids.push_back({x + 0.5, y + 0.5, z + 0.5});
  const VectorVolume v = world_vector_volume(box);
  int checked = 0, wrong = 0;
  for (int k = 0; k < v.resolution.z; ++k)
    for (int j = 0; j < v.resolution.y; ++j)
      for (int i = 0; i < v.resolution.x; ++i) {
        // The centre exactly (voxel_centre rounds in its last bits; here d must be exact, since
        // a lattice distance of exactly `reach` is not covered).
        const Vec3d p{box.begin.x + i + 0.5, box.begin.y + j + 0.5, box.begin.z + k + 0.5};
        double d = 1e300;
        for (const Vec3d& s : solids) d = std::min(d, (p - s).length());
        const VectorTexel got = t.get(v.index(i, j, k));
        const double want_strength = d < reach ? 1 - d / reach : 0;
        bool ok = std::abs(got.strength - want_strength) < 1e-6;
        if (ok && want_strength > 0 && d > 0) {
          const Vec3d from = p - Vec3d{got.x, got.y, got.z} * d;  // the solid it points away from
          ok = false;
          for (const Vec3d& s : solids) ok = ok || (from - s).length() < 1e-4;
        }
        ++checked;
        if (!ok && wrong < 5)
          ADD_FAILURE() << "voxel " << i << "," << j << "," << k << ": strength " << got.strength
                        << " want " << want_strength << " (d " << d << "), direction " << got.x
                        << "," << got.y << "," << got.z;
        wrong += !ok;
      }
  EXPECT_EQ(wrong, 0) << "of " << checked;
}

TEST(WorldVectors, AwayFromTheNearestSolidWithItsExactDistance) {
  const World w = scattered_world(3);
  const Box3i box = Box3i::from_size({40, 32, 24});
  const WorldVectorField f(w, box, 6.5, VectorStorage::kRgba32f);
  expect_world_vectors(w, box, 6.5, f.texture());
  // The volume: texel (i, j, k) centred on voxel (i, j, k)'s centre.
  const Vec3d c = f.volume().voxel_centre(3, 4, 5);
  EXPECT_NEAR((c - Vec3d{3.5, 4.5, 5.5}).length(), 0, 1e-12);
  // A sub-box of the field's domain gives the same texels.
  const Box3i part{{5, 6, 7}, {30, 20, 19}};
  const VectorTexture sub = vectors_from_field(f.field(), part, 6.5, VectorStorage::kRgba32f);
  EXPECT_EQ(sub.get(0), f.texture().get(f.volume().index(5, 6, 7)));
  EXPECT_NE(error_of([&] { WorldVectorField(w, box, 0, VectorStorage::kRgba8); }).find("reach"),
            std::string::npos);
}

TEST(WorldVectors, EditsKeepTheFieldEqualToARebuild) {
  World w = scattered_world(9);
  const Box3i box = Box3i::from_size({40, 32, 24});
  WorldVectorField f(w, box, 5, VectorStorage::kRgba8);
  std::mt19937 rng(4);
  for (int e = 0; e < 12; ++e) {
    DirtyRegions dirty(8, DirtyRegions::Track::kOccupancy);
    Edit edit;
    edit.op = e % 2 ? EditOp::kCarve : EditOp::kPlace;
    edit.brush =
        SphereBrush{{double(rng() % 40), double(rng() % 32), double(rng() % 24)}, 2.0 + rng() % 4};
    apply_edit(w, edit, &dirty);
    const std::int64_t texels = f.update(dirty);
    // Exactly the union of the changed boxes grown by the reach (ceil(5) + 1): each texel once.
    std::vector<char> covered(static_cast<std::size_t>(box.volume()), 0);
    for (const Box3i& b : dirty.boxes()) {
      const Box3i r = b.grown(6).intersect(box);
      for (int z = r.begin.z; z < r.end.z; ++z)
        for (int y = r.begin.y; y < r.end.y; ++y)
          for (int x = r.begin.x; x < r.end.x; ++x)
            covered[static_cast<std::size_t>((z * 32 + y) * 40 + x)] = 1;
    }
    EXPECT_EQ(texels, std::count(covered.begin(), covered.end(), 1)) << "after edit " << e;
    const WorldVectorField fresh(w, box, 5, VectorStorage::kRgba8);
    ASSERT_TRUE(std::equal(f.texture().bytes().begin(), f.texture().bytes().end(),
                           fresh.texture().bytes().begin()))
        << "after edit " << e;
  }
  expect_world_vectors(w, box, 5, WorldVectorField(w, box, 5, VectorStorage::kRgba32f).texture());
}

}  // namespace
}  // namespace voxfield

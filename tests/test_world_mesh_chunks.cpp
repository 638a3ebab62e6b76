// WorldMeshChunks: a voxel world's surface kept per chunk through its edits has, after every edit,
// the triangles mesh_world() gives for the edited world — positions, normals and colours bit for
// bit, at iso 0 and on offset surfaces, for every mesher and in a placed frame — while re-meshing
// only the chunks within the field's reach of the edit; a repaint re-colours; misuse is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <random>
#include <set>
#include <string>

#include "mesh_compare.h"
#include "voxfield/edit.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"

using namespace voxfield;

namespace {

void expect_mesh_world(const WorldMeshChunks& kept, const World& world, const MeshOptions& o,
                       Metric metric, const std::string& what) {
  const Mesh mine = kept.merged();
  const Mesh full = mesh_world(world, o, metric);
  ASSERT_GT(full.triangle_count(), 0u) << what;
  ASSERT_EQ(mine.triangle_count(), full.triangle_count()) << what;
  ASSERT_EQ(mine.vertex_count(), full.vertex_count()) << what;
  EXPECT_TRUE(test::corner_triangles<true>(mine) == test::corner_triangles<true>(full)) << what;
}

// Ground with hills and a few colours in a 48 x 40 x 32 box; with `anchors`, two voxels in
// opposite corners that no edit reaches keep the content's box equal to the bounds, so that
// mesh_world's lattice (the content grown) is the kept one's (the bounds grown) sample for sample —
// the offset surfaces' crossings then round alike.
World ground(bool anchors) {
  World w(8, Box3i{{0, 0, 0}, {48, 40, 32}});
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 48; ++x) {
      const int h = 6 + (x * 7 + y * 3) % 5 + (x / 12 + y / 10) % 3;
      for (int z = 0; z < h; ++z)
        w.voxels.set({x, y, z}, static_cast<std::uint8_t>(1 + (x / 8 + z / 4) % 3));
    }
  // A ledge on top, the content's highest voxels: the surface over them is not symmetric, so
  // its normals show whether the air above them is sampled far enough.
  w.voxels.fill(Box3i{{20, 20, 12}, {22, 21, 14}}, 3);
  w.voxels.set({22, 20, 12}, 3);
  if (anchors) {
    w.voxels.set({47, 39, 31}, 4);
    w.voxels.set({0, 0, 31}, 4);
  }
  return w;
}

// A seeded stream of places, carves and paints (spheres, boxes, capsules) away from the anchors.
Edit random_edit(std::mt19937& rng) {
  std::uniform_real_distribution<double> x(6, 42), y(6, 34), z(3, 20), r(1, 4.5);
  std::uniform_int_distribution<int> kind(0, 5), material(1, 5);
  Edit e;
  const int k = kind(rng);
  e.op = k < 2 ? EditOp::kPlace : k < 4 ? EditOp::kCarve : EditOp::kPaint;
  e.material = static_cast<std::uint8_t>(material(rng));
  const Vec3d c{x(rng), y(rng), z(rng)};
  if (k % 3 == 0) {
    e.brush = SphereBrush{c, r(rng)};
  } else if (k % 3 == 1) {
    const Vec3i lo{static_cast<int>(c.x), static_cast<int>(c.y), static_cast<int>(c.z)};
    e.brush = BoxBrush{lo, lo + Vec3i{3, 2, 4}};
  } else {
    e.brush = CapsuleBrush{c, c + Vec3d{4, -3, 2}, r(rng) / 2};
  }
  return e;
}

struct Surface {
  double iso;
  Metric metric;
};

}  // namespace

TEST(WorldMeshChunks, KeepsMeshWorldThroughAnEditStream) {
  for (const Surface surface : {Surface{0, Metric::kEuclidean}, Surface{2, Metric::kEuclidean},
                                Surface{-1, Metric::kEuclidean}, Surface{2, Metric::kManhattan}})
    for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
      SCOPED_TRACE(std::string(mesher_name(m)) + " iso " + std::to_string(surface.iso) + " " +
                   metric_name(surface.metric));
      World world = ground(/*anchors=*/true);
      MeshOptions o;
      o.algorithm = m;
      o.iso = surface.iso;
      o.chunk_edge = 8;
      WorldMeshChunks kept(world, o, surface.metric);
      expect_mesh_world(kept, world, o, surface.metric, "before any edit");
      const Vec3i count = kept.chunk_count();
      const int total = count.x * count.y * count.z;
      const int reach = static_cast<int>(std::ceil(std::abs(surface.iso))) + 3;
      std::mt19937 rng(7 + static_cast<int>(m));
      for (int edit = 0; edit < 8; ++edit) {
        DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
        const EditResult r = apply_edit(world, random_edit(rng), &dirty);
        const std::vector<Vec3i> remeshed = kept.update(dirty);
        if (r.voxels_changed > 0) {
          EXPECT_FALSE(remeshed.empty()) << "edit " << edit;
          EXPECT_LT(static_cast<int>(remeshed.size()), total / 2) << "edit " << edit;
        }
        // Every re-meshed chunk reads a sample within the reach of a changed voxel: its cells
        // (lattice from the bounds grown by the margin) three samples before to two past.
        const int margin = surface.iso == 0  ? 2
                           : surface.iso > 0 ? 2 + static_cast<int>(std::ceil(surface.iso))
                                             : 1;
        for (const Vec3i& c : remeshed)
          for (int a = 0; a < 3; ++a) {
            const int first_sample = c[a] * o.chunk_edge - margin;  // in voxels
            EXPECT_LT(first_sample - 3, r.changed_box.end[a] + reach) << "edit " << edit;
            EXPECT_GT(first_sample + o.chunk_edge + 3, r.changed_box.begin[a] - reach)
                << "edit " << edit;
          }
        expect_mesh_world(kept, world, o, surface.metric, "after edit " + std::to_string(edit));
      }
    }
}

// Without anchors the kept lattice is larger than mesh_world's (the bounds against the content),
// and the surface still closes where the content touches the bounds; a repaint re-colours.
TEST(WorldMeshChunks, ClosesAtTheBoundsAndRepaints) {
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    SCOPED_TRACE(mesher_name(m));
    World world = ground(/*anchors=*/false);
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 16;
    WorldMeshChunks kept(world, o);
    expect_mesh_world(kept, world, o, Metric::kEuclidean, "before the repaint");
    const Mesh before = kept.merged();
    DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
    Edit paint;
    paint.op = EditOp::kPaint;
    paint.material = 9;
    paint.brush = BoxBrush{{10, 10, 0}, {20, 20, 31}};
    ASSERT_GT(apply_edit(world, paint, &dirty).voxels_changed, 0);
    EXPECT_FALSE(kept.update(dirty).empty());
    const Mesh after = kept.merged();
    expect_mesh_world(kept, world, o, Metric::kEuclidean, "after the repaint");
    EXPECT_EQ(after.positions.size(), before.positions.size());
    EXPECT_FALSE(after.colors == before.colors);  // the same surface, other colours
  }
}

// The reach, pinned: toggling one voxel at every offset around a chunk border of the lattice
// (from |iso| + 6 before it to as many after) and updating gives mesh_world's mesh each time. A
// chunk's reads reach three samples past its cells, which covers the surfaces near the voxels
// themselves; an offset surface six voxels out moves chunks farther away, where only the field's
// reach finds them (re-meshing by the changed boxes alone fails here).
TEST(WorldMeshChunks, OneVoxelAtEveryOffsetFromABorder) {
  for (const Surface surface : {Surface{0, Metric::kEuclidean}, Surface{2, Metric::kEuclidean},
                                Surface{6, Metric::kEuclidean}}) {
    SCOPED_TRACE("iso " + std::to_string(surface.iso));
    World world = ground(/*anchors=*/true);
    MeshOptions o;
    o.algorithm = Mesher::kDualContouring;
    o.iso = surface.iso;
    o.chunk_edge = 8;
    WorldMeshChunks kept(world, o, surface.metric);
    const int margin = surface.iso > 0 ? 2 + static_cast<int>(surface.iso) : 2;
    const int border = 3 * o.chunk_edge - margin;  // voxel x where lattice chunk 3 begins
    const int span = static_cast<int>(surface.iso) + 6;
    for (int x = border - span; x <= border + span; ++x) {
      const Vec3i p{x, 20, 12};
      DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
      Edit e;
      e.op = world.voxels.get(p) ? EditOp::kCarve : EditOp::kPlace;
      e.brush = BoxBrush{p, p};
      apply_edit(world, e, &dirty);
      kept.update(dirty);
      expect_mesh_world(kept, world, o, surface.metric, "after toggling x = " + std::to_string(x));
    }
  }
}

// Placed in the world's frame, as mesh_world() places its mesh; chunk meshes too.
TEST(WorldMeshChunks, MeshesInTheWorldsFrame) {
  World world = ground(/*anchors=*/true);
  world.frame.origin_world = {10, -4, 2};
  world.frame.voxel_size_world = {0.25, 0.25, 0.5};
  MeshOptions o;
  o.chunk_edge = 16;
  WorldMeshChunks kept(world, o);
  expect_mesh_world(kept, world, o, Metric::kEuclidean, "in a frame");
  const Mesh merged = kept.merged();
  const std::set<std::array<float, 3>> placed(merged.positions.begin(), merged.positions.end());
  const Mesh chunk = kept.chunk_mesh({1, 1, 0});
  ASSERT_GT(chunk.vertex_count(), 0u);
  for (const auto& p : chunk.positions) EXPECT_TRUE(placed.count(p)) << p[0] << " " << p[1];
}

// An unbounded world kept over a box: mesh_world of the world cut to the box, through edits inside
// and across the box's faces.
TEST(WorldMeshChunks, KeepsAnUnboundedWorldOverABox) {
  const World bounded = ground(/*anchors=*/false);
  World start(8);  // the same voxels without bounds, and more beyond the box
  start.voxels = bounded.voxels.rechunked(8, std::nullopt);
  start.voxels.fill(Box3i{{40, 30, 0}, {60, 50, 9}}, 5);
  const Box3i box{{2, 3, 0}, {44, 36, 30}};
  for (const double iso : {0.0, 2.0}) {  // an offset surface's colours come from the box's voxels
    SCOPED_TRACE("iso " + std::to_string(iso));
    World world = start;
    MeshOptions o;
    o.chunk_edge = 16;
    o.iso = iso;
    WorldMeshChunks kept(world, o, Metric::kEuclidean, box);
    std::mt19937 rng(99);
    for (int edit = 0; edit < 6; ++edit) {
      if (edit > 0) {
        DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
        Edit e = random_edit(rng);
        if (edit % 2 == 0)
          e.brush = SphereBrush{{43.0, 20.0 + edit, 8.0}, 3};  // across the box's face
        apply_edit(world, e, &dirty);
        kept.update(dirty);
      }
      World cut(8, box);
      cut.voxels = world.voxels.rechunked(8, box);
      expect_mesh_world(kept, cut, o, Metric::kEuclidean, "after edit " + std::to_string(edit));
    }
  }
  EXPECT_THROW(
      WorldMeshChunks(start, MeshOptions{}, Metric::kEuclidean, Box3i{{5, 5, 5}, {5, 9, 9}}),
      InvalidArgument);
  MeshOptions bad;
  bad.chunk_edge = 1;  // refused before the field is built
  EXPECT_THROW(WorldMeshChunks(start, bad, Metric::kEuclidean, box), InvalidArgument);
}

TEST(WorldMeshChunks, RefusesWhatItCannotKeep) {
  MeshOptions o;
  World unbounded;
  unbounded.voxels.set({1, 2, 3}, 1);
  EXPECT_THROW(WorldMeshChunks(unbounded, o), InvalidArgument);
  World world = ground(/*anchors=*/false);
  MeshOptions half = o;
  half.iso = 0.5;
  EXPECT_THROW(WorldMeshChunks(world, half), InvalidArgument);
  WorldMeshChunks kept(world, o);
  EXPECT_THROW(kept.chunk_mesh(kept.chunk_count()), InvalidArgument);
  EXPECT_TRUE(kept.update(DirtyRegions(8, DirtyRegions::Track::kAnyChange)).empty());
  DirtyRegions occupancy(8, DirtyRegions::Track::kOccupancy);  // would miss repaints
  occupancy.add(Box3i{{1, 1, 1}, {2, 2, 2}});
  EXPECT_THROW(kept.update(occupancy), InvalidArgument);
  world.voxels = world.voxels.rechunked(8, Box3i{{0, 0, 0}, {64, 64, 64}});
  DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
  dirty.add(Box3i{{0, 0, 0}, {1, 1, 1}});
  EXPECT_THROW(kept.update(dirty), InvalidArgument);
}

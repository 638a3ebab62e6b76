// The voxel compiler's parallel paths under ThreadSanitizer (the tsan preset runs this executable):
// the octree's subtrees built concurrently and joined, voxelisation jobs writing disjoint boxes,
// and the renderer's rows with per-thread tape caches — the same results as on one thread.
#include <gtest/gtest.h>

#include "csg_examples.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"
#include "voxfield/csg_render.h"
#include "voxfield/parallel.h"

using namespace voxfield;

namespace {}  // namespace

TEST(ParallelCsg, ThreadsGiveTheSameOctreeVoxelsAndPicture) {
  const csg::Model m = test::csg_example("building.sdf");
  const csg::Tape tape = csg::compile_tape(m);
  csg::OctreeOptions oo;
  oo.depth = 4;
  csg::VoxelizeOptions vo;
  vo.voxel_size = 0.25;
  vo.field = true;
  CsgRenderOptions ro;
  ro.width = 64;
  ro.height = 48;
  ro.depth = 4;
  csg::Octree one_tree;
  csg::Voxelized one_vox;
  Image one_img;
  {
    ThreadLimit limit(1);
    one_tree = csg::build_octree(tape, m, oo);
    one_vox = csg::voxelize(m, vo);
    one_img = render_csg(m, ro);
  }
  const csg::Octree tree = csg::build_octree(tape, m, oo);
  EXPECT_EQ(tree.children, one_tree.children);
  EXPECT_EQ(tree.sources, one_tree.sources);
  ASSERT_EQ(tree.leaves.size(), one_tree.leaves.size());
  for (std::size_t i = 0; i < tree.leaves.size(); ++i)
    EXPECT_EQ(tree.leaves[i].variant, one_tree.leaves[i].variant);
  const csg::Voxelized vox = csg::voxelize(m, vo);
  EXPECT_EQ(vox.field, one_vox.field);
  EXPECT_EQ(render_csg(m, ro).rgb, one_img.rgb);
}

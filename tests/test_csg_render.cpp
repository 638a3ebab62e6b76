// CSG pictures: tracing each octree cell's pruned tape gives the picture of the whole tape (the
// marches differ only in where steps land, so pixels may differ along silhouettes and nowhere
// else), runs far fewer instructions, and the variant view shows the variants.
#include <gtest/gtest.h>

#include <set>

#include "csg_examples.h"
#include "voxfield/csg.h"
#include "voxfield/csg_render.h"

namespace voxfield {
namespace {

TEST(CsgRender, PrunedEqualsWholeAndCostsLess) {
  for (const char* name : {"gear.sdf", "blobs.sdf", "building.sdf"}) {
    const csg::Model m = test::csg_example(name);
    CsgRenderOptions o;
    o.width = 160;
    o.height = 120;
    CsgRenderStats pruned_stats, whole_stats;
    const Image pruned = render_csg(m, o, &pruned_stats);
    o.prune = false;
    const Image whole = render_csg(m, o, &whole_stats);
    int differing = 0;
    for (std::size_t i = 0; i < pruned.rgb.size(); i += 3) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(pruned.rgb[i + c] - whole.rgb[i + c]));
      differing += d > 6;
    }
    EXPECT_LT(differing, 160 * 120 / 100) << name;  // under 1 % of the pixels, on silhouettes
    EXPECT_GT(pruned_stats.hits, 160 * 120 / 10) << name;
    EXPECT_NEAR(static_cast<double>(pruned_stats.hits), static_cast<double>(whole_stats.hits),
                160 * 120 / 100.0)
        << name;
    EXPECT_LT(pruned_stats.instructions * 3, whole_stats.instructions) << name;
  }
}

TEST(CsgRender, VariantViewShowsEachVariant) {
  const csg::Model gear = test::csg_example("gear.sdf");
  CsgRenderOptions o;
  o.width = 200;
  o.height = 150;
  o.view = CsgRenderOptions::View::kVariants;
  o.shadows = false;
  CsgRenderStats st;
  const Image img = render_csg(gear, o, &st);
  std::set<std::uint32_t> colours;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3)
    colours.insert(std::uint32_t{img.rgb[i]} << 16 | std::uint32_t{img.rgb[i + 1]} << 8 |
                   img.rgb[i + 2]);
  EXPECT_GE(st.variants, 3);
  EXPECT_GT(colours.size(), static_cast<std::size_t>(st.variants));  // shaded variants and the sky
}

TEST(CsgRender, RefusesUnboundedModelsWithoutABox) {
  const csg::Model plane = csg::parse_model("(plane 0 0 1 0)", "plane.sdf");
  EXPECT_THROW((void)render_csg(plane, {}), InvalidArgument);
  CsgRenderOptions o;
  o.width = 32;
  o.height = 24;
  o.box = csg::Bounds{{-1, -1, -1}, {1, 1, 1}};
  const Image img = render_csg(plane, o);
  EXPECT_EQ(img.width, 32);
}

}  // namespace
}  // namespace voxfield

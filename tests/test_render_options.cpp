// voxfield — check_render_scene_options (render.h) against the scenes themselves: the check
// refuses exactly the options a RenderScene and a DynamicRenderScene refuse, without building a
// field (programs that build their scene later, or on a device only, check with it first).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "voxfield/error.h"
#include "voxfield/render.h"

namespace voxfield {
namespace {

bool scene_options_accepted(const auto& make) {
  try {
    make();
    return true;
  } catch (const InvalidArgument&) {
    return false;
  }
}

TEST(RenderOptions, TheCheckRefusesWhatEveryHostSceneRefuses) {
  World w(8, Box3i{{0, 0, 0}, {20, 16, 12}});
  for (int x = 3; x < 9; ++x) w.voxels.set({x, 5, 4}, 2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  int refused = 0, cases = 0;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (double skip : {0.0, 1.0, 16.0, 63.0, 63.5, 255.0, 255.5, 256.0, -1.0, nan, inf})
      for (bool lighting : {true, false})
        for (double light : {16.0, 63.0, 0.0, 63.5, -2.0, nan}) {
          RenderSceneOptions o;
          o.skip_metric = m;
          o.skip_max_distance_vox = skip;
          o.lighting_field = lighting;
          o.lighting_max_distance_vox = light;
          const std::string what = std::string(metric_name(m)) + " skip " + std::to_string(skip) +
                                   (lighting ? " light " + std::to_string(light) : " unlit");
          const bool check = scene_options_accepted([&] { check_render_scene_options(o); });
          EXPECT_EQ(check, scene_options_accepted([&] { RenderScene scene(w, o); })) << what;
          EXPECT_EQ(check, scene_options_accepted([&] { DynamicRenderScene scene(w, o); })) << what;
          refused += !check;
          ++cases;
        }
  // Both kinds occur: the comparison above is not of two functions that accept everything.
  EXPECT_GT(refused, 0);
  EXPECT_LT(refused, cases);
}

}  // namespace
}  // namespace voxfield

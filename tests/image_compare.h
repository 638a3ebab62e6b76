// Tests' image comparison: how many pixels differ by more than a number of levels in some channel,
// and the mean difference per channel.
#pragma once

#include <cstdlib>

#include "voxfield/image.h"

namespace voxfield::test {

struct ImageDiff {
  std::size_t pixels = 0;
  std::size_t off = 0;  // pixels with a channel more than `levels` apart
  double mean = 0;      // mean |difference| over every channel of every pixel
};

inline ImageDiff compare_images(const Image& a, const Image& b, int levels) {
  ImageDiff d;
  d.pixels = a.rgb.size() / 3;
  double total = 0;
  for (std::size_t i = 0; i + 2 < a.rgb.size() && i + 2 < b.rgb.size(); i += 3) {
    int worst = 0;
    for (int c = 0; c < 3; ++c) {
      const int diff = std::abs(int(a.rgb[i + c]) - int(b.rgb[i + c]));
      worst = std::max(worst, diff);
      total += diff;
    }
    d.off += worst > levels;
  }
  d.mean = a.rgb.empty() ? 0 : total / static_cast<double>(a.rgb.size());
  return d;
}

}  // namespace voxfield::test

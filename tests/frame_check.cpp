// Checks a screenshot of voxfield-demo: a real frame shows both sky and world, so it has many
// colours, no colour covers most of it, and its top corner (sky, the camera looks down at the
// world) differs clearly from its centre (the world). Exit status 0 when it does; the reason on
// stderr otherwise.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>

#include "voxfield/error.h"
#include "voxfield/image.h"
#include "voxfield/png.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: frame_check SCREENSHOT.png\n";
    return 2;
  }
  try {
    const voxfield::Image img = voxfield::read_png(argv[1]);
    std::map<std::uint32_t, std::size_t> counts;
    for (std::size_t i = 0; i + 2 < img.rgb.size(); i += 3)
      ++counts[(std::uint32_t{img.rgb[i]} << 16) | (std::uint32_t{img.rgb[i + 1]} << 8) |
               img.rgb[i + 2]];
    std::size_t largest = 0;
    for (const auto& [colour, n] : counts) largest = std::max(largest, n);
    const std::size_t pixels = static_cast<std::size_t>(img.width) * img.height;
    auto mean = [&](int x0, int y0, int x1, int y1, int c) {
      double sum = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) sum += img.pixel(x, y)[c];
      return sum / ((x1 - x0) * (y1 - y0));
    };
    const int w = img.width, h = img.height;
    double difference = 0;
    for (int c = 0; c < 3; ++c)
      difference += std::abs(mean(w * 9 / 10, 0, w, h / 10, c) -
                             mean(w * 2 / 5, h * 2 / 5, w * 3 / 5, h * 3 / 5, c));
    std::printf(
        "%dx%d, %zu colours, the commonest covers %.1f %%, sky corner vs centre differ by %.0f "
        "levels\n",
        w, h, counts.size(), 100.0 * static_cast<double>(largest) / static_cast<double>(pixels),
        difference);
    if (counts.size() < 64)
      return std::fprintf(stderr, "too few colours: not a rendered frame\n"), 1;
    if (largest * 2 > pixels)
      return std::fprintf(stderr, "one colour covers most of the frame\n"), 1;
    if (difference < 40)
      return std::fprintf(stderr, "the sky corner looks like the centre: is the world missing?\n"),
             1;
    return 0;
  } catch (const voxfield::Error& e) {
    std::cerr << "frame_check: " << e.what() << "\n";
    return 1;
  }
}

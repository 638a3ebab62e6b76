// voxfield — 8-bit RGB images: the renderer's frames (PNG files of them: png.h).
#pragma once

#include <cstdint>
#include <vector>

namespace voxfield {

struct Image {
  int width = 0, height = 0;
  // Row-major, top row first, 3 bytes (R, G, B; sRGB) per pixel.
  std::vector<std::uint8_t> rgb;

  Image() = default;
  // A black image. Throws InvalidArgument for a non-positive or absurd size (more than 2^28
  // pixels).
  Image(int width, int height);

  std::uint8_t* pixel(int x, int y) {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x);
  }
  const std::uint8_t* pixel(int x, int y) const {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x);
  }
};

// FNV-1a (hash.h) of the size and the pixels: benchmarks print it beside their times.
std::uint64_t content_hash(const Image& image);

}  // namespace voxfield

// voxfield — 8-bit RGB images and PNG files, for the renderer's frames and golden-image tests.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace voxfield {

struct Image {
  int width = 0, height = 0;
  // Row-major, top row first, 3 bytes (R, G, B; sRGB) per pixel.
  std::vector<std::uint8_t> rgb;

  Image() = default;
  // A black image. Throws InvalidArgument for a non-positive or absurd size (more than 2^28 pixels).
  Image(int width, int height);

  std::uint8_t* pixel(int x, int y) { return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x); }
  const std::uint8_t* pixel(int x, int y) const {
    return rgb.data() + 3 * (static_cast<std::size_t>(y) * width + x);
  }
};

// The bytes of an 8-bit RGB PNG of the image. Throws InvalidArgument / Error.
std::vector<std::uint8_t> encode_png(const Image& image);
// Writes an 8-bit RGB PNG atomically (the old file or the new one, never a mix). Throws IoError.
void write_png(const Image& image, const std::filesystem::path& path);
// Reads any PNG (grey, palette, RGB, with or without alpha, 8 or 16 bits) as 8-bit RGB; alpha is
// composited over black. Throws IoError or FormatError with libpng's message.
Image read_png(const std::filesystem::path& path);

}  // namespace voxfield

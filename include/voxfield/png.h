// voxfield — PNG files of images: the renderer's frames, golden-image tests.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "voxfield/image.h"

namespace voxfield {

// The bytes of an 8-bit RGB PNG of the image. Throws InvalidArgument / Error.
std::vector<std::uint8_t> encode_png(const Image& image);
// Writes an 8-bit RGB PNG atomically (the old file or the new one, never a mix). Throws IoError.
void write_png(const Image& image, const std::filesystem::path& path);
// Reads any PNG (grey, palette, RGB, with or without alpha, 8 or 16 bits) as 8-bit RGB; alpha is
// composited over black. Throws IoError or FormatError with libpng's message.
Image read_png(const std::filesystem::path& path);

}  // namespace voxfield

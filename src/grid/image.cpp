// voxfield — 8-bit RGB images (the renderer's frames).
#include "voxfield/image.h"

#include <string>

#include "voxfield/error.h"
#include "voxfield/hash.h"

namespace voxfield {

Image::Image(int w, int h) : width(w), height(h) {
  if (w <= 0 || h <= 0 || static_cast<std::int64_t>(w) * h > (std::int64_t{1} << 28))
    throw InvalidArgument("image size " + std::to_string(w) + "x" + std::to_string(h) +
                          " is out of range (1..2^28 pixels)");
  rgb.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3, 0);
}

std::uint64_t content_hash(const Image& image) {
  const std::int32_t size[2] = {image.width, image.height};
  return fnv1a(fnv1a(kFnvOffset, size, sizeof size), image.rgb.data(), image.rgb.size());
}

}  // namespace voxfield

// voxfield — PNG files through libpng's simplified API (png_image), chosen over a hand-written
// encoder because it is Debian's reference PNG implementation and its simplified API reports
// errors through a message field instead of longjmp, which would skip C++ destructors.
#include <png.h>

#include <cstring>

#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/png.h"

namespace voxfield {

std::vector<std::uint8_t> encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() !=
          static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3)
    throw InvalidArgument("encode_png: image buffer does not match its size");
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // First call sizes the buffer, second fills it.
  png_alloc_size_t bytes = 0;
  if (!png_image_write_to_memory(&png, nullptr, &bytes, 0, image.rgb.data(), 0, nullptr))
    throw Error(std::string("PNG encoding failed: ") + png.message);
  std::vector<std::uint8_t> out(bytes);
  if (!png_image_write_to_memory(&png, out.data(), &bytes, 0, image.rgb.data(), 0, nullptr))
    throw Error(std::string("PNG encoding failed: ") + png.message);
  out.resize(bytes);
  return out;
}

void write_png(const Image& image, const std::filesystem::path& path) {
  std::vector<std::uint8_t> out;
  try {
    out = encode_png(image);
  } catch (const Error& e) {
    throw IoError(path.string() + ": " + e.what());
  }
  write_file_atomic(path, out);
}

Image read_png(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = read_file(path, std::uint64_t{1} << 31);
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()))
    throw FormatError(path.string(), 0, std::string("not a readable PNG: ") + png.message);
  png.format = PNG_FORMAT_RGB;
  Image image;
  try {
    image = Image(static_cast<int>(png.width), static_cast<int>(png.height));
  } catch (const InvalidArgument& e) {
    png_image_free(&png);
    throw FormatError(path.string(), 0, e.what());
  }
  png_color black{0, 0, 0};
  if (!png_image_finish_read(&png, &black, image.rgb.data(), 0, nullptr))
    throw FormatError(path.string(), 0, std::string("PNG decoding failed: ") + png.message);
  return image;
}

}  // namespace voxfield

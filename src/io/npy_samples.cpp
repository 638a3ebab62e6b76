// voxfield — a .npy volume's samples as the floats the meshers take (see voxfield/npy.h).
//
// NpyVolume::value's conversion, one loop per dtype rather than a switch per sample: a 140 MB
// scan spent longer converting its samples that way than meshing them.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "npy_sample_types.h"
#include "voxfield/error.h"
#include "voxfield/npy.h"

namespace voxfield {

std::vector<float> float_samples(const NpyVolume& volume, const std::string& path) {
  std::vector<float> values(static_cast<std::size_t>(volume.count()));
  const std::uint8_t* p = volume.bytes.data();
  const std::size_t size = dtype_size(volume.dtype);
  detail::npy::with_sample_type(volume.dtype, [&]<class T>() {
    for (std::size_t i = 0; i < values.size(); ++i) {
      const double v = detail::npy::sample_as_double<T>(p + i * size);
      if (std::abs(v) > std::numeric_limits<float>::max())  // false for NaN, which passes on
        throw FormatError(path, volume.file_offset_of(static_cast<std::int64_t>(i)),
                          "value " + std::to_string(v) + " does not fit a float32 sample");
      values[i] = static_cast<float>(v);
    }
  });
  return values;
}

}  // namespace voxfield

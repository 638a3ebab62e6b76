// voxfield — reading CSG model files (the one place that maps extensions to notations).
#include "voxfield/csg_files.h"

#include "voxfield/file.h"

namespace voxfield::csg {

Model load_model(const std::filesystem::path& path, const OpenScadOptions& openscad) {
  // Models are small texts; the language's own limit is 64 MiB.
  const auto bytes = read_file(path, std::uint64_t{64} << 20);
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::string ext = path.extension().string(), name = path.string();
  if (ext == ".json") return parse_model_json(text, name);
  if (ext == ".sdf") return parse_model_sexpr(text, name);
  if (ext == ".csg") return parse_openscad_csg(text, name, openscad);
  return parse_model(text, name);
}

}  // namespace voxfield::csg

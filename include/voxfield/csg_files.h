// voxfield — CSG model files by extension: .sdf (S-expressions), .json, OpenSCAD's .csg; any other
// extension is read as the model language, JSON when it starts with '['.
#pragma once

#include <filesystem>

#include "voxfield/csg.h"

namespace voxfield::csg {

// Throws IoError (unreadable, not a regular file, over 64 MiB) or ModelError, naming the file.
Model load_model(const std::filesystem::path& path, const OpenScadOptions& openscad = {});

}  // namespace voxfield::csg

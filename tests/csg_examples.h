// Test helper: the example CSG models of examples/csg/, as text or parsed.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include "voxfield/csg.h"

namespace voxfield::test {

inline std::string csg_example_text(const std::string& name) {
  std::ifstream in(std::string(VOXFIELD_EXAMPLES_DIR) + "/csg/" + name);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline csg::Model csg_example(const std::string& name) {
  return csg::parse_model(csg_example_text(name), name);
}

}  // namespace voxfield::test

// Test helper: the message of the voxfield::Error a call throws, or "(no error)", so that tests
// can assert on what a refusal says.
#pragma once

#include <string>

#include "voxfield/error.h"

namespace voxfield::test {

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace voxfield::test

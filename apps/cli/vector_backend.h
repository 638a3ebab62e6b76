// voxfield CLI — the backend of the vector-field commands: choose_backend's choice, except that a
// device that cannot run the vector-field passes (no shaderFloat64) falls back to the CPU with a
// message, as a missing device does.
#pragma once

#include <iostream>
#include <memory>
#include <string>

#include "backend_choice.h"
#include "voxfield/gpu_vectors.h"

namespace voxfield::cli {

inline std::shared_ptr<gpu::Context> choose_vector_backend(const std::string& name) {
  std::shared_ptr<gpu::Context> context = choose_backend(name);
  std::string why;
  if (context && !gpu::supports_vector_passes(*context, &why)) {
    std::cerr << "voxfield: " << why << "; using the cpu backend\n";
    context.reset();
  }
  return context;
}

}  // namespace voxfield::cli

// voxfield render — the GLSL of the Vulkan CSG renderer (gpu_csg_render.cpp), as text: its march
// kernels are generated per variant at run time, so every kernel is assembled from these pieces
// and compiled in-process (gpu::compile_glsl).
#pragma once

#include <string>

namespace voxfield::gpu::csg_trace {

// The kernels' shared declarations (buffers, records, ray set-up, the CSG prelude and the
// interpreter); every kernel is common() followed by its own main.
std::string common();
std::string init_main();     // rays from the camera (mode 0) or from hits toward the sun (mode 1)
std::string advance_main();  // each active ray to its next surface cell: queued, hit or missed
std::string bin_main();      // queue offsets and indirect dispatch sizes per variant
std::string scatter_main();  // queued rays into their variant's stretch of the queue
std::string shade_main();    // the pixel colours
// Normals and materials of the hits on full cells' faces, by `eval` on the whole tape.
std::string full_hits_main(const std::string& eval);
// The march through one variant's cells: `eval` is the GLSL of a function
// `float vf_eval(vec3 p, uint base, out uint material)` (a compiled variant or the interpreter).
std::string march_main(const std::string& eval);

}  // namespace voxfield::gpu::csg_trace

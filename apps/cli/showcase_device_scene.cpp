// voxfield showcase — the terrain drawn on Vulkan with its fields computed there
// (gpu::DeviceRenderScene) beside the same frame from the CPU's fields copied up (gpu::render of
// the host scene): the same picture, and the bytes each way.
#include <chrono>

#include "cli.h"
#include "showcase.h"
#include "voxfield/gpu_render.h"
#include "voxfield/png.h"

namespace voxfield::cli {

void showcase_device_scene(const std::filesystem::path& out, const World& world, const Box3i& box,
                           const RenderScene& host_scene, const Camera& camera,
                           const RenderOptions& options, std::ostream& md,
                           std::vector<Timing>& timings) {
  md << "\n### On Vulkan, the fields computed where they are drawn\n";
  const std::shared_ptr<gpu::Context> context = showcase_vulkan(md);
  if (!context) return;
  const gpu::DeviceInfo& device = context->device();
  const std::string emulated = device.hardware ? "" : "CPU emulation of the GPU";
  try {
    context->reset_counters();
    const Image from_host = gpu::render(*context, host_scene, camera, options);
    const gpu::Counters host = context->counters();
    context->reset_counters();
    auto start = std::chrono::steady_clock::now();
    gpu::DeviceRenderScene scene(context, world, DynamicRenderScene::default_options(), box);
    timings.push_back(
        {"render fields and cells on Vulkan (" + device.name + ")", ms_since(start), emulated});
    const gpu::DeviceRenderScene::UpdateStats& built = scene.build_stats();
    RenderStats st;
    const Image image = scene.render(camera, options, &st);
    timings.push_back({"frame terrain-device-fields.png (Vulkan, " + std::to_string(options.width) +
                           "×" + std::to_string(options.height) + ")",
                       st.ms, emulated});
    write_png(image, out / "terrain-device-fields.png");
    const bool same = image.rgb == from_host.rgb;
    md << "\nThe same view on " << device.name << " (`voxfield render --backend vulkan --fields "
       << "device`): the skip and lighting fields computed on the device from one copy of the "
          "world there, and the ray marcher's cells packed from them there. Against the frame of "
          "the CPU's fields copied up, it is "
       << (same ? "**the same picture, pixel for pixel**" : "**a DIFFERENT picture**") << ".\n\n"
       << "| fields | bytes up | bytes down | submits |\n|---|---|---|---|\n"
       << "| computed on the CPU, cells copied up (and the frame) | " << host.bytes_uploaded
       << " | " << host.bytes_downloaded << " | " << host.submits << " |\n"
       << "| computed on the device, cells packed there (and the frame) | "
       << context->counters().bytes_uploaded << " | " << context->counters().bytes_downloaded
       << " | " << context->counters().submits << " |\n\n"
       << "What came back of the device's fields: " << built.bytes_down << " bytes, "
       << "8 for each of the " << built.chunks_repacked
       << " chunks (its distance range and whether it holds a solid voxel, from which the host "
          "decides which chunks are stored voxel by voxel); the rest of the bytes down are the "
          "picture.\n\n![the terrain on Vulkan, fields computed there](terrain-device-fields.png)"
          "\n";
  } catch (const Error& e) {
    md << "\nOn Vulkan: not run here (" << e.what() << ").\n";
  }
}

}  // namespace voxfield::cli

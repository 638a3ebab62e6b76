// voxfield-demo — switching modes, and drawing the vectors mode's frames (vectors_mode.h) and the
// terrain mode's (terrain_mode.h). Vectors: on the Vulkan path the frame's step and picture are
// recorded into the frame's command buffer and the pixels copied to the swapchain image; otherwise
// the CPU's picture is presented as the world's CPU frames are. Terrain: the same, with the GPU
// terrain renderer's frame or the CPU rasteriser's picture.
#include <backends/imgui_impl_opengl2.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>

#include <iostream>

#include "demo.h"
#include "voxfield/error.h"

namespace voxfield::demo {

void Demo::set_mode(Mode mode) {
  wait_idle();
  const bool was_on = vectors_ != nullptr, was_terrain = terrain_ != nullptr;
  vectors_.reset();
  terrain_.reset();
  if (mode == Mode::kWorld) {
    frame_camera();
    status_ = "world mode";
    return;
  }
  if (mode == Mode::kTerrain) {
    terrain_ = std::make_unique<TerrainMode>(terrain_settings_, vk_ ? path_.context : nullptr);
    status_ = terrain_->on_gpu()
                  ? "terrain mode: marching cubes, HistoPyramid and an indirect draw on the "
                    "Vulkan device; edits upload only the samples they change"
                  : "terrain mode: the terrain field meshed chunk by chunk, drawn by the CPU "
                    "rasteriser";
    std::cerr << "voxfield-demo: " << status_ << "\n";
    if (!was_terrain) TerrainMode::frame(camera_, terrain_settings_);
    return;
  }
  try {
    vectors_ = std::make_unique<VectorsMode>(path_.context, vectors_settings_);
    status_ = std::string("vectors mode: the field is stepped and drawn on the ") +
              (vectors_->on_gpu() ? "Vulkan device" : "CPU");
  } catch (const Error& e) {
    if (!path_.context) throw;
    // The device cannot run the vector passes (no shaderFloat64, a texture past its buffers):
    // the CPU runs the mode, and the panel says why.
    vectors_ = std::make_unique<VectorsMode>(nullptr, vectors_settings_);
    status_ = std::string("vectors mode on the CPU: ") + e.what();
  }
  std::cerr << "voxfield-demo: " << status_ << "\n";
  if (!was_on) VectorsMode::frame(camera_);
}

bool Demo::draw_vectors(VulkanWindow::Screenshot* shot) {
  const int w = width(), h = height();
  const auto t0 = Clock::now();
  if (gl_) {
    const Image img = vectors_->render(camera_, w, h);
    gl_->draw_frame(
        img, [] { ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData()); }, shot);
    last_.render_ms = ms_between(t0, Clock::now());
    return true;
  }
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), 1};
  std::function<void(VkCommandBuffer, VkImage)> fill;
  if (vectors_->on_gpu()) {
    fill = [&](VkCommandBuffer cmd, VkImage image) {
      const VkBuffer pixels = vectors_->record_frame(
          cmd, camera_, w, h, vk_->bgra() ? gpu::PixelOrder::kBgra : gpu::PixelOrder::kRgba);
      vkCmdCopyBufferToImage(cmd, pixels, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    };
  } else {
    fill = stage_cpu_frame(vectors_->render(camera_, w, h));
  }
  const bool drawn = vk_->draw_frame(
      fill, [](VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); },
      shot);
  if (vectors_->on_gpu()) wait_idle();  // the frame's time includes its step and picture
  last_.render_ms = ms_between(t0, Clock::now());
  return drawn;
}

// The terrain mode's frames: on the GPU, recorded into the frame's command buffer and copied to
// the swapchain image; otherwise the CPU rasteriser's picture, presented as the CPU renderer's are.
bool Demo::draw_terrain(VulkanWindow::Screenshot* shot) {
  const int w = width(), h = height();
  const auto t0 = Clock::now();
  if (vk_ && terrain_->on_gpu()) {
    terrain_->upload_edits();
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), 1};
    const bool drawn = vk_->draw_frame(
        [&](VkCommandBuffer cmd, VkImage image) {
          const VkBuffer pixels = terrain_->record_frame(
              cmd, camera_, w, h, vk_->bgra() ? gpu::PixelOrder::kBgra : gpu::PixelOrder::kRgba);
          vkCmdCopyBufferToImage(cmd, pixels, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                                 &copy);
        },
        [](VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); },
        shot);
    wait_idle();  // the frame's time includes its meshing and draw; its triangle count is read
    last_.render_ms = ms_between(t0, Clock::now());
    return drawn;
  }
  const Image img = terrain_->render(camera_, w, h);
  if (gl_) {
    gl_->draw_frame(
        img, [] { ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData()); }, shot);
    last_.render_ms = ms_between(t0, Clock::now());
    return true;
  }
  const bool drawn = vk_->draw_frame(
      stage_cpu_frame(img),
      [](VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); },
      shot);
  last_.render_ms = ms_between(t0, Clock::now());
  return drawn;
}

}  // namespace voxfield::demo

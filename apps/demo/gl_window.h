// voxfield-demo — the fallback window for machines without a usable Vulkan device: an OpenGL 2.1
// context that shows the CPU renderer's frames (glDrawPixels) with the panel drawn over them.
// Frames never come from OpenGL itself; it only presents them.
#pragma once

#include <GLFW/glfw3.h>

#include <string>
#include <vector>

#include "voxfield/image.h"
#include "vulkan_window.h"  // WindowError, Screenshot

namespace voxfield::demo {

class GlWindow {
 public:
  // Throws WindowError when GLFW or OpenGL cannot open a window.
  GlWindow(int width, int height, const std::string& title);
  ~GlWindow();
  GlWindow(const GlWindow&) = delete;
  GlWindow& operator=(const GlWindow&) = delete;

  GLFWwindow* window() const { return window_; }
  int width() const;
  int height() const;
  std::string renderer_name() const { return renderer_; }
  // Shows `frame` (the framebuffer's size), then lets `overlay` draw (the panel), and swaps; with
  // `screenshot`, the shown image is read back first.
  void draw_frame(const Image& frame, const std::function<void()>& overlay,
                  VulkanWindow::Screenshot* screenshot);

 private:
  GLFWwindow* window_ = nullptr;
  std::string renderer_;
};

}  // namespace voxfield::demo

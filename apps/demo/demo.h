// voxfield-demo — the application object: the window, the world, the render path and the panel's
// state, shared by the frame loop (main.cpp) and the ImGui panel (panel.cpp).
#pragma once

#include <chrono>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "clock.h"
#include "demo_world.h"
#include "fly_camera.h"
#include "gl_window.h"
#include "terrain_mode.h"
#include "vectors_mode.h"
#include "voxfield/gpu_render.h"
#include "vulkan_window.h"

namespace voxfield::demo {

struct Options {
  WorldSettings world;
  std::string load;
  std::string backend = "auto";
  std::string fields = "auto";  // where the Vulkan path's fields live: auto, host, device
  int width = 1280, height = 720;
  bool validation = false;
  bool benchmark = false;
  int frames = 0;  // exit after this many frames (0: benchmark 300, interactive until closed)
  double interval_ms = 200;
  std::string csv;
  std::string screenshot;
  std::string mode = "world";  // or "vectors" (vectors_mode.h) or "terrain" (terrain_mode.h)
  VectorsSettings vectors;
  TerrainSettings terrain;
};

// What draws the frames, and why.
struct RenderPath {
  std::shared_ptr<gpu::Context> context;  // null: the CPU renderer
  std::unique_ptr<gpu::SceneRenderer> renderer;
  // The world's fields wanted on the device (each new world tries; DemoWorld::device_scene() says
  // whether they are there).
  bool device_fields = false;
  std::string why;
};

struct Brush {
  int radius = 4;
  std::uint8_t material = 1;
  bool paint = false;
};

enum class Mode { kWorld, kVectors, kTerrain };

struct Timings {
  double frame_ms = 0, update_ms = 0, render_ms = 0;
};

class Demo {
 public:
  explicit Demo(const Options& o);
  ~Demo();
  int run();

 private:
  void choose_path(const std::string& backend);
  // Keeps the world's fields on the path's device; false (the reason in the status line) when the
  // device cannot hold them.
  bool follow_on_device();
  // Draws `next` from now on (regenerate, load). Throws voxfield::Error, keeping the current world,
  // when `next`'s fields cannot be built on the host where they are to stay there.
  void replace_world(std::unique_ptr<DemoWorld> next, const std::string& done);
  void frame_camera();
  void handle_input(double dt_s);
  void edit_at_cursor(EditOp op);
  bool draw(VulkanWindow::Screenshot* shot);
  void panel();
  void help();
  void take_screenshot(const std::string& path);
  // Switches mode (or rebuilds the current one with new settings): the vectors and terrain modes
  // on the render path's device when there is one (and it can run them), else on the CPU.
  void set_mode(Mode mode);
  bool draw_vectors(VulkanWindow::Screenshot* shot);
  bool draw_terrain(VulkanWindow::Screenshot* shot);
  // The ray through the cursor (the window's centre in look mode), in the frame's pixels.
  Ray cursor_ray();
  // A CPU picture copied into the window's staging buffer (in its byte order): the frame's fill.
  std::function<void(VkCommandBuffer, VkImage)> stage_cpu_frame(const Image& img);
  bool gpu_can_draw() const { return path_.renderer != nullptr; }
  std::string title() const;
  GLFWwindow* glfw() const { return vk_ ? vk_->window() : gl_->window(); }
  int width() const { return vk_ ? vk_->width() : gl_->width(); }
  int height() const { return vk_ ? vk_->height() : gl_->height(); }
  void wait_idle() const {
    if (vk_) vk_->wait_idle();
  }

  Options options_;
  std::unique_ptr<VulkanWindow> vk_;  // the window, when Vulkan can present to it
  std::unique_ptr<GlWindow> gl_;      // otherwise this one, showing CPU frames
  std::string no_vulkan_;             // why there is no Vulkan window
  std::unique_ptr<DemoWorld> world_;
  std::unique_ptr<VectorsMode> vectors_;  // the vectors mode, when on
  VectorsSettings vectors_settings_;
  std::unique_ptr<TerrainMode> terrain_;  // the terrain mode, when on
  TerrainSettings terrain_settings_;
  RenderPath path_;
  FlyCamera camera_;
  Brush brush_;
  RenderView view_ = RenderView::kShaded;
  Algorithm error_algorithm_ = Algorithm::kJfa;
  bool show_help_ = false;
  bool look_mode_ = false;  // Tab: the mouse turns the view, clicks edit at the centre
  double last_x_ = 0, last_y_ = 0;
  double scroll_ = 0;
  std::vector<int> keys_pressed_, clicks_;  // since the last frame
  Clock::time_point last_edit_ = Clock::now();
  Timings last_;
  std::deque<float> frame_history_;
  std::string status_;
  char save_path_[256] = "demo-world.vfw";
  char load_path_[256] = "";
  int ui_size_ = 128, ui_chunk_ = 16, ui_metric_ = 0, ui_backend_ = 0;
  float ui_max_distance_ = 32;
  VkDescriptorPool imgui_pool_ = VK_NULL_HANDLE;
  int screenshots_ = 0;
};

}  // namespace voxfield::demo

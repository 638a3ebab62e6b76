// voxfield-demo — paint a voxel world and watch its distance fields follow.
//
// The reference dissertation's demonstration application: a window, a world drawn by ray
// marching through an exact distance field, sphere brushes that place, carve and paint, and a
// benchmark mode replaying the dissertation's seeded stream of edits. Frames come from voxfield's
// Vulkan ray marcher when there is a Vulkan device for it (--backend), otherwise from the CPU
// renderer — presented through a Vulkan swapchain, or through OpenGL on machines with no usable
// Vulkan device at all; the title and the panel say which.
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl2.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "demo.h"
#include "voxfield/edit_stream.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/gpu_render_vulkan.h"
#include "voxfield/image.h"
#include "voxfield/png.h"

namespace voxfield::demo {

Demo::Demo(const Options& o) : options_(o) {
  world_ = o.load.empty() ? std::make_unique<DemoWorld>(o.world)
                          : std::make_unique<DemoWorld>(o.world, o.load);
  try {
    vk_ = std::make_unique<VulkanWindow>(o.width, o.height, "voxfield-demo", o.validation);
  } catch (const WindowError& e) {
    no_vulkan_ = e.what();
    std::cerr << "voxfield-demo: no Vulkan window (" << no_vulkan_
              << "); showing the CPU renderer's frames through OpenGL\n";
    gl_ = std::make_unique<GlWindow>(o.width, o.height, "voxfield-demo");
  }
  ui_size_ = o.world.size;
  ui_chunk_ = o.world.chunk_edge;
  ui_max_distance_ = static_cast<float>(o.world.max_distance_vox);
  ui_metric_ = static_cast<int>(o.world.metric);
  vectors_settings_ = o.vectors;
  terrain_settings_ = o.terrain;
  choose_path(o.backend);
  // Fields not followed on a device are the host's: built now, so that a world too large for
  // them (the memory limit) is refused at start-up rather than by the first frame.
  if (!world_->device_scene()) (void)world_->scene();
  frame_camera();
  if (o.mode == "vectors") set_mode(Mode::kVectors);
  if (o.mode == "terrain") set_mode(Mode::kTerrain);

  // Input callbacks first: the ImGui backend chains to them.
  glfwSetWindowUserPointer(glfw(), this);
  glfwSetScrollCallback(glfw(), [](GLFWwindow* w, double, double dy) {
    static_cast<Demo*>(glfwGetWindowUserPointer(w))->scroll_ += dy;
  });
  // Presses are queued from the callbacks, so a click or a key tap shorter than a frame (frames
  // are slow on software Vulkan) is never lost between two polls of the button state.
  // Ctrl+Q quits as the window's close button does (the frame loop ends, --csv is complete); the
  // press's own modifiers are checked, since Ctrl may be up again by the next frame. Q is the key
  // the keyboard layout calls "q" (Ctrl+A's place on AZERTY), the US position where it has no name.
  glfwSetKeyCallback(glfw(), [](GLFWwindow* w, int key, int scancode, int action, int mods) {
    if (action != GLFW_PRESS) return;
    const char* name = glfwGetKeyName(key, scancode);
    const bool q = name ? std::strcmp(name, "q") == 0 : key == GLFW_KEY_Q;
    if (q && (mods & GLFW_MOD_CONTROL) != 0) glfwSetWindowShouldClose(w, GLFW_TRUE);
    static_cast<Demo*>(glfwGetWindowUserPointer(w))->keys_pressed_.push_back(key);
  });
  glfwSetMouseButtonCallback(glfw(), [](GLFWwindow* w, int button, int action, int) {
    if (action == GLFW_PRESS)
      static_cast<Demo*>(glfwGetWindowUserPointer(w))->clicks_.push_back(button);
  });
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
  ImGui::StyleColorsDark();
  if (gl_) {
    ImGui_ImplGlfw_InitForOpenGL(glfw(), true);
    ImGui_ImplOpenGL2_Init();
    return;
  }
  VulkanWindow& vw = *vk_;
  ImGui_ImplGlfw_InitForVulkan(vw.window(), true);
  VkInstance instance = vw.instance();
  ImGui_ImplVulkan_LoadFunctions(
      [](const char* name, void* user) {
        return vkGetInstanceProcAddr(*static_cast<VkInstance*>(user), name);
      },
      &instance);
  VkDescriptorPoolSize sizes{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 4};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  dp.maxSets = 4;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &sizes;
  if (vkCreateDescriptorPool(vw.device(), &dp, nullptr, &imgui_pool_) != VK_SUCCESS)
    throw WindowError("cannot create the panel's descriptor pool");
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = vw.instance();
  info.PhysicalDevice = vw.physical();
  info.Device = vw.device();
  info.QueueFamily = vw.queue_family();
  info.Queue = vw.queue();
  info.DescriptorPool = imgui_pool_;
  info.MinImageCount = vw.min_image_count();
  info.ImageCount = vw.image_count();
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  ImGui_ImplVulkan_Init(&info, vw.render_pass());
  vw.run_once([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
  ImGui_ImplVulkan_DestroyFontUploadObjects();
}

Demo::~Demo() {
  wait_idle();
  if (vk_) {
    ImGui_ImplVulkan_Shutdown();
  } else {
    ImGui_ImplOpenGL2_Shutdown();
  }
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  vectors_.reset();
  terrain_.reset();
  world_->stop_device();
  path_ = RenderPath{};  // voxfield's objects on the device go before the device
  if (imgui_pool_) vkDestroyDescriptorPool(vk_->device(), imgui_pool_, nullptr);
}

void Demo::choose_path(const std::string& backend) {
  wait_idle();
  const bool vectors = vectors_ != nullptr, terrain = terrain_ != nullptr;
  vectors_.reset();  // its field may live on the device about to go
  terrain_.reset();
  world_->stop_device();
  path_ = RenderPath{};
  const Backend b = parse_backend(backend);
  if (!vk_) {
    path_.why = "CPU renderer, shown through OpenGL (" + gl_->renderer_name() +
                "): no usable Vulkan device";
  } else if (b == Backend::kCpu) {
    path_.why = "CPU renderer (--backend cpu)";
  } else if (b == Backend::kAuto && !vk_->device_is_hardware()) {
    path_.why = "CPU renderer (auto: " + vk_->device_name() +
                " is not a hardware GPU; --backend vulkan uses it)";
  } else {
    try {
      path_.context = gpu::adopt({vk_->instance(), vk_->physical(), vk_->device(), vk_->queue(),
                                  vk_->queue_family(), vk_->float64()});
      path_.renderer = std::make_unique<gpu::SceneRenderer>(path_.context);
      path_.why = "Vulkan ray marcher on " + vk_->device_name();
    } catch (const Error& e) {
      path_ = RenderPath{};
      path_.why = std::string("CPU renderer (no usable Vulkan compute: ") + e.what() + ")";
    }
    // Fields computed and kept where they are drawn: on a hardware GPU, or when asked (on a CPU
    // device the host computes them faster).
    path_.device_fields =
        path_.renderer != nullptr &&
        (options_.fields == "device" || (options_.fields == "auto" && vk_->device_is_hardware()));
    if (path_.device_fields)
      path_.why += follow_on_device() ? ", its fields computed there" : ", fields from the host";
  }
  ui_backend_ = path_.renderer ? 1 : 0;
  std::cerr << "voxfield-demo: " << path_.why << "\n";
  if (vectors) set_mode(Mode::kVectors);
  if (terrain) set_mode(Mode::kTerrain);
}

bool Demo::follow_on_device() {
  try {
    world_->follow_on_device(path_.context);
    return true;
  } catch (const Error& e) {
    status_ = std::string("fields stay on the host: ") + e.what();
    std::cerr << "voxfield-demo: " << status_ << "\n";
    return false;
  }
}

void Demo::replace_world(std::unique_ptr<DemoWorld> next, const std::string& done) {
  // Fields meant for the host are built before the swap, so that a world too large for them
  // leaves the current one in place; fields meant for the device are built there after the
  // current world's copy has gone (never two on the device), on the host if the device refuses.
  if (!path_.device_fields) (void)next->scene();
  wait_idle();
  world_->stop_device();
  std::unique_ptr<DemoWorld> previous = std::exchange(world_, std::move(next));
  if (path_.device_fields && !follow_on_device()) {
    try {
      (void)world_->scene();
    } catch (const Error&) {
      // Neither the device nor the host can hold the new world's fields: the previous world
      // comes back, where its fields were.
      world_ = std::move(previous);
      if (!follow_on_device()) (void)world_->scene();
      throw;
    }
  }
  frame_camera();
  status_ = done;
}

void Demo::frame_camera() {
  const Box3i box = world_->box();
  const Vec3i s = box.size();
  const Vec3d centre{box.begin.x + s.x / 2.0, box.begin.y + s.y / 2.0, box.begin.z + s.z * 0.3};
  camera_.look({box.begin.x - s.x * 0.25, box.begin.y - s.y * 0.25, box.begin.z + s.z * 1.1},
               centre);
}

std::string Demo::title() const {
  if (terrain_)
    return std::string("voxfield-demo — terrain — ") + (terrain_->on_gpu() && vk_
                                                            ? "GPU marching cubes and indirect draw"
                                                            : "CPU meshes and rasteriser");
  if (vectors_)
    return std::string("voxfield-demo — vectors — ") +
           (vectors_->on_gpu() ? "Vulkan passes" : "CPU passes");
  return "voxfield-demo — " + world_->origin() + " — " +
         (gpu_can_draw() ? "Vulkan ray marcher" : "CPU renderer");
}

bool Demo::draw(VulkanWindow::Screenshot* shot) {
  if (vk_) {
    ImGui_ImplVulkan_NewFrame();
  } else {
    ImGui_ImplOpenGL2_NewFrame();
  }
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  panel();
  if (show_help_) help();
  ImGui::Render();
  if (vectors_) return draw_vectors(shot);
  if (terrain_) return draw_terrain(shot);

  RenderOptions ro;
  ro.width = width();
  ro.height = height();
  ro.view = view_;
  ro.error_algorithm = error_algorithm_;
  const Camera cam = camera_.camera();
  const auto t0 = Clock::now();
  if (gl_) {
    const Image img = render(world_->scene(), cam, ro);
    gl_->draw_frame(
        img, [] { ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData()); }, shot);
    last_.render_ms = ms_between(t0, Clock::now());
    return true;
  }
  std::function<void(VkCommandBuffer, VkImage)> fill;
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {static_cast<std::uint32_t>(ro.width), static_cast<std::uint32_t>(ro.height),
                      1};
  if (gpu_can_draw()) {
    gpu::DeviceRenderScene* device_scene = world_->device_scene();
    if (!device_scene) path_.renderer->sync(world_->scene());
    // (device_scene by value: the frame is recorded after this block ends.)
    fill = [&, device_scene](VkCommandBuffer cmd, VkImage image) {
      const gpu::PixelOrder order = vk_->bgra() ? gpu::PixelOrder::kBgra : gpu::PixelOrder::kRgba;
      const VkBuffer pixels = device_scene
                                  ? gpu::record_render(*device_scene, cmd, cam, ro, order)
                                  : gpu::record_render(*path_.renderer, cmd, cam, ro, order);
      vkCmdCopyBufferToImage(cmd, pixels, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    };
  } else {
    fill = stage_cpu_frame(render(world_->scene(), cam, ro));
  }
  const bool drawn = vk_->draw_frame(
      fill, [](VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); },
      shot);
  if (gpu_can_draw()) wait_idle();  // the GPU frame's time includes its execution
  last_.render_ms = ms_between(t0, Clock::now());
  return drawn;
}

std::function<void(VkCommandBuffer, VkImage)> Demo::stage_cpu_frame(const Image& img) {
  void* mapped = nullptr;
  const VkBuffer staging =
      vk_->staging(static_cast<VkDeviceSize>(img.width) * img.height * 4, &mapped);
  auto* dst = static_cast<std::uint8_t*>(mapped);
  const bool bgra = vk_->bgra();
  for (std::size_t i = 0; i < static_cast<std::size_t>(img.width) * img.height; ++i) {
    dst[4 * i + 0] = img.rgb[3 * i + (bgra ? 2 : 0)];
    dst[4 * i + 1] = img.rgb[3 * i + 1];
    dst[4 * i + 2] = img.rgb[3 * i + (bgra ? 0 : 2)];
    dst[4 * i + 3] = 255;
  }
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {static_cast<std::uint32_t>(img.width), static_cast<std::uint32_t>(img.height),
                      1};
  return [staging, copy](VkCommandBuffer cmd, VkImage image) {
    vkCmdCopyBufferToImage(cmd, staging, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
  };
}

void Demo::take_screenshot(const std::string& path) {
  VulkanWindow::Screenshot shot;
  while (!draw(&shot)) {
  }
  if (shot.rgb.empty()) {
    status_ = "screenshots need a swapchain that transfers can read; this one cannot";
    return;
  }
  Image img(shot.width, shot.height);
  img.rgb = std::move(shot.rgb);
  write_png(img, path);
  status_ = "saved " + path;
  std::cerr << "voxfield-demo: saved " << path << "\n";
}

int Demo::run() {
  std::ofstream csv;
  if (!options_.csv.empty()) {
    csv.open(options_.csv);
    if (!csv) throw IoError(options_.csv + ": cannot create");
    // The GPU columns are voxfield's own traffic in the frame (scene copies and the ray marcher's
    // work; the demo's swapchain submission is not voxfield's): zero on the CPU renderer.
    // In the vectors mode the edits column counts the field's steps so far.
    // The terrain mode's columns: its last edit's re-mesh time, the mesh's triangles and the bytes
    // the edit would upload to a renderer keeping the field on the GPU (zero in the other modes).
    csv << "frame,frame_ms,update_ms,render_ms,edits,gpu_submits,gpu_dispatches,gpu_bytes_up,gpu_"
           "bytes_down,mesh_ms,triangles,bytes_up\n";
  }
  // Benchmark mode: the dissertation's seeded edits, one every interval of wall time, radii up to
  // the chunk edge - 1, with the camera circling the world.
  std::optional<RandomEditStream> stream;
  std::mt19937_64 terrain_edits(options_.world.seed);
  if (options_.benchmark && !terrain_)
    stream.emplace(world_->box(), options_.world.seed, 1, world_->settings().chunk_edge - 1);
  const auto start = Clock::now();
  auto previous = start;
  std::int64_t streamed = 0;
  for (int frame = 0; !glfwWindowShouldClose(glfw()); ++frame) {
    if (options_.frames > 0 && frame >= options_.frames) break;
    glfwPollEvents();
    const auto t0 = Clock::now();
    const gpu::Counters gpu_before = path_.context ? path_.context->counters() : gpu::Counters{};
    const double dt_s = std::min(0.1, ms_between(previous, t0) / 1000.0);
    previous = t0;
    double update_ms = 0;
    if (terrain_ && options_.benchmark) {
      // The camera circles the terrain; a seeded brush lands on the surface every interval,
      // added or carved in turn, with the material of its turn (the stream's count, so skipped
      // brushes keep the turns of those applied).
      const Box3i box = terrain_->box();
      const Vec3i s = box.size();
      const double angle = 0.6 + frame * 0.02;
      const Vec3d centre{s.x / 2.0, s.y / 2.0, s.z * 0.3};
      const double r = 1.05 * std::max(s.x, s.y);
      // Looking a little to the left of the terrain's centre, so it shows beside the panel.
      const Vec3d right{-std::sin(angle), std::cos(angle), 0};
      camera_.look(
          centre + Vec3d{r * std::cos(angle), r * std::sin(angle), 0.75 * std::max(s.x, s.y)},
          centre - right * (0.3 * s.x));
      // At most four brushes a frame (a hand's pace); those a slow frame let pass are skipped, not
      // queued, so a slow device (a software one under validation) does not fall ever further
      // behind.
      const auto due = static_cast<std::int64_t>(ms_between(start, t0) / options_.interval_ms) + 1;
      streamed = std::max(streamed, due - 4);
      const auto a = Clock::now();
      for (; streamed < due; ++streamed) {
        const double x = static_cast<double>(terrain_edits() % static_cast<unsigned>(s.x));
        const double y = static_cast<double>(terrain_edits() % static_cast<unsigned>(s.y));
        terrain_->edit_above(x, y, streamed % 2 == 0, static_cast<std::uint8_t>(2 + streamed % 3));
      }
      update_ms = ms_between(a, Clock::now());
      last_.update_ms = update_ms;
    } else if (vectors_) {
      if (options_.benchmark) {  // the camera circles the agents' box
        const double angle = 0.6 + frame * 0.02;
        // Looking a little to the left of the box, so it shows beside the panel.
        const Vec3d eye{13 * std::cos(angle), 13 * std::sin(angle), 7};
        const Vec3d right{-std::sin(angle), std::cos(angle), 0};  // the camera's right
        camera_.look(eye, Vec3d{0, 0, -1.5} - right * 6.0);
      } else {
        handle_input(dt_s);
      }
      const auto a = Clock::now();
      vectors_->advance(options_.benchmark ? 1.0 / 60 : dt_s);
      update_ms = ms_between(a, Clock::now());
      last_.update_ms = update_ms;
    } else if (stream) {
      const Box3i box = world_->box();
      const Vec3i s = box.size();
      const double angle = 0.6 + frame * 0.02;
      const Vec3d centre{box.begin.x + s.x / 2.0, box.begin.y + s.y / 2.0, box.begin.z + s.z * 0.3};
      const double r = 0.85 * std::max(s.x, s.y);
      camera_.look(centre + Vec3d{r * std::cos(angle), r * std::sin(angle), s.z * 0.9}, centre);
      // The edits due by now (one per interval), applied together with one incremental update.
      const auto due = static_cast<std::int64_t>(ms_between(start, t0) / options_.interval_ms) + 1;
      std::vector<Edit> batch;
      for (; streamed < due; ++streamed) batch.push_back(stream->next());
      if (!batch.empty()) {
        const auto a = Clock::now();
        world_->apply(batch);
        update_ms = ms_between(a, Clock::now());
      }
      last_.update_ms = update_ms;
    } else {
      handle_input(dt_s);
    }
    const bool last_frame = options_.frames > 0 && frame + 1 == options_.frames;
    if (last_frame && !options_.screenshot.empty()) {
      take_screenshot(options_.screenshot);
    } else {
      while (!draw(nullptr)) {
      }
    }
    glfwSetWindowTitle(glfw(), title().c_str());
    last_.frame_ms = ms_between(t0, Clock::now());
    frame_history_.push_back(static_cast<float>(last_.frame_ms));
    if (frame_history_.size() > 120) frame_history_.pop_front();
    if (csv.is_open()) {
      const gpu::Counters g = path_.context ? path_.context->counters() : gpu::Counters{};
      csv << frame << "," << last_.frame_ms << "," << update_ms << "," << last_.render_ms << ","
          << (vectors_   ? vectors_->steps()
              : terrain_ ? terrain_->edits()
                         : world_->edits())
          << "," << g.submits - gpu_before.submits << "," << g.dispatches - gpu_before.dispatches
          << "," << g.bytes_uploaded - gpu_before.bytes_uploaded << ","
          << g.bytes_downloaded - gpu_before.bytes_downloaded << ","
          << (terrain_ ? terrain_->last_mesh_ms() : 0.0) << ","
          << (terrain_ ? terrain_->triangles() : 0) << ","
          << (terrain_ ? terrain_->last_bytes_up() : 0) << "\n";
    }
  }
  if (csv.is_open()) {
    csv.close();
    if (!csv) throw IoError(options_.csv + ": write failed");
  }
  return 0;
}

}  // namespace voxfield::demo

int main(int argc, char** argv) {
  using namespace voxfield;
  using namespace voxfield::demo;
  install_signal_cleanup();  // a save interrupted by Ctrl-C leaves no temporary behind
  Options o;
  CLI::App app{"voxfield-demo: paint a voxel world and watch its distance fields follow"};
  std::string metric = "manhattan";
  app.add_option("--world", o.world.size, "terrain size N (N x N x N/2 voxels)")
      ->check(CLI::Range(16, 1024));
  app.add_option("--chunk", o.world.chunk_edge, "chunk edge (8, 16, 32, 64, 128)");
  app.add_option("--load", o.load, "start from a .vox, .vfw or .npy file instead of the terrain");
  app.add_option("--backend", o.backend,
                 "who draws: cpu, vulkan, auto (a hardware GPU, else the CPU)")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  app.add_option("--fields", o.fields,
                 "with the Vulkan ray marcher: where the fields are computed and kept — device, "
                 "host, or auto (the device when it is a hardware GPU)")
      ->check(CLI::IsMember({"auto", "host", "device"}));
  app.add_option("--metric", metric, "metric of the field rays skip by")
      ->check(CLI::IsMember({"manhattan", "chebyshev", "euclidean"}));
  app.add_option("--max-distance", o.world.max_distance_vox,
                 "its max distance (clamp) in voxels: an edit's reach");
  app.add_option("--width", o.width, "window width")->check(CLI::Range(64, 8192));
  app.add_option("--height", o.height, "window height")->check(CLI::Range(64, 8192));
  app.add_flag("--validation", o.validation,
               "enable the Khronos validation layer (messages on stderr)");
  app.add_flag("--benchmark", o.benchmark,
               "replay the dissertation's seeded edits and exit after --frames");
  app.add_option("--frames", o.frames, "exit after N frames (benchmark mode: 300 by default)")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--seed", o.world.seed, "seed of the terrain and the benchmark's edits");
  app.add_option("--interval-ms", o.interval_ms, "time between the benchmark's edits")
      ->check(CLI::PositiveNumber);
  app.add_option("--csv", o.csv,
                 "one row per frame (frame_ms, update_ms, render_ms, edits, GPU traffic)");
  app.add_option("--screenshot", o.screenshot, "with --frames: save the last frame as PNG");
  app.add_option("--mode", o.mode,
                 "world (paint voxels, fields follow), vectors (the vector-field paper's agents, "
                 "their field and a reactive sheet) or terrain (smooth terrain shaped by brushes, "
                 "re-meshed chunk by chunk)")
      ->check(CLI::IsMember({"world", "vectors", "terrain"}));
  app.add_option("--terrain-size", o.terrain.size, "terrain mode: samples along x and y")
      ->check(CLI::IsMember({64, 128, 192, 256}));
  app.add_option("--terrain-storage", o.terrain.storage, "terrain mode: 0 i8, 1 i16, 2 f32")
      ->check(CLI::Range(0, 2));
  app.add_option("--terrain-mesher", o.terrain.mesher,
                 "terrain mode: 0 marching cubes, 1 surface nets, 2 dual contouring")
      ->check(CLI::Range(0, 2));
  app.add_option("--vector-resolution", o.vectors.resolution, "vectors mode: voxels per axis")
      ->check(CLI::IsMember({16, 32, 64, 128}));
  app.add_option("--vector-sources", o.vectors.sources, "vectors mode: agents")
      ->check(CLI::Range(1, 1000));
  app.add_option("--vector-algorithm", o.vectors.algorithm,
                 "vectors mode: 0 brute, 1 splat, 2 jfa, 3 jfa+1, 4 jfa+2")
      ->check(CLI::Range(0, 4));
  CLI11_PARSE(app, argc, argv);
  if (o.benchmark && o.frames == 0) o.frames = 300;
  glfwSetErrorCallback([](int code, const char* message) {
    std::cerr << "voxfield-demo: GLFW error " << code << ": " << message << "\n";
  });
  try {
    o.world.metric = parse_metric(metric);
    GlfwSession glfw;
    Demo demo(o);
    return demo.run();
  } catch (const WindowError& e) {
    std::cerr << "voxfield-demo: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "voxfield-demo: " << e.what() << "\n";
    return 1;
  }
}

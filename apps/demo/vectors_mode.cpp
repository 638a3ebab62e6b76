// voxfield-demo — the vectors mode (vectors_mode.h).
#include "vectors_mode.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>

#include "clock.h"

namespace voxfield::demo {
namespace {

const VectorAlgorithm kVectorAlgorithms[] = {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat,
                                             VectorAlgorithm::kJfa, VectorAlgorithm::kJfaPlus1,
                                             VectorAlgorithm::kJfaPlus2};
const VectorStorage kVectorStorages[] = {VectorStorage::kRgba8, VectorStorage::kRgba16f,
                                         VectorStorage::kRgba32f};
constexpr int kMaxStepsPerFrame = 4;

VectorVolume volume_of(const VectorsSettings& s) {
  const int n = s.resolution;
  return vector_agents_volume({n, n, s.quarter_z ? std::max(1, n / 4) : n});
}

}  // namespace

VectorsMode::VectorsMode(std::shared_ptr<gpu::Context> context, const VectorsSettings& settings)
    : settings_(settings),
      volume_(volume_of(settings)),
      agents_(settings.sources, 2026),
      scheduler_(1.0 / settings.hz, kMaxStepsPerFrame) {
  VectorOptions options;
  options.algorithm = kVectorAlgorithms[settings.algorithm];
  const VectorStorage storage = kVectorStorages[settings.storage];
  if (context)
    gpu_sim_ = std::make_unique<gpu::VectorSimulation>(std::move(context), volume_, storage,
                                                       options, settings.decay_per_s);
  else
    cpu_sim_.emplace(volume_, storage, options, settings.decay_per_s);
}

int VectorsMode::advance(double frame_s) {
  const int due = scheduler_.advance(frame_s);
  const double dt = scheduler_.dt_s();
  const auto start = std::chrono::steady_clock::now();
  if (has_pending_) {  // the last frame was not drawn (its swapchain was out of date): run it now
    gpu_sim_->step(pending_, dt);
    has_pending_ = false;
  }
  for (int i = 0; i < due; ++i) {
    const std::vector<VectorSource> sources = agents_.step(dt);
    if (cpu_sim_) {
      cpu_sim_->step(sources, dt);
      cpu_times_ = cpu_sim_->last_times();
    } else if (i + 1 < due) {
      gpu_sim_->step(sources, dt);  // catch-up steps: submitted on their own
      gpu_times_ = gpu_sim_->last_timings();
    } else {
      pending_ = sources;  // the frame's own step: recorded with its picture
      has_pending_ = true;
    }
    ++steps_;
  }
  if (due > 0) last_step_ms_ = ms_since(start) / due;
  return due;
}

VectorViewOptions VectorsMode::view(const FlyCamera& camera, int width, int height) const {
  VectorViewOptions v;
  v.width = width;
  v.height = height;
  v.auto_eye = false;
  v.eye = camera.eye;
  v.look_at = camera.eye + camera.forward();
  v.fov_deg = camera.fov_degrees;
  v.density = settings_.density;
  v.sheet = settings_.sheet;
  v.sheet_push = settings_.sheet_push;
  return v;
}

Image VectorsMode::render(const FlyCamera& camera, int width, int height) const {
  return render_vectors(volume_, cpu_sim_->field(), view(camera, width, height));
}

VkBuffer VectorsMode::record_frame(VkCommandBuffer cmd, const FlyCamera& camera, int width,
                                   int height, gpu::PixelOrder order) {
  if (has_pending_) {
    gpu::record_step(*gpu_sim_, cmd, pending_, scheduler_.dt_s());
    has_pending_ = false;
  }
  return gpu::record_render(*gpu_sim_, cmd, view(camera, width, height), order);
}

void VectorsMode::frame(FlyCamera& camera) {
  camera.look({-9.5, -12.5, 7.5}, {0, 0, -1.5});
}

bool VectorsMode::panel(VectorsSettings& s) {
  bool changed = false;
  const char* resolutions[] = {"16", "32", "64", "128"};
  int r = s.resolution == 16 ? 0 : s.resolution == 32 ? 1 : s.resolution == 64 ? 2 : 3;
  if (ImGui::Combo("resolution", &r, resolutions, 4)) {
    s.resolution = 16 << r;
    changed = true;
  }
  changed |= ImGui::Checkbox("quarter z (the paper's reduced axis)", &s.quarter_z);
  const char* algorithms[] = {"brute", "splat", "jfa", "jfa+1", "jfa+2"};
  changed |= ImGui::Combo("algorithm", &s.algorithm, algorithms, 5);
  const char* storages[] = {"rgba8", "rgba16f", "rgba32f"};
  changed |= ImGui::Combo("storage", &s.storage, storages, 3);
  changed |= ImGui::SliderFloat("decay /s", &s.decay_per_s, 0, 8);
  changed |= ImGui::SliderFloat("steps /s", &s.hz, 10, 240, "%.0f");
  changed |= ImGui::SliderInt("sources", &s.sources, 1, 200);
  // The view changes without a rebuild.
  ImGui::Checkbox("reactive sheet", &s.sheet);
  ImGui::SliderFloat("sheet push", &s.sheet_push, 0, 3);
  ImGui::SliderFloat("fog density", &s.density, 0.5f, 40, "%.1f");
  return changed;
}

void VectorsMode::stats_panel() const {
  if (on_gpu())
    ImGui::TextWrapped(
        "%lld steps of %.1f ms on Vulkan; each frame's last step is recorded with its "
        "picture",
        static_cast<long long>(steps_), 1000.0 * scheduler_.dt_s());
  else
    ImGui::TextWrapped("%lld steps of %.1f ms on the CPU, %.2f ms per step",
                       static_cast<long long>(steps_), 1000.0 * scheduler_.dt_s(), last_step_ms_);
  if (scheduler_.dropped_s() > 0)
    ImGui::Text("%.2f s dropped (more than %d steps due in a frame)", scheduler_.dropped_s(),
                kMaxStepsPerFrame);
  if (cpu_sim_) {
    const VectorPassTimes& t = cpu_times_;
    ImGui::Text("search %.3f  seed %.3f  flood %.3f (%d passes)", t.search_ms, t.seed_ms,
                t.flood_ms, t.flood_passes);
    ImGui::Text("convert + decay + blend %.3f ms", t.convert_ms + t.blend_ms);
  } else {
    // Timestamps come from steps submitted on their own (catch-up steps); a software device
    // (lavapipe) times its CPU emulation.
    if (gpu_times_.empty()) ImGui::TextDisabled("device passes: timed when steps catch up");
    for (const gpu::PassTiming& t : gpu_times_)
      ImGui::Text("device %s %.3f ms", t.pass.c_str(), t.ms);
  }
}

}  // namespace voxfield::demo

// voxfield-demo — the vectors mode: the vector-field paper's agents flying through a volume, their
// field stepped at a fixed rate (generation, decay, blend), drawn by the visualiser with the
// reactive sheet — a cloth the field pushes away from the agents, sampled through the same
// functions as voxfield_vectors.glsl. On the Vulkan path the field lives on the device: catch-up
// steps are submitted on their own, the frame's last step and the picture are recorded into the
// frame's command buffer (gpu_vectors_vulkan.h); otherwise the CPU steps and draws.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fly_camera.h"
#include "voxfield/gpu_vectors_vulkan.h"
#include "voxfield/vector_agents.h"
#include "voxfield/vectors.h"

namespace voxfield::demo {

struct VectorsSettings {
  int resolution = 64;  // voxels per axis (the paper's quarter axis: z / 4 when quarter_z)
  bool quarter_z = false;
  int algorithm = 1;  // index into kVectorAlgorithms: splat
  int storage = 0;    // rgba8, rgba16f, rgba32f
  float decay_per_s = 1.0f;
  float hz = 60;  // fixed steps per second
  int sources = 20;
  bool sheet = true;
  float sheet_push = 0.8f;
  float density = 8;
};

class VectorsMode {
 public:
  // `context` null: the CPU steps and draws. Throws voxfield::Error for settings it refuses.
  VectorsMode(std::shared_ptr<gpu::Context> context, const VectorsSettings& settings);

  // Advances the fixed-step clock by `frame_s`: runs the steps due (at most 4), except that on the
  // Vulkan path the last one is left for record_frame(). Returns how many steps are due.
  int advance(double frame_s);
  // The CPU path's picture.
  Image render(const FlyCamera& camera, int width, int height) const;
  // The Vulkan path: the pending step (if any) and the picture, recorded into `cmd`; returns the
  // buffer of packed pixels.
  VkBuffer record_frame(VkCommandBuffer cmd, const FlyCamera& camera, int width, int height,
                        gpu::PixelOrder order);

  // Where a camera should start: looking at the agents' box from above one corner.
  static void frame(FlyCamera& camera);
  // The panel's section; returns true when the settings changed (rebuild the mode).
  static bool panel(VectorsSettings& s);
  void stats_panel() const;

  bool on_gpu() const { return gpu_sim_ != nullptr; }
  std::int64_t steps() const { return steps_; }
  double last_step_ms() const { return last_step_ms_; }
  const VectorsSettings& settings() const { return settings_; }
  const VectorVolume& volume() const { return volume_; }

 private:
  VectorViewOptions view(const FlyCamera& camera, int width, int height) const;

  VectorsSettings settings_;
  VectorVolume volume_;
  VectorAgents agents_;
  FixedStepScheduler scheduler_;
  std::optional<VectorSimulation> cpu_sim_;
  std::unique_ptr<gpu::VectorSimulation> gpu_sim_;
  std::vector<VectorSource> pending_;  // the Vulkan path's step left for the frame
  bool has_pending_ = false;
  std::int64_t steps_ = 0;
  double last_step_ms_ = 0;
  VectorPassTimes cpu_times_;
  std::vector<gpu::PassTiming> gpu_times_;
};

}  // namespace voxfield::demo

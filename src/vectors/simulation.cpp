// A step of the dynamic field (Hamlin, "Volumetric Interaction", section 3.3: decay and blend) and
// the fixed-step scheduler that drives it. The paper's "fixed time step" was a minimum interval
// that never caught up after a slow frame; FixedStepScheduler keeps an accumulator and runs whole
// steps, capped per frame so a stall cannot snowball.
#include <cmath>
#include <string>

#include "vector_internal.h"
#include "voxfield/error.h"

namespace voxfield {

VectorTexel blend_vector_texels(const VectorTexel& current, const VectorTexel& previous,
                                double decay_per_s, double dt_s) {
  const double sc = current.strength;
  const double sp = std::max(0.0, previous.strength - decay_per_s * dt_s);
  const double total = sc + sp;
  // Both gone (or decayed away): the zero texel, as where no source ever was — not the old
  // direction at strength 0, which would keep a stale direction in the texture.
  if (!(total > 0)) return {};
  const double w = sc / total;
  const Vec3d n = Vec3d{current.x, current.y, current.z} * w +
                  Vec3d{previous.x, previous.y, previous.z} * (1.0 - w);
  const double length = n.length();
  VectorTexel out;
  if (length > 0) {
    out.x = static_cast<float>(n.x / length);
    out.y = static_cast<float>(n.y / length);
    out.z = static_cast<float>(n.z / length);
  }
  out.strength = static_cast<float>(std::max(sc, sp));
  return out;
}

VectorSimulation::VectorSimulation(const VectorVolume& volume, VectorStorage storage,
                                   VectorOptions options, double decay_per_s)
    : volume_(volume), options_(options), decay_per_s_(decay_per_s) {
  volume_.validate();
  if (!std::isfinite(decay_per_s) || decay_per_s < 0)
    throw InvalidArgument("vector simulation: the decay per second must be finite and >= 0");
  options_.interrupter = nullptr;  // never kept: step() is the long-lived object's only work
  current_ = VectorTexture(volume_.resolution, storage);
  field_ = VectorTexture(volume_.resolution, storage);
  next_ = VectorTexture(volume_.resolution, storage);
}

void VectorSimulation::step(std::span<const VectorSource> sources, double dt_s) {
  if (!std::isfinite(dt_s) || dt_s <= 0)
    throw InvalidArgument("vector simulation: the time step must be finite and > 0");
  VectorPassTimes t;
  const std::vector<std::int32_t> winners = vector_winners(volume_, sources, options_, &t);
  std::int64_t start = detail::vectors::now_ns();
  write_vector_texels(volume_, sources, winners, current_);
  t.convert_ms = detail::vectors::ms_since(start);

  // Decay and blend in one sweep (the decay is one subtraction per texel; timed together).
  start = detail::vectors::now_ns();
  detail::vectors::for_each_slab(volume_, nullptr, "vector blend", [&](int k0, int k1) {
    const std::int64_t b = volume_.index(0, 0, k0), e = volume_.index(0, 0, k1);
    for (std::int64_t i = b; i < e; ++i)
      next_.set(i, blend_vector_texels(current_.get(i), field_.get(i), decay_per_s_, dt_s));
  });
  t.blend_ms = detail::vectors::ms_since(start);
  std::swap(field_, next_);
  times_ = t;
  ++steps_;
}

FixedStepScheduler::FixedStepScheduler(double dt_s, int max_steps_per_frame)
    : dt_s_(dt_s), max_steps_(max_steps_per_frame) {
  if (!std::isfinite(dt_s) || dt_s <= 0)
    throw InvalidArgument("fixed step: the time step must be finite and > 0");
  if (max_steps_per_frame < 1)
    throw InvalidArgument("fixed step: at least one step per frame must be allowed");
}

int FixedStepScheduler::advance(double frame_s) {
  if (!std::isfinite(frame_s) || frame_s < 0)
    throw InvalidArgument("fixed step: a frame time must be finite and >= 0");
  accumulator_s_ += frame_s;
  const double due = std::floor(accumulator_s_ / dt_s_);
  const int steps = due >= max_steps_ ? max_steps_ : static_cast<int>(due);
  accumulator_s_ -= steps * dt_s_;
  if (accumulator_s_ >= dt_s_) {  // the cap held steps back: drop them, keep the fraction
    const double keep = std::fmod(accumulator_s_, dt_s_);
    dropped_s_ += accumulator_s_ - keep;
    accumulator_s_ = keep;
  }
  return steps;
}

}  // namespace voxfield

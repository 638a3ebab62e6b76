// voxfield GPU backend — the vector-field module's GPU entry points (gpu_vectors.h) on the passes
// of vector_engine.h: a generation, a simulation whose textures stay on the device, the visualiser.
#include <chrono>
#include <cmath>
#include <cstring>

#include "vector_engine.h"
#include "voxfield/error.h"
#include "voxfield/gpu_vectors_vulkan.h"

namespace voxfield::gpu {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Reads `bytes` of `src` back through the context's read-back buffer (one submit).
void download(Context::Impl& c, DescriptorArena& sets, Buffer& src, std::uint64_t bytes,
              std::uint8_t* out, VectorGpuStats* stats) {
  Buffer& readback = c.readback_buffer(bytes);
  Recorder rec(c, &sets);
  rec.copy(src, 0, readback, 0, bytes);
  rec.submit();
  std::memcpy(out, readback.mapped(), bytes);
  if (stats) {
    stats->bytes_downloaded += static_cast<std::int64_t>(bytes);
    ++stats->submits;
    ++stats->fence_waits;
  }
}

VectorTexture download_texture(VectorEngine& e, Context::Impl& c, Buffer& texels,
                               VectorGpuStats* stats) {
  VectorTexture out(e.volume().resolution, e.storage());
  download(c, e.sets(), texels, e.texture_bytes(), out.data(), stats);
  return out;
}

Image download_image(VectorEngine& e, Context::Impl& c, Buffer& pixels, const VectorViewOptions& v,
                     VectorGpuStats* stats) {
  Image image(v.width, v.height);
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(v.width) * v.height * 4);
  download(c, e.sets(), pixels, rgba.size(), rgba.data(), stats);
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) {
      const std::uint8_t* from = rgba.data() + (static_cast<std::size_t>(y) * v.width + x) * 4;
      std::memcpy(image.pixel(x, y), from, 3);
    }
  return image;
}

// The stages an application may read a recorded field in: compute and transfers, and vertex and
// fragment shaders where the context's queue family draws.
VkPipelineStageFlags reader_stages(Context::Impl& c) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(c.physical, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(c.physical, &count, families.data());
  VkPipelineStageFlags stages =
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  if (c.queue_family < count && (families[c.queue_family].queueFlags & VK_QUEUE_GRAPHICS_BIT))
    stages |= VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
  return stages;
}

void submitted(Recorder& rec, VectorGpuStats& stats, std::vector<PassTiming>* timings) {
  rec.submit();
  ++stats.submits;
  ++stats.fence_waits;
  if (timings) *timings = rec.timings();
}

}  // namespace

bool supports_vector_passes(Context& context, std::string* why) {
  const Context::Impl& c = context.impl();
  if (c.float64) return true;
  if (why)
    *why = "the vector-field passes need the device feature shaderFloat64, which " + c.info.name +
           " does not have (or which was not enabled on it)";
  return false;
}

VectorTexture generate_vectors(Context& context, const VectorVolume& volume,
                               std::span<const VectorSource> sources, VectorStorage storage,
                               const VectorOptions& options, std::vector<std::int32_t>* winners,
                               VectorGpuStats* stats, std::vector<PassTiming>* timings) {
  const auto start = std::chrono::steady_clock::now();
  Context::Impl& c = context.impl();
  c.require_device();
  VectorGpuStats local;
  VectorGpuStats& st = stats ? *stats : local;
  VectorEngine engine(c, volume, storage);
  Buffer texels = engine.make_texture();
  {
    Recorder rec(c, &engine.sets());
    VectorEngine::Targets t;
    t.current = &texels;
    t.want_winners = winners != nullptr;
    engine.record(rec, sources, options, t, st);
    submitted(rec, st, timings);
  }
  VectorTexture out = download_texture(engine, c, texels, &st);
  if (winners) {
    winners->assign(static_cast<std::size_t>(volume.voxel_count()), -1);
    download(c, engine.sets(), engine.winners(), winners->size() * 4,
             reinterpret_cast<std::uint8_t*>(winners->data()), &st);
  }
  st.ms = ms_since(start);
  return out;
}

Image render_vectors(Context& context, const VectorVolume& volume, const VectorTexture& texture,
                     const VectorViewOptions& view, VectorGpuStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  Context::Impl& c = context.impl();
  c.require_device();
  volume.validate();
  if (!(texture.resolution() == volume.resolution))
    throw InvalidArgument("render_vectors: the texture's resolution differs from the volume's");
  VectorGpuStats local;
  VectorGpuStats& st = stats ? *stats : local;
  VectorEngine engine(c, volume, texture.storage());
  Buffer texels = engine.make_texture();
  Buffer& staging = c.upload_buffer(texture.bytes().size());
  std::memcpy(staging.mapped(), texture.bytes().data(), texture.bytes().size());
  Buffer* pixels = nullptr;
  {
    Recorder rec(c, &engine.sets());
    rec.copy(staging, 0, texels, 0, texture.bytes().size());
    pixels = &engine.record_view(rec, texels, view);
    ++st.dispatches;
    submitted(rec, st, nullptr);
  }
  st.bytes_uploaded += static_cast<std::int64_t>(texture.bytes().size());
  Image image = download_image(engine, c, *pixels, view, &st);
  st.ms = ms_since(start);
  return image;
}

struct VectorSimulation::Impl {
  std::shared_ptr<Context> context;
  VectorEngine engine;
  VectorOptions options;
  double decay_per_s;
  Buffer current, field, next;
  std::int64_t steps = 0;
  VectorGpuStats stats;
  std::vector<PassTiming> timings;
  VkPipelineStageFlags readers;  // where an application may read a recorded field

  // The arguments are checked by VectorSimulation's constructor.
  Impl(std::shared_ptr<Context> ctx, const VectorVolume& volume, VectorStorage storage,
       VectorOptions o, double decay)
      : context(std::move(ctx)),
        engine(context->impl(), volume, storage),
        options(o),
        decay_per_s(decay),
        readers(reader_stages(context->impl())) {
    options.interrupter = nullptr;
    current = engine.make_texture();
    field = engine.make_texture();
    next = engine.make_texture();
    // Every texture starts as the zero texel (rgba8: 128, 128, 128, 0).
    Context::Impl& c = context->impl();
    Recorder rec(c, &engine.sets());
    const std::uint32_t zero = storage == VectorStorage::kRgba8 ? 0x00808080u : 0u;
    for (Buffer* b : {&current, &field, &next}) rec.fill(*b, 0, VK_WHOLE_SIZE, zero);
    rec.submit();
  }

  // One step's uploads and passes into `rec` (own or the application's command buffer); the
  // textures swap once the caller has recorded what it adds. Throws InvalidArgument for a bad
  // time step or source before recording anything.
  void record_step(Recorder& rec, std::span<const VectorSource> sources, double dt_s,
                   VectorGpuStats& st) {
    if (!std::isfinite(dt_s) || dt_s <= 0)
      throw InvalidArgument("vector simulation: the time step must be finite and > 0");
    context->impl().require_device();  // the sources are checked by engine.record
    VectorEngine::Targets t;
    t.current = &current;
    t.previous = &field;
    t.next = &next;
    t.decay = static_cast<float>(decay_per_s * dt_s);  // as the CPU's step rounds it
    engine.record(rec, sources, options, t, st);
  }
  void finish_step(const VectorGpuStats& st) {
    std::swap(field, next);
    ++steps;
    stats = st;
  }
};

VectorSimulation::VectorSimulation(std::shared_ptr<Context> context, const VectorVolume& volume,
                                   VectorStorage storage, VectorOptions options,
                                   double decay_per_s) {
  if (!context) throw InvalidArgument("gpu::VectorSimulation: no context");
  // Arguments first (InvalidArgument, as the CPU's constructor), then the device.
  volume.validate();
  if (!std::isfinite(decay_per_s) || decay_per_s < 0)
    throw InvalidArgument("vector simulation: the decay per second must be finite and >= 0");
  context->impl().require_device();
  impl_ = std::make_unique<Impl>(std::move(context), volume, storage, options, decay_per_s);
}

VectorSimulation::~VectorSimulation() = default;

void VectorSimulation::step(std::span<const VectorSource> sources, double dt_s) {
  const auto start = std::chrono::steady_clock::now();
  Impl& s = *impl_;
  VectorGpuStats st;
  {
    Recorder rec(s.context->impl(), &s.engine.sets());
    s.record_step(rec, sources, dt_s, st);
    submitted(rec, st, &s.timings);
  }
  st.ms = ms_since(start);
  s.finish_step(st);
}

VectorTexture VectorSimulation::field() {
  return download_texture(impl_->engine, impl_->context->impl(), impl_->field, nullptr);
}
VectorTexture VectorSimulation::current() {
  return download_texture(impl_->engine, impl_->context->impl(), impl_->current, nullptr);
}

Image VectorSimulation::render(const VectorViewOptions& view) {
  Impl& s = *impl_;
  Context::Impl& c = s.context->impl();
  Buffer* pixels = nullptr;
  s.engine.settle();  // an own submission: every earlier command has finished
  {
    Recorder rec(c, &s.engine.sets());
    pixels = &s.engine.record_view(rec, s.field, view);
    rec.submit();
  }
  return download_image(s.engine, c, *pixels, view, nullptr);
}

VectorFieldBuffer record_step(VectorSimulation& sim, VkCommandBuffer cmd,
                              std::span<const VectorSource> sources, double dt_s) {
  VectorSimulation::Impl& s = sim.impl();
  VectorGpuStats st;
  {
    Recorder rec(s.context->impl(), cmd, s.engine.sets());
    s.record_step(rec, sources, dt_s, st);
    // The application's shaders and copies read the new field after this (its vertex and
    // fragment shaders too where the queue draws).
    rec.expose(s.next, s.readers, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  }
  s.finish_step(st);
  return field_buffer(sim);
}

VectorFieldBuffer field_buffer(VectorSimulation& sim) {
  return {sim.impl().field.handle(), 0, sim.impl().engine.texture_bytes()};
}

VkBuffer record_render(VectorSimulation& sim, VkCommandBuffer cmd, const VectorViewOptions& view,
                       PixelOrder order) {
  VectorSimulation::Impl& s = sim.impl();
  Context::Impl& c = s.context->impl();
  c.require_device();
  Recorder rec(c, cmd, s.engine.sets());
  Buffer& pixels = s.engine.record_view(rec, s.field, view, order == PixelOrder::kBgra);
  rec.expose(pixels, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  return pixels.handle();
}

const VectorVolume& VectorSimulation::volume() const {
  return impl_->engine.volume();
}
VectorStorage VectorSimulation::storage() const {
  return impl_->engine.storage();
}
std::int64_t VectorSimulation::steps() const {
  return impl_->steps;
}
const VectorGpuStats& VectorSimulation::last_stats() const {
  return impl_->stats;
}
const std::vector<PassTiming>& VectorSimulation::last_timings() const {
  return impl_->timings;
}
Context& VectorSimulation::context() {
  return *impl_->context;
}

}  // namespace voxfield::gpu

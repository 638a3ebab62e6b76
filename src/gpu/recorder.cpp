// voxfield GPU compute layer — the recorder and its derived barriers (see recorder.h).
#include "gpu/recorder.h"

#include <algorithm>

#include "gpu/split_buffer.h"

#include "voxfield/error.h"

namespace voxfield::gpu {
namespace {

constexpr VkAccessFlags kWriteAccess =
    VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT;
// Sets per descriptor pool, and storage-buffer descriptors per set on average.
constexpr std::uint32_t kSetsPerPool = 64;
constexpr std::uint32_t kBuffersPerSet = 32;  // the largest plans bind 25 (split_buffer.h windows)

VkAccessFlags shader_access(Access a) {
  VkAccessFlags flags = 0;
  if (a == Access::kWrite || a == Access::kReadWrite) flags |= VK_ACCESS_SHADER_WRITE_BIT;
  if (a == Access::kRead || a == Access::kReadWrite) flags |= VK_ACCESS_SHADER_READ_BIT;
  return flags;
}

}  // namespace

// ---- descriptor sets --------------------------------------------------------------------------

DescriptorArena::~DescriptorArena() {
  for (VkDescriptorPool p : pools_) vkDestroyDescriptorPool(ctx_->device, p, nullptr);
}

void DescriptorArena::reset() {
  for (VkDescriptorPool p : pools_) vkResetDescriptorPool(ctx_->device, p, 0);
  // Keep the first pool (recycled), free the rest: a burst does not pin its pools forever.
  while (pools_.size() > 1) {
    vkDestroyDescriptorPool(ctx_->device, pools_.back(), nullptr);
    pools_.pop_back();
  }
  left_in_pool_ = pools_.empty() ? 0 : kSetsPerPool;
  pool_descriptors_.resize(pools_.size());
  left_descriptors_ = pools_.empty() ? 0 : pool_descriptors_[0];
  cached_.clear();
}

VkDeviceSize Binding::covered() const {
  if (offset >= buffer->size()) return 0;
  return bytes == VK_WHOLE_SIZE ? buffer->size() - offset
                                : std::min(bytes, buffer->size() - offset);
}

void check_split_binding(const Context::Impl& ctx, VkDeviceSize bytes, const std::string& what) {
  if (bytes > split_capacity_bytes(ctx))
    throw InvalidArgument(what + " needs " + std::to_string(bytes) +
                          " bytes, more than this device binds (" + std::to_string(kSplitParts) +
                          " storage buffers of " + std::to_string(split_part_bytes(ctx)) +
                          " bytes)");
}

void check_whole_binding(const Context::Impl& ctx, VkDeviceSize bytes, const std::string& what) {
  if (bytes > ctx.limits.maxStorageBufferRange)
    throw InvalidArgument(what + " needs " + std::to_string(bytes) +
                          " bytes, more than this device binds (one storage buffer of " +
                          std::to_string(ctx.limits.maxStorageBufferRange) + " bytes)");
}

std::array<Binding, kSplitParts> split_bindings(Buffer& b, const Context::Impl& ctx) {
  const VkDeviceSize part = split_part_bytes(ctx);
  if (b.size() > part * kSplitParts)
    throw Error("GPU: internal error: a buffer of " + std::to_string(b.size()) +
                " bytes is bound in more than " + std::to_string(kSplitParts) + " parts");
  std::array<Binding, kSplitParts> parts{&b, &b, &b, &b};
  for (int k = 0; k < kSplitParts; ++k) {
    const VkDeviceSize at = part * static_cast<VkDeviceSize>(k);
    parts[k] = at < b.size() ? Binding(&b, at, std::min(part, b.size() - at)) : parts[0];
  }
  return parts;
}

VkDescriptorSet DescriptorArena::set(const Kernel& kernel, std::span<const Binding> buffers) {
  Key key{kernel.set_layout, {}};
  key.buffers.reserve(buffers.size());
  for (const Binding& b : buffers) key.buffers.push_back({b.buffer->handle(), b.offset, b.bytes});
  for (const auto& [k, s] : cached_)
    if (k == key) return s;

  VkDescriptorSet set = VK_NULL_HANDLE;
  for (int attempt = 0; attempt < 2 && set == VK_NULL_HANDLE; ++attempt) {
    // A fresh pool when the last one has no set or too few descriptors left for this one (sized
    // for the larger of a typical set and this one), or when it failed to give a set anyway.
    if (left_in_pool_ == 0 || buffers.size() > left_descriptors_ || attempt == 1) {
      const std::uint32_t descriptors =
          kSetsPerPool *
          std::max<std::uint32_t>(kBuffersPerSet, static_cast<std::uint32_t>(buffers.size()));
      const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, descriptors};
      VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
      dp.maxSets = kSetsPerPool;
      dp.poolSizeCount = 1;
      dp.pPoolSizes = &size;
      VkDescriptorPool pool;
      check(vkCreateDescriptorPool(ctx_->device, &dp, nullptr, &pool), "vkCreateDescriptorPool");
      pools_.push_back(pool);
      ++ctx_->counters.descriptor_pools;
      left_in_pool_ = kSetsPerPool;
      left_descriptors_ = descriptors;
      pool_descriptors_.push_back(descriptors);
    }
    VkDescriptorSetAllocateInfo dsa{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dsa.descriptorPool = pools_.back();
    dsa.descriptorSetCount = 1;
    dsa.pSetLayouts = &kernel.set_layout;
    const VkResult r = vkAllocateDescriptorSets(ctx_->device, &dsa, &set);
    if (r == VK_ERROR_OUT_OF_POOL_MEMORY || r == VK_ERROR_FRAGMENTED_POOL) {
      set = VK_NULL_HANDLE;  // this pool's descriptors ran out before its sets: a fresh pool
      left_in_pool_ = 0;
      continue;
    }
    check(r, "vkAllocateDescriptorSets");
    --left_in_pool_;
    left_descriptors_ -= static_cast<std::uint32_t>(buffers.size());
  }
  if (set == VK_NULL_HANDLE) check(VK_ERROR_OUT_OF_POOL_MEMORY, "vkAllocateDescriptorSets");

  std::vector<VkDescriptorBufferInfo> infos(buffers.size());
  std::vector<VkWriteDescriptorSet> writes(buffers.size());
  for (std::size_t b = 0; b < buffers.size(); ++b) {
    infos[b] = {buffers[b].buffer->handle(), buffers[b].offset, buffers[b].bytes};
    writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = set;
    writes[b].dstBinding = static_cast<std::uint32_t>(b);
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  vkUpdateDescriptorSets(ctx_->device, static_cast<std::uint32_t>(writes.size()), writes.data(), 0,
                         nullptr);
  cached_.emplace_back(std::move(key), set);
  return set;
}

// ---- recording --------------------------------------------------------------------------------

Recorder::Recorder(Context::Impl& ctx, DescriptorArena* sets) : ctx_(ctx), owns_cmd_(true) {
  ctx.require_device();
  VkCommandBufferAllocateInfo cba{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cba.commandPool = ctx.command_pool;
  cba.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cba.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(ctx.device, &cba, &cmd_), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  const VkResult r = vkBeginCommandBuffer(cmd_, &begin);
  if (r != VK_SUCCESS) {
    vkFreeCommandBuffers(ctx.device, ctx.command_pool, 1, &cmd_);
    check(r, "vkBeginCommandBuffer");
  }
  if (!sets) {
    if (!ctx.transient_sets) ctx.transient_sets = std::make_unique<DescriptorArena>(ctx);
    ++ctx.transient_set_users;
    transient_sets_ = true;
  }
  sets_ = sets ? sets : ctx.transient_sets.get();
}

Recorder::Recorder(Context::Impl& ctx, VkCommandBuffer external, DescriptorArena& sets)
    : ctx_(ctx), cmd_(external), sets_(&sets) {
  ctx.require_device();
  // The application submits this command buffer when it likes: voxfield's own submissions made
  // in between (a SceneRenderer::sync(), say) were not known when these barriers were derived.
  // One barrier first orders everything submitted before this command buffer on the queue.
  VkMemoryBarrier all{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  all.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  all.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                       0, 1, &all, 0, nullptr, 0, nullptr);
  ++ctx_.counters.pipeline_barriers;
}

Recorder::~Recorder() {
  if (owns_cmd_) vkFreeCommandBuffers(ctx_.device, ctx_.command_pool, 1, &cmd_);
  if (owns_cmd_ && !submitted_) {
    // Abandoned (an exception between recording and submitting): the states recorded for these
    // buffers describe commands that never ran. Assume anything may have touched them, so the
    // next use of each waits for everything before it.
    for (Buffer* b : used_)
      b->sync = Buffer::Sync{VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, 0, 0,
                             VK_PIPELINE_STAGE_ALL_COMMANDS_BIT};
  }
  // This recorder's commands ran (submit() waits) or never will: when no other recorder still
  // holds sets from the shared arena, its sets are recycled.
  if (transient_sets_ && --ctx_.transient_set_users == 0) ctx_.transient_sets->reset();
}

void Recorder::touch(Buffer& b) {
  if (b.mapped() && std::find(touched_.begin(), touched_.end(), &b) == touched_.end())
    touched_.push_back(&b);
}

void Recorder::prepare(std::span<const Use> uses_in) {
  if (submitted_) throw InvalidArgument("GPU recorder: recording after submit()");
  // One use per buffer: a buffer bound twice (or copied onto itself) is used by the union.
  std::vector<Use> uses;
  for (const Use& u : uses_in) {
    auto it =
        std::find_if(uses.begin(), uses.end(), [&](const Use& v) { return v.buffer == u.buffer; });
    if (it == uses.end()) {
      uses.push_back(u);
    } else {
      it->stage |= u.stage;
      it->access |= u.access;
    }
  }
  std::vector<VkBufferMemoryBarrier> barriers;
  VkPipelineStageFlags src = 0, dst = 0;
  for (const Use& u : uses) {
    if (std::find(used_.begin(), used_.end(), u.buffer) == used_.end()) used_.push_back(u.buffer);
    Buffer::Sync& s = u.buffer->sync;
    const bool writes = (u.access & kWriteAccess) != 0;
    VkPipelineStageFlags wait = 0;
    VkAccessFlags made_available = 0;
    if (s.write_stages != 0 &&
        (writes || (u.stage & ~s.visible_stages) != 0 || (u.access & ~s.visible_access) != 0)) {
      wait = s.write_stages | (writes ? s.read_stages : 0);  // after a write (and its readers)
      made_available = s.write_access;
    } else if (writes && s.read_stages != 0) {
      wait = s.read_stages;  // write after read: an execution dependency
    }
    if (wait != 0) {
      VkBufferMemoryBarrier b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
      b.srcAccessMask = made_available;
      b.dstAccessMask = made_available ? u.access : 0;
      b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      b.buffer = u.buffer->handle();
      b.offset = 0;
      b.size = VK_WHOLE_SIZE;
      barriers.push_back(b);
      src |= wait;
      dst |= u.stage;
    }
    if (writes) {
      s.write_stages = u.stage;
      s.write_access = u.access & kWriteAccess;
      s.visible_stages = 0;
      s.visible_access = 0;
      s.read_stages = 0;
      touch(*u.buffer);
    } else {
      if (s.write_stages != 0) {
        s.visible_stages |= u.stage;
        s.visible_access |= u.access;
      }
      s.read_stages |= u.stage;
    }
  }
  if (!barriers.empty()) {
    vkCmdPipelineBarrier(cmd_, src, dst, 0, 0, nullptr, static_cast<std::uint32_t>(barriers.size()),
                         barriers.data(), 0, nullptr);
    ++ctx_.counters.pipeline_barriers;
  }
  start_pending_pass();
}

void Recorder::start_pending_pass() {
  // A pass's start is stamped after the barrier of its first command, so that waiting for the
  // previous pass is not counted in this one.
  if (pending_start_ < 0) return;
  vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, ctx_.timestamps,
                      static_cast<std::uint32_t>(pending_start_));
  pending_start_ = -1;
}

void Recorder::bind(const Kernel& kernel, Buffers buffers, const void* push, std::size_t push_bytes,
                    const Use* also, VkPipelineBindPoint point) {
  const bool compute = point == VK_PIPELINE_BIND_POINT_COMPUTE;
  // A graphics kernel's buffers are read by its vertex and fragment stages (graphics.h).
  const VkPipelineStageFlags stage =
      compute ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT
              : VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
  const VkShaderStageFlags push_stages =
      compute ? VK_SHADER_STAGE_COMPUTE_BIT
              : VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  // Buffers past the last binding the shader uses are ignored, so passes that share one binding
  // plan (the exact transform's) can be given the same list.
  if (buffers.size() < kernel.interface.buffers.size())
    throw InvalidArgument("GPU kernel " + kernel.name + ": " + std::to_string(buffers.size()) +
                          " buffers given, the shader uses binding " +
                          std::to_string(kernel.interface.buffers.size() - 1));
  if (push_bytes != kernel.interface.push_bytes)
    throw InvalidArgument("GPU kernel " + kernel.name + ": " + std::to_string(push_bytes) +
                          " bytes of push constants given, the shader declares " +
                          std::to_string(kernel.interface.push_bytes));
  const std::size_t used = kernel.interface.buffers.size();
  std::vector<Use> uses;
  for (std::size_t b = 0; b < used; ++b) {
    // Past the range the binding is invalid (even one the shader never touches: it is written to
    // the set), and a device may read or write only part of it (lavapipe tolerates it, other
    // drivers need not): the module must bind such a buffer in parts.
    const VkDeviceSize covered = buffers[b].covered();
    if (covered > ctx_.limits.maxStorageBufferRange)
      throw Error("GPU: internal error: kernel " + kernel.name + " would bind " +
                  std::to_string(covered) + " bytes at binding " + std::to_string(b) +
                  ", past the device's storage-buffer range (" +
                  std::to_string(ctx_.limits.maxStorageBufferRange) + ")");
    if (kernel.interface.buffers[b] != Access::kNone)
      uses.push_back({buffers[b].buffer, stage, shader_access(kernel.interface.buffers[b])});
  }
  if (also) uses.push_back(*also);  // one barrier for the command's every use
  prepare(uses);
  const VkDescriptorSet set = sets_->set(kernel, buffers.first(used));
  vkCmdBindPipeline(cmd_, point, kernel.pipeline);
  vkCmdBindDescriptorSets(cmd_, point, kernel.layout, 0, 1, &set, 0, nullptr);
  if (push_bytes > 0)
    vkCmdPushConstants(cmd_, kernel.layout, push_stages, 0, static_cast<std::uint32_t>(push_bytes),
                       push);
}

void Recorder::dispatch(const Kernel& kernel, Buffers buffers, const void* push,
                        std::size_t push_bytes, std::uint64_t invocations) {
  const std::uint64_t per_group = kernel.interface.invocations_per_group();
  const std::uint64_t groups = (invocations + per_group - 1) / per_group;
  const std::uint64_t max_x = ctx_.limits.maxComputeWorkGroupCount[0];
  const std::uint64_t gx = std::max<std::uint64_t>(std::min(groups, max_x), 1);
  const std::uint64_t gy = (groups + gx - 1) / gx;
  if (gy > ctx_.limits.maxComputeWorkGroupCount[1])
    throw InvalidArgument("GPU kernel " + kernel.name + ": " + std::to_string(invocations) +
                          " invocations exceed the device's dispatch limits");
  if (groups == 0) return;
  dispatch_groups(kernel, buffers, push, push_bytes,
                  {static_cast<std::uint32_t>(gx), static_cast<std::uint32_t>(gy), 1});
}

void Recorder::dispatch_strided(const Kernel& kernel, Buffers buffers, const void* push,
                                std::size_t push_bytes, std::uint64_t invocations) {
  const std::uint64_t per_group = kernel.interface.invocations_per_group();
  const std::uint64_t groups = std::min<std::uint64_t>((invocations + per_group - 1) / per_group,
                                                       ctx_.limits.maxComputeWorkGroupCount[0]);
  if (groups == 0) return;
  dispatch_groups(kernel, buffers, push, push_bytes, {static_cast<std::uint32_t>(groups), 1, 1});
}

void Recorder::dispatch_groups(const Kernel& kernel, Buffers buffers, const void* push,
                               std::size_t push_bytes, std::array<std::uint32_t, 3> groups) {
  bind(kernel, buffers, push, push_bytes, nullptr);
  vkCmdDispatch(cmd_, groups[0], groups[1], groups[2]);
  ++ctx_.counters.dispatches;
}

void Recorder::dispatch_indirect(const Kernel& kernel, Buffers buffers, const void* push,
                                 std::size_t push_bytes, Buffer& args, VkDeviceSize offset) {
  const Use use{&args, VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, VK_ACCESS_INDIRECT_COMMAND_READ_BIT};
  bind(kernel, buffers, push, push_bytes, &use);
  vkCmdDispatchIndirect(cmd_, args.handle(), offset);
  ++ctx_.counters.dispatches;
}

void Recorder::copy(Buffer& src, Buffer& dst, std::span<const VkBufferCopy> regions) {
  copy({Copy{&src, &dst, regions}});
}

void Recorder::copy(std::initializer_list<Copy> copies) {
  std::vector<Use> uses;
  for (const Copy& c : copies)
    if (!c.regions.empty()) {
      uses.push_back({c.src, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT});
      uses.push_back({c.dst, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT});
    }
  if (uses.empty()) return;
  prepare(uses);
  for (const Copy& c : copies) {
    if (c.regions.empty()) continue;
    vkCmdCopyBuffer(cmd_, c.src->handle(), c.dst->handle(),
                    static_cast<std::uint32_t>(c.regions.size()), c.regions.data());
    std::int64_t bytes = 0;
    for (const VkBufferCopy& r : c.regions) bytes += static_cast<std::int64_t>(r.size);
    if (c.src->mapped() && !c.dst->mapped()) ctx_.counters.bytes_uploaded += bytes;
    if (c.dst->mapped() && !c.src->mapped()) ctx_.counters.bytes_downloaded += bytes;
  }
}

void Recorder::copy(Buffer& src, VkDeviceSize src_offset, Buffer& dst, VkDeviceSize dst_offset,
                    VkDeviceSize bytes) {
  if (bytes == 0) return;
  const VkBufferCopy region{src_offset, dst_offset, bytes};
  copy(src, dst, {&region, 1});
}

void Recorder::update(Buffer& dst, VkDeviceSize offset, const void* data, VkDeviceSize bytes) {
  const Use use{&dst, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT};
  prepare({&use, 1});
  vkCmdUpdateBuffer(cmd_, dst.handle(), offset, bytes, data);
  ctx_.counters.bytes_uploaded += static_cast<std::int64_t>(bytes);
}

void Recorder::fill(Buffer& dst, VkDeviceSize offset, VkDeviceSize bytes, std::uint32_t value) {
  const Use use{&dst, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT};
  prepare({&use, 1});
  vkCmdFillBuffer(cmd_, dst.handle(), offset, bytes, value);
}

void Recorder::expose(Buffer& b, VkPipelineStageFlags stage, VkAccessFlags access) {
  const Use use{&b, stage, access};
  prepare({&use, 1});
}

int Recorder::begin_pass() {
  if (!owns_cmd_ || ctx_.timestamps == VK_NULL_HANDLE ||
      queries_used_ + 2 > Context::Impl::kQueries)
    return -1;
  if (queries_used_ == 0) vkCmdResetQueryPool(cmd_, ctx_.timestamps, 0, Context::Impl::kQueries);
  start_pending_pass();  // a pass begun and never given a command starts here
  const int ticket = queries_used_;
  queries_used_ += 2;
  pending_start_ = ticket;  // stamped after the next command's barrier
  return ticket;
}

void Recorder::end_pass(int ticket, std::string label) {
  if (ticket < 0) return;
  if (pending_start_ == ticket) start_pending_pass();  // an empty pass
  vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, ctx_.timestamps,
                      static_cast<std::uint32_t>(ticket + 1));
  passes_.emplace_back(ticket, std::move(label));
}

void Recorder::submit() {
  if (!owns_cmd_)
    throw InvalidArgument(
        "GPU recorder: an application's command buffer is submitted by the application");
  if (submitted_) throw InvalidArgument("GPU recorder: submitted twice");
  if (pending_start_ >= 0 || passes_.size() * 2 != static_cast<std::size_t>(queries_used_))
    throw InvalidArgument("GPU recorder: a timed pass was begun and not ended");
  // The host reads what the GPU wrote into host-visible buffers once the fence has signalled.
  std::vector<Use> host;
  for (Buffer* b : touched_)
    if (b->sync.write_stages != 0 && !(b->sync.visible_stages & VK_PIPELINE_STAGE_HOST_BIT))
      host.push_back({b, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT});
  if (!host.empty()) prepare(host);
  check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
  ctx_.submit_and_wait(cmd_);
  submitted_ = true;  // ran: the buffers' states now describe what happened
  if (passes_.empty()) return;
  std::vector<std::uint64_t> ticks(static_cast<std::size_t>(queries_used_));
  check(vkGetQueryPoolResults(ctx_.device, ctx_.timestamps, 0,
                              static_cast<std::uint32_t>(queries_used_), ticks.size() * 8,
                              ticks.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  for (const auto& [q, label] : passes_)
    timings_.push_back({label, static_cast<double>(ticks[static_cast<std::size_t>(q) + 1] -
                                                   ticks[static_cast<std::size_t>(q)]) *
                                   ctx_.timestamp_period_ns * 1e-6});
}

}  // namespace voxfield::gpu

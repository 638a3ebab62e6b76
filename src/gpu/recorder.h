// voxfield GPU compute layer — the recorder: records dispatches and copies, and derives every
// barrier from what each command does to each buffer, so no module places a barrier by hand.
//
// Each Buffer remembers its last write (stages and accesses), which stages have been made to see
// that write, and the reads since it. Before a command, the recorder compares the command's uses
// with that state and emits one vkCmdPipelineBarrier carrying a buffer memory barrier per buffer
// that needs one: read after write and write after write get a memory dependency, write after
// read an execution dependency, read after read nothing. Dispatches take their buffers' accesses
// from the shader's own `readonly` / `writeonly` qualifiers (kernel.h). The state outlives a
// submission, so work of a later submission is ordered after the writes of an earlier one by the
// same rules (a pipeline barrier's first scope covers everything submitted before it on the
// queue), and host-visible buffers the GPU wrote are made visible to the host at submit().
//
// A recorder either owns a command buffer (submit() submits it with the context's fence and waits:
// one submit, one fence wait) or records into an application's command buffer, which the
// application submits (gpu_vulkan.h). Descriptor sets come from a DescriptorArena: the context's
// shared one (recycled once no recorder using it is alive), or one the caller keeps alive as long
// as its commands may run.
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "gpu/kernel.h"
#include "gpu/vulkan_context.h"

namespace voxfield::gpu {

class GraphicsKernel;
class RenderTarget;

// One storage-buffer binding of a command: a buffer, whole, or a window of it. A window lets a
// buffer larger than the device's maxStorageBufferRange be bound in parts (split_buffer.h).
// Barriers are derived for the whole buffer either way.
struct Binding {
  Binding(Buffer* b) : buffer(b) {}  // NOLINT(google-explicit-constructor): a whole buffer
  Binding(Buffer* b, VkDeviceSize offset_bytes, VkDeviceSize size_bytes)
      : buffer(b), offset(offset_bytes), bytes(size_bytes) {}
  Buffer* buffer;
  VkDeviceSize offset = 0;
  VkDeviceSize bytes = VK_WHOLE_SIZE;
  // The bytes the binding covers.
  VkDeviceSize covered() const;
};

// Descriptor sets for recorded dispatches, one per distinct (kernel, buffers) pair, from pools
// grown on demand. reset() recycles them all: only once no recorded command can still run. Sets
// are found by the buffers' handles: a buffer destroyed while an arena still holds sets naming it
// must not be replaced by a new one before the arena is reset (a new buffer may reuse the handle).
// The context's shared arena is reset whenever no recorder is using it.
class DescriptorArena {
 public:
  explicit DescriptorArena(Context::Impl& ctx) : ctx_(&ctx) {}
  ~DescriptorArena();
  DescriptorArena(const DescriptorArena&) = delete;
  DescriptorArena& operator=(const DescriptorArena&) = delete;

  VkDescriptorSet set(const Kernel& kernel, std::span<const Binding> buffers);
  void reset();
  std::size_t sets() const { return cached_.size(); }

 private:
  struct Key {
    VkDescriptorSetLayout layout;
    struct Bound {
      VkBuffer handle;
      VkDeviceSize offset, bytes;
      bool operator==(const Bound&) const = default;
    };
    std::vector<Bound> buffers;
    bool operator==(const Key&) const = default;
  };
  Context::Impl* ctx_;
  std::vector<VkDescriptorPool> pools_;
  std::uint32_t left_in_pool_ = 0;
  std::uint32_t left_descriptors_ = 0;           // in the last pool
  std::vector<std::uint32_t> pool_descriptors_;  // each pool's, as made
  std::vector<std::pair<Key, VkDescriptorSet>> cached_;
};

class Recorder {
 public:
  // Records into a command buffer of its own; submit() runs it. Descriptor sets come from `sets`
  // when given (an object that keeps its sets across submissions), else from the recorder's own.
  explicit Recorder(Context::Impl& ctx, DescriptorArena* sets = nullptr);
  // Records into `external` (begun by the application, submitted by it), binding sets from `sets`.
  Recorder(Context::Impl& ctx, VkCommandBuffer external, DescriptorArena& sets);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // The buffers of a dispatch, binding 0 first. Every binding must cover at most the device's
  // maxStorageBufferRange (an internal error otherwise: the module binds larger buffers in parts).
  using Buffers = std::span<const Binding>;

  // `invocations` invocations of `kernel` along x, in workgroups of its local size, split over y
  // when the count exceeds the device's limit. `push` must be exactly the shader's push-constant
  // block (checked against its reflected size).
  void dispatch(const Kernel& kernel, Buffers buffers, const void* push, std::size_t push_bytes,
                std::uint64_t invocations);
  void dispatch_groups(const Kernel& kernel, Buffers buffers, const void* push,
                       std::size_t push_bytes, std::array<std::uint32_t, 3> groups);
  // `invocations` invocations of a kernel that strides: workgroups along x only, at most the
  // device's limit, the shader looping over i = gl_GlobalInvocationID.x, then i += stride, with
  // stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x. On lavapipe, dispatches split over y were
  // observed to lose their second row's work in the vector-field and marching-cubes shaders
  // (simple kernels ran right; the cause was not found): striding needs no second row.
  void dispatch_strided(const Kernel& kernel, Buffers buffers, const void* push,
                        std::size_t push_bytes, std::uint64_t invocations);
  template <class Push>
  void dispatch_strided(const Kernel& k, Buffers b, const Push& p, std::uint64_t invocations) {
    dispatch_strided(k, b, &p, sizeof p, invocations);
  }
  // Workgroup counts read from `args` at `offset` (three uint32) when the command runs.
  void dispatch_indirect(const Kernel& kernel, Buffers buffers, const void* push,
                         std::size_t push_bytes, Buffer& args, VkDeviceSize offset);
  template <class Push>
  void dispatch(const Kernel& k, Buffers b, const Push& p, std::uint64_t invocations) {
    dispatch(k, b, &p, sizeof p, invocations);
  }
  template <class Push>
  void dispatch(const Kernel& k, std::initializer_list<Binding> b, const Push& p,
                std::uint64_t invocations) {
    dispatch(k, Buffers(b.begin(), b.size()), &p, sizeof p, invocations);
  }
  void dispatch_groups(const Kernel& k, std::initializer_list<Binding> b, const void* push,
                       std::size_t push_bytes, std::array<std::uint32_t, 3> groups) {
    dispatch_groups(k, Buffers(b.begin(), b.size()), push, push_bytes, groups);
  }
  void dispatch_indirect(const Kernel& k, std::initializer_list<Binding> b, const void* push,
                         std::size_t push_bytes, Buffer& args, VkDeviceSize offset) {
    dispatch_indirect(k, Buffers(b.begin(), b.size()), push, push_bytes, args, offset);
  }

  // A draw of `graphics` into `target` (graphics.h): the target cleared to `clear` (and the depth
  // to 0, reversed depth's far), then one vkCmdDrawIndirect whose VkDrawIndirectCommand is read
  // from `args` at `offset` when the command runs; the shaders pull what they draw from
  // `buffers`, whose barriers are derived for the vertex and fragment stages.
  void draw_indirect(const GraphicsKernel& graphics, RenderTarget& target, Buffers buffers,
                     const void* push, std::size_t push_bytes, Buffer& args, VkDeviceSize offset,
                     const std::array<float, 4>& clear);
  // The target's last drawn colour into `dst`: 4 bytes per pixel in the target's format, rows
  // top first, tightly packed.
  void copy_colour(RenderTarget& target, Buffer& dst);

  void copy(Buffer& src, Buffer& dst, std::span<const VkBufferCopy> regions);
  // Copies recorded as one step, behind one barrier: the uploads of an update, the read-backs of
  // a result. The caller guarantees they are independent: no two write overlapping bytes, and no
  // buffer one of them writes is read by another.
  struct Copy {
    Buffer* src;
    Buffer* dst;
    std::span<const VkBufferCopy> regions;
  };
  void copy(std::initializer_list<Copy> copies);
  void copy(Buffer& src, VkDeviceSize src_offset, Buffer& dst, VkDeviceSize dst_offset,
            VkDeviceSize bytes);
  // Writes `bytes` (at most 65536, a multiple of 4) into `dst` from the command buffer itself.
  void update(Buffer& dst, VkDeviceSize offset, const void* data, VkDeviceSize bytes);
  void fill(Buffer& dst, VkDeviceSize offset, VkDeviceSize bytes, std::uint32_t value);

  // Hands `b` to commands outside the recorder (an application's copy out of a frame): its last
  // write is made visible to `stage` / `access`, and later writes wait for that use.
  void expose(Buffer& b, VkPipelineStageFlags stage, VkAccessFlags access);

  // A timed pass: timestamps around the commands recorded between begin_pass() and end_pass(),
  // read after submit() into timings(). Without timestamps (no support, an external command
  // buffer, or the query pool used up) both calls do nothing.
  int begin_pass();
  void end_pass(int ticket, std::string label);
  const std::vector<PassTiming>& timings() const { return timings_; }

  // Submits the recorded commands and waits for them (own command buffer only). Afterwards the
  // host may read every host-visible buffer the commands wrote.
  void submit();

  VkCommandBuffer command_buffer() const { return cmd_; }

 private:
  struct Use {
    Buffer* buffer;
    VkPipelineStageFlags stage;
    VkAccessFlags access;
  };
  void prepare(std::span<const Use> uses);
  void bind(const Kernel& kernel, Buffers buffers, const void* push, std::size_t push_bytes,
            const Use* also, VkPipelineBindPoint point = VK_PIPELINE_BIND_POINT_COMPUTE);
  void touch(Buffer& b);
  void start_pending_pass();

  Context::Impl& ctx_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  bool owns_cmd_ = false;
  bool submitted_ = false;
  DescriptorArena* sets_;
  bool transient_sets_ = false;   // sets_ is the context's shared arena (vulkan_context.h)
  std::vector<Buffer*> touched_;  // host-visible buffers written, made visible at submit()
  std::vector<Buffer*> used_;     // every buffer whose state this recording changed
  int pending_start_ = -1;        // a begun pass whose start is stamped after the next barrier
  std::vector<std::pair<int, std::string>> passes_;
  int queries_used_ = 0;
  std::vector<PassTiming> timings_;
};

}  // namespace voxfield::gpu

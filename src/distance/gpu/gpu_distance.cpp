// voxfield GPU backend — exact distance fields on Vulkan compute, built once and kept exact under
// edits.
//
// The same separable algorithm as the CPU (Meijster, Roerdink & Hesselink 2000), as three kinds of
// dispatch: edt_sites (distances along x to the nearest site), edt_lines (the lower envelope along
// y, then z) and edt_encode (stored values, encoded exactly like the CPU's). Each pass reads what
// the previous one wrote across its whole box, so passes are separate dispatches with a pipeline
// barrier between them — barrier() in GLSL only orders one workgroup, which is how the
// dissertation's single-shader version raced.
//
// A FieldEngine keeps the world (brick pool + page table) and the field resident. A full build
// and an incremental update are the same operation: upload the chunks that changed, then for each
// region recompute its compute box and encode its out box into the field — all in one command
// buffer, one submit, one fence wait, no read-back unless asked for.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "../exact/whole_field.h"
#include "../incremental/update_regions.h"
#include "column_slabs.h"
#include "distance_shaders.h"
#include "field_encoding.h"
#include "gpu/recorder.h"
#include "gpu/split_buffer.h"
#include "resident_world.h"
#include "shaders/layout.h"
#include "voxfield/gpu_distance.h"
#include "work_buffers.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;
using namespace detail_encoding;

constexpr int kMaxExtent = 16384;  // keeps every cost of the passes within 31 bits
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

}  // namespace

class FieldEngine {
 public:
  // Keeps its own resident world, or rides on `shared` (another field's, over the same chunks),
  // which its runs then neither upload to nor grow. With `slab`, the field is that slab of the
  // domain options.domain (distance_slab.h): the resident field covers the slab alone, and
  // set_column_neighbours() says what lies beyond it.
  FieldEngine(Context::Impl& ctx, const World& world, const DistanceOptions& options,
              std::shared_ptr<ResidentWorld> shared = nullptr,
              std::shared_ptr<WorkBuffers> work = nullptr, const Box3i* slab = nullptr)
      : ctx_(ctx),
        kernels_{ctx.kernel(shaders::edt_sites()), ctx.kernel(shaders::edt_lines()),
                 ctx.kernel(shaders::edt_encode()), ctx.kernel(shaders::edt_columns())},
        world_(world),
        options_(options),
        plan_(detail::make_field_plan(world.voxels, options, slab)),
        tables_(ctx) {
    if (!plan_.unit_spacing)
      throw InvalidArgument("GPU: the Vulkan backend supports unit voxel spacing only");
    if (plan_.domain.empty()) throw InvalidArgument("GPU: the field's domain is empty");
    // A slab's costs and site offsets span the whole domain.
    const Box3i whole = slab ? *options.domain : plan_.domain;
    const Vec3i extent = whole.size();
    if (options.nearest_sites && (extent.x > 32767 || extent.y > 32767 || extent.z > 32767))
      throw InvalidArgument("GPU: nearest sites need a domain of at most 32767 voxels per axis");
    if (extent.x > kMaxExtent || extent.y > kMaxExtent || extent.z > kMaxExtent)
      throw InvalidArgument("GPU: domain " + to_string(whole) + " exceeds " +
                            std::to_string(kMaxExtent) + " voxels along an axis");
    const Vec3i n = plan_.domain.size();
    // Packed as stored on the CPU (1, 2 or 4 bytes per voxel), rows padded to whole words.
    field_bytes_ = static_cast<VkDeviceSize>(n.y) * n.z *
                   static_cast<VkDeviceSize>(row_pitch(plan_, options.storage)) *
                   (4 / lanes_of(options.storage));
    // The field and its sites are resident whole (slabs cut the work buffers, not these), bound
    // as split_buffer.h's windows.
    check_split_binding(ctx, field_bytes_, "GPU: the field of a " + to_string(n) + " domain");
    // Nearest sites: 8 bytes per voxel of the domain (three int16 offsets, padded).
    site_bytes_ = options.nearest_sites ? static_cast<VkDeviceSize>(plan_.domain.volume()) * 8 : 0;
    check_split_binding(ctx, site_bytes_,
                        "GPU: the nearest-site buffer of a " + to_string(n) + " domain");
    make_header();
    owns_world_ = shared == nullptr;
    resident_ =
        shared ? std::move(shared) : std::make_shared<ResidentWorld>(ctx, world, plan_.domain);
    if (&resident_->world() != &world || !resident_->covers(plan_.domain))
      throw InvalidArgument(
          "GPU: a field shares the resident world of a field of the same world over the same "
          "chunks only");
    resident_->describe(header_);
    work_ = work ? std::move(work) : std::make_shared<WorkBuffers>();
    header_buf_ = Buffer(ctx, sizeof header_, kStorage, false);
    field_buf_ = Buffer(ctx, field_bytes_, kStorage, false);
    field_sites_buf_ = Buffer(ctx, std::max<VkDeviceSize>(site_bytes_, 16), kStorage, false);
  }

  // The nearest solid and air voxels beyond the slab's z faces, per column (distance_slab.h; the
  // caller has checked them): uploaded by the next run, read by every z pass whose box reaches a
  // face. Offsets from the slab's first slice fit int16, as the whole domain's extent does.
  void set_column_neighbours(const SlabNeighbours& n) { tables_.set_uploaded(n, plan_.domain); }

  const detail::FieldPlan& plan() const { return plan_; }
  std::size_t field_bytes() const { return static_cast<std::size_t>(field_bytes_); }
  const DistanceOptions& options() const { return options_; }

  // Every chunk the domain touches.
  std::vector<Vec3i> all_chunks() const { return resident_->all_chunks(); }
  // `regions` cut into parts whose work buffers fit the device's storage-buffer range: the same
  // values (a clamped field's depend only on the sites within its reach), more dispatches. A
  // region no such cut fits (an unclamped field's, whose reach is the whole domain) stays whole,
  // and run() computes it in z-slabs with column neighbours instead (column_slabs.h).
  std::vector<detail::UpdateRegion> parts(const std::vector<detail::UpdateRegion>& regions) const {
    return detail::split_regions(
        regions, plan_.domain, detail::field_reach(plan_),
        WorkBuffers::most_region_voxels(ctx_.limits.maxStorageBufferRange, options_.nearest_sites));
  }
  const std::shared_ptr<ResidentWorld>& resident_world() const { return resident_; }
  const std::shared_ptr<WorkBuffers>& work_buffers() const { return work_; }
  bool owns_world() const { return owns_world_; }
  const World& world() const { return world_; }

  // Uploads `chunks` (those inside the page table), recomputes `regions`, optionally reads the
  // whole field back: one command buffer, one submit, one fence wait.
  // A run that throws leaves the device's copy of the world in doubt (the host counts page
  // entries and bricks as sent that may not have been, and a grown pool may have lost its old
  // bricks): the next run sends the header and the whole world again.
  void run(const std::vector<Vec3i>& chunks, const std::vector<detail::UpdateRegion>& regions,
           bool download, std::vector<PassTiming>* timings) {
    const bool resync = resync_;
    if (resync) {
      first_run_ = true;
      if (owns_world_) resident_->resync();
    }
    try {
      run_once(resync ? all_chunks() : chunks, regions, download, timings);
    } catch (...) {
      resync_ = true;
      throw;
    }
    resync_ = false;
  }

  void run_once(const std::vector<Vec3i>& chunks, const std::vector<detail::UpdateRegion>& regions,
                bool download, std::vector<PassTiming>* timings) {
    Staging up;
    Uploads uploads;
    stage(chunks, regions, up, uploads);
    // Every buffer the passes bind is bound whole, and stage() and the constructor keep each
    // within the range one binding may hold; past it the binding would be invalid.
    for (const Binding& b : bindings())
      if (b.covered() > ctx_.limits.maxStorageBufferRange)
        throw Error("GPU: internal error: a distance pass would bind " +
                    std::to_string(b.covered()) + " bytes, past the storage-buffer range (" +
                    std::to_string(ctx_.limits.maxStorageBufferRange) + ")");
    // What the copies carry (the staging's alignment padding stays behind).
    upload_bytes_ = first_run_ ? sizeof header_ : 0;
    for (const auto* copies : {&uploads.page_copies, &uploads.brick_copies})
      for (const VkBufferCopy& c : *copies) upload_bytes_ += static_cast<std::size_t>(c.size);
    upload_bytes_ += tables_.staged_bytes();
    Buffer& upload = ctx_.upload_buffer(std::max<VkDeviceSize>(up.bytes.size(), 16));
    if (!up.bytes.empty()) std::memcpy(upload.mapped(), up.bytes.data(), up.bytes.size());
    Buffer* readback = download ? &ctx_.readback_buffer(field_bytes_ + site_bytes_) : nullptr;
    Recorder rec(ctx_);
    record_transfers(rec, upload, uploads);
    for (const detail::UpdateRegion& r : regions) record_region(rec, r, timings != nullptr);
    if (readback) record_readback(rec, *readback);
    rec.submit();
    tables_.submitted();
    if (timings) *timings = rec.timings();
  }

  std::size_t upload_bytes() const { return upload_bytes_; }
  ResidentField resident() {
    return {&header_buf_, &resident_->pages(), &resident_->bricks(), &field_buf_,
            plan_.domain, plan_.encoding,      header_.none_pos};
  }

  // The field as last read back.
  DistanceField read_back() const {
    const auto* stored = static_cast<const std::uint8_t*>(ctx_.readback.mapped());
    DistanceField f;
    switch (options_.storage) {
      case Storage::kU8:
        f = build_field<std::uint8_t>(world_, options_, plan_, stored);
        break;
      case Storage::kU16:
        f = build_field<std::uint16_t>(world_, options_, plan_, stored);
        break;
      case Storage::kF32:
        f = build_field<float>(world_, options_, plan_, stored);
        break;
    }
    if (options_.nearest_sites) {
      // Three int16 offsets and a pad per voxel, x fastest over the domain: the CPU's SiteOffset.
      std::vector<SiteOffset> dense(static_cast<std::size_t>(plan_.domain.volume()));
      const auto* words = reinterpret_cast<const std::int16_t*>(stored + field_bytes_);
      for (std::size_t i = 0; i < dense.size(); ++i)
        dense[i] = {words[4 * i], words[4 * i + 1], words[4 * i + 2]};
      Grid<SiteOffset> sites(world_.voxels.chunk_edge(), SiteOffset{}, world_.voxels.bounds());
      sites.copy_from_dense(plan_.domain, dense.data());
      sites.compact();
      f.sites = std::move(sites);
    }
    return f;
  }

 private:
  using Uploads = ResidentWorld::Uploads;

  // Step 1, stage: the header (first run only), the changed page entries and bricks into `up`
  // (a field on another's resident world leaves them to that field's runs), and work buffers
  // large enough for the largest region.
  void stage(const std::vector<Vec3i>& chunks, const std::vector<detail::UpdateRegion>& regions,
             Staging& up, Uploads& uploads) {
    if (first_run_) {
      const VkDeviceSize at = up.add(&header_, sizeof header_);
      header_copy_ = VkBufferCopy{at, 0, sizeof header_};
    }
    // The work buffers first: a region too large for them, even in z-slabs, is refused before
    // anything changes.
    VkDeviceSize largest = 4;
    std::int64_t table_words = 0;
    for (const auto& r : regions) {
      const ColumnSlabs cut = column_slabs(r);
      largest = std::max<VkDeviceSize>(largest, static_cast<VkDeviceSize>(cut.work_voxels) * 4);
      table_words = std::max(table_words, cut.table_words);
    }
    tables_.stage(table_words, up);
    const VkDeviceSize widest = work_->widest_after(largest, options_.nearest_sites);
    if (widest > ctx_.limits.maxStorageBufferRange)
      throw InvalidArgument("GPU: a region of " + std::to_string(largest / 4) +
                            " voxels needs a work buffer of " + std::to_string(widest) +
                            " bytes, more than this device's storage-buffer range (" +
                            std::to_string(ctx_.limits.maxStorageBufferRange) +
                            ") (internal error: z-slabs should fit)");
    work_->grow(ctx_, largest, options_.nearest_sites);
    if (owns_world_) resident_->stage(chunks, up, uploads);
  }

  // Step 2, transfers, recorded before every pass: a grown pool's old bricks, the header, changed
  // page entries and bricks. (The recorder orders them after the previous submission's passes,
  // which read the buffers they overwrite.)
  void record_transfers(Recorder& rec, Buffer& upload, Uploads& uploads) {
    const std::span<const VkBufferCopy> header =
        first_run_ ? std::span<const VkBufferCopy>(&header_copy_, 1)
                   : std::span<const VkBufferCopy>();
    resident_->record(rec, upload, uploads, &header_buf_, header);
    tables_.record(rec, upload);
    first_run_ = false;
  }

  // How region `r` is computed: whole, or in z-slabs when its box of sites is too large for the
  // work buffers (column_slabs.h).
  ColumnSlabs column_slabs(const detail::UpdateRegion& r) const {
    const std::uint64_t range = ctx_.limits.maxStorageBufferRange;
    return plan_column_slabs(r.in, WorkBuffers::most_region_voxels(range, options_.nearest_sites),
                             range, options_.nearest_sites ? 24 : 4);
  }

  // Step 3, one region's passes: recompute its compute box, encode its out box into the field —
  // in z-slabs when it is too large for the work buffers: first the slabs' column neighbours
  // (edt_columns), then each slab that holds voxels of the out box, its z passes starting from
  // them.
  void record_region(Recorder& rec, const detail::UpdateRegion& r, bool timed) {
    const std::array<Binding, 21> bound = bindings();
    const auto pass = [&](const Kernel& kernel, const L::PassParams& t, std::uint64_t invocations,
                          std::string name) {
      const int ticket = timed ? rec.begin_pass() : -1;
      rec.dispatch(kernel, bound, t, invocations);
      rec.end_pass(ticket, std::move(name));
    };
    const Box3i& field = plan_.domain;
    const ColumnSlabs cut = column_slabs(r);
    if (cut.thickness == 0) {
      // A field that is a slab of a larger domain reads its uploaded table; others none.
      record_box(pass, r.in, r.out, {field.begin.x, field.begin.y, field.size().x, 0},
                 {field.begin.z, field.end.z, 0, 0}, tables_.has_uploaded());
      return;
    }
    L::PassParams cp{};
    cp.box_begin = {r.in.begin.x, r.in.begin.y, r.in.begin.z, 0};
    cp.box_size = {r.in.size().x, r.in.size().y, r.in.size().z, 0};
    cp.table = {r.in.begin.x, r.in.begin.y, r.in.size().x,
                static_cast<std::int32_t>(tables_.computed_base())};
    cp.faces = {0, 0, cut.thickness, cut.count};
    cp.column_neighbours = tables_.has_uploaded() ? 1u : 0u;
    const std::int64_t columns = static_cast<std::int64_t>(r.in.size().x) * r.in.size().y;
    pass(kernels_.columns, cp, static_cast<std::uint64_t>(columns), "slab neighbours");
    for (int k = 0; k < cut.count; ++k) {
      Box3i slab = r.in;
      slab.begin.z = r.in.begin.z + k * cut.thickness;
      slab.end.z = std::min(r.in.end.z, slab.begin.z + cut.thickness);
      const Box3i out = r.out.intersect(slab);
      if (out.empty()) continue;  // its sites are in the other slabs' neighbours already
      const auto base = static_cast<std::int32_t>(tables_.computed_base() + 2 * columns * k);
      record_box(pass, slab, out, {r.in.begin.x, r.in.begin.y, r.in.size().x, base},
                 {slab.begin.z, slab.end.z, 0, 0}, true);
    }
  }

  // The transform over box `in` and the encoding of `out` (inside it), the z passes reading the
  // neighbour table `table` of faces `faces` (PassParams) when `neighbours`.
  template <class Pass>
  void record_box(const Pass& pass, const Box3i& in, const Box3i& out, L::ivec4 table,
                  L::ivec4 faces, bool neighbours) {
    const Vec3i n = in.size();
    L::PassParams pp{};
    pp.box_begin = {in.begin.x, in.begin.y, in.begin.z, 0};
    pp.box_size = {n.x, n.y, n.z, 0};
    pp.out_begin = {out.begin.x, out.begin.y, out.begin.z, 0};
    pp.out_size = {out.size().x, out.size().y, out.size().z, 0};
    pp.table = table;
    pp.faces = faces;
    pp.column_neighbours = neighbours ? 1u : 0u;
    // One separable transform: sites along z into `result`, then x and y through `other` —
    // the CPU's order, so that nearest sites break ties the same way (docs/distance.md).
    auto transform = [&](std::uint32_t result, std::uint32_t other, bool to_air) {
      const std::string what = to_air ? " (to air)" : "";
      L::PassParams t = pp;
      t.sites_are_air = to_air ? 1u : 0u;
      t.axis = 2;
      t.dst = result;
      pass(kernels_.sites, t, static_cast<std::uint64_t>(n.x) * n.y, "columns z" + what);
      t.axis = 0;
      t.src = result;
      t.dst = other;
      pass(kernels_.lines, t, static_cast<std::uint64_t>(n.y) * n.z, "lines x" + what);
      t.axis = 1;
      t.src = other;
      t.dst = result;
      pass(kernels_.lines, t, static_cast<std::uint64_t>(n.x) * n.z, "lines y" + what);
    };
    transform(0, 1, false);
    if (plan_.is_signed) transform(2, 1, true);
    L::PassParams enc = pp;
    enc.src = 0;
    enc.src2 = 2;
    // One invocation per word of packed values that the out box touches.
    const std::int64_t lanes = static_cast<std::int64_t>(lanes_of(options_.storage));
    const std::int64_t ox = out.begin.x - plan_.domain.begin.x;
    const std::int64_t words = (ox + out.size().x - 1) / lanes - ox / lanes + 1;
    pass(kernels_.encode, enc, static_cast<std::uint64_t>(words * out.size().y * out.size().z),
         "encode");
  }

  // Step 4, read-back (when asked): the field and its sites into `readback`.
  void record_readback(Recorder& rec, Buffer& readback) {
    const VkBufferCopy field{0, 0, field_bytes_}, sites{0, field_bytes_, site_bytes_};
    rec.copy({{&field_buf_, &readback, {&field, 1}},
              {&field_sites_buf_, &readback,
               site_bytes_ > 0 ? std::span(&sites, 1) : std::span<const VkBufferCopy>()}});
  }

  void make_header() {
    header_ = {};
    header_.field_begin = {plan_.domain.begin.x, plan_.domain.begin.y, plan_.domain.begin.z, 0};
    header_.field_size = {plan_.domain.size().x, plan_.domain.size().y, plan_.domain.size().z,
                          row_pitch(plan_, options_.storage)};
    header_.metric = static_cast<std::uint32_t>(plan_.metric);
    header_.is_signed = plan_.is_signed ? 1u : 0u;
    header_.storage = options_.storage == Storage::kU8    ? L::VF_U8
                      : options_.storage == Storage::kU16 ? L::VF_U16
                                                          : L::VF_F32;
    header_.clamp_cost = clamp_cost(plan_);
    header_.track_sites = options_.nearest_sites ? 1u : 0u;
    header_.part_shift = split_part_shift(ctx_);
    // The CPU keeps a site when its cost is at most the clamp's cost, rounded down.
    const double clamp_c =
        plan_.metric == Metric::kEuclidean ? plan_.clamp * plan_.clamp : plan_.clamp;
    header_.site_cost_max =
        std::isfinite(clamp_c)
            ? static_cast<std::uint32_t>(std::min<double>(std::floor(clamp_c), L::VF_INF - 1.0))
            : L::VF_INF - 1;
    header_.bias = static_cast<std::int32_t>(plan_.encoding.bias);
    switch (options_.storage) {
      case Storage::kU8:
        set_encoding<std::uint8_t>(header_, plan_);
        break;
      case Storage::kU16:
        set_encoding<std::uint16_t>(header_, plan_);
        break;
      case Storage::kF32:
        set_encoding<float>(header_, plan_);
        break;
    }
    if (plan_.metric == Metric::kEuclidean && options_.storage != Storage::kF32) {
      const double s = plan_.encoding.scale;
      if (s != std::floor(s))
        throw InvalidArgument(
            "GPU: Euclidean fixed point needs an integral scale on the Vulkan backend");
      header_.scale_sq = static_cast<std::uint32_t>(s * s);
      const double costs = std::min<double>(header_.clamp_cost, 3.0 * kMaxExtent * kMaxExtent);
      if ((costs - 1) * s * s >= 4294967296.0)
        throw InvalidArgument("GPU: fixed-point scale " + std::to_string(s) +
                              " with this clamp overflows 32 bits");
    }
  }

  // The exact transform's binding plan (shaders/layout.h), the same for its three kernels.
  // The brick pool, the field and its sites in split_buffer.h's windows: the first at its own
  // binding, the other three from binding 11 on; a slab's column neighbours at 20.
  std::array<Binding, 21> bindings() {
    WorkBuffers& w = *work_;
    const auto bricks = split_bindings(resident_->bricks(), ctx_);
    const auto field = split_bindings(field_buf_, ctx_);
    const auto sites = split_bindings(field_sites_buf_, ctx_);
    return {&header_buf_,     &resident_->pages(),
            bricks[0],        &w.cost[0],
            &w.cost[1],       &w.cost[2],
            &w.scratch_s,     &w.scratch_t,
            field[0],         &w.sites,
            sites[0],         bricks[1],
            bricks[2],        bricks[3],
            field[1],         field[2],
            field[3],         sites[1],
            sites[2],         sites[3],
            &tables_.buffer()};
  }

  Context::Impl& ctx_;
  // The update's three kernels, looked up once: a lookup hashes the shader's SPIR-V, and an update
  // of many small regions dispatches them hundreds of times.
  struct Kernels {
    const Kernel& sites;
    const Kernel& lines;
    const Kernel& encode;
    const Kernel& columns;
  } kernels_;
  const World& world_;
  DistanceOptions options_;
  detail::FieldPlan plan_;
  L::Header header_{};
  VkBufferCopy header_copy_{};
  VkDeviceSize field_bytes_ = 0, site_bytes_ = 0;
  std::size_t upload_bytes_ = 0;  // staged by the last run
  std::shared_ptr<ResidentWorld> resident_;
  bool owns_world_ = true;
  bool first_run_ = true;
  bool resync_ = false;  // the last run threw: the next sends the whole world (run())
  // The passes' work buffers, shared with the fields on the same resident world (their runs are
  // submitted and waited for one at a time).
  std::shared_ptr<WorkBuffers> work_;
  Buffer header_buf_, field_buf_, field_sites_buf_;
  // The column neighbours of slabs: a slab field's own, and those of regions cut into z-slabs.
  NeighbourTables tables_;
};

DistanceField compute_distance_field(Context& context, const World& world,
                                     const DistanceOptions& options,
                                     std::vector<PassTiming>* timings) {
  const detail::FieldPlan plan = detail::make_field_plan(world.voxels, options);
  if (plan.domain.empty()) {
    if (options.nearest_sites)
      throw InvalidArgument("GPU: the Vulkan backend does not compute nearest sites yet");
    return voxfield::compute_distance_field(world, options);
  }
  FieldEngine engine(context.impl(), world, options);
  engine.run(engine.all_chunks(), engine.parts({{plan.domain, plan.domain}}), /*download=*/true,
             timings);
  DistanceField f = engine.read_back();
  f.frame = world.frame;
  return f;
}

DistanceField compute_slab_distance_field(Context& context, const World& world,
                                          const DistanceOptions& options, std::int32_t z0,
                                          std::int32_t z1, const SlabNeighbours& neighbours,
                                          std::vector<PassTiming>* timings) {
  if (!options.domain || options.domain->empty())
    throw InvalidArgument("a slab's field needs the whole field's domain (options.domain)");
  const Box3i& d = *options.domain;
  const Box3i slab{{d.begin.x, d.begin.y, z0}, {d.end.x, d.end.y, z1}};
  // The engine's plan refuses a slab outside the domain before the neighbours are read.
  FieldEngine engine(context.impl(), world, options, nullptr, nullptr, &slab);
  detail::exact::check_slab_neighbours(d, z0, z1, neighbours);
  engine.set_column_neighbours(neighbours);
  engine.run(engine.all_chunks(), engine.parts({{slab, slab}}), /*download=*/true, timings);
  DistanceField f = engine.read_back();
  f.frame = world.frame;
  return f;
}

// ---- DynamicField ----------------------------------------------------------------------------

DynamicField::DynamicField(std::shared_ptr<Context> context, const World& world,
                           DistanceOptions options)
    : context_(std::move(context)), frame_(world.frame) {
  if (!context_) throw InvalidArgument("gpu::DynamicField needs a context");
  if (!options.domain) {
    if (!world.voxels.bounds())
      throw InvalidArgument(
          "a dynamic distance field needs a fixed domain: bound the world or set options.domain");
    options.domain = *world.voxels.bounds();
  }
  engine_ = std::make_unique<FieldEngine>(context_->impl(), world, options);
  reach_ = detail::field_reach(engine_->plan());
  chunk_shift_ = world.voxels.chunk_shift();
  rebuild();
}

DynamicField::DynamicField(DynamicField& owner, DistanceOptions options)
    : context_(owner.context_), frame_(owner.frame_) {
  if (!owner.engine_->owns_world())
    throw InvalidArgument(
        "GPU: a field rides on the field that owns the resident world, not on another rider");
  const World& world = owner.engine_->world();
  if (!options.domain) options.domain = owner.engine_->plan().domain;
  engine_ =
      std::make_unique<FieldEngine>(context_->impl(), world, options,
                                    owner.engine_->resident_world(), owner.engine_->work_buffers());
  reach_ = detail::field_reach(engine_->plan());
  chunk_shift_ = world.voxels.chunk_shift();
  rebuild();
}

DynamicField::~DynamicField() = default;

const DistanceOptions& DynamicField::options() const {
  return engine_->options();
}

void DynamicField::rebuild() {
  const Box3i domain = engine_->plan().domain;
  engine_->run(engine_->all_chunks(), engine_->parts({{domain, domain}}), false, &timings_);
}

std::size_t DynamicField::field_bytes() const {
  return engine_->field_bytes();
}

DynamicDistanceField::UpdateStats DynamicField::update(const DirtyRegions& dirty) {
  DynamicDistanceField::UpdateStats stats;
  if (dirty.empty()) return stats;
  const std::vector<detail::UpdateRegion> merged =
      detail::update_regions(dirty, engine_->plan().domain, reach_);
  // (Each cut into slabs where the device's buffers need it: the slabs read more sites.)
  const std::vector<detail::UpdateRegion> regions = engine_->parts(merged);
  // The chunks whose voxels changed: the dirty boxes are per chunk.
  std::vector<Vec3i> chunks;
  for (const Box3i& b : dirty.boxes())
    chunks.push_back(
        {b.begin.x >> chunk_shift_, b.begin.y >> chunk_shift_, b.begin.z >> chunk_shift_});
  engine_->run(chunks, regions, false, &timings_);
  for (const auto& r : regions) {
    stats.voxels_recomputed += r.out.volume();
    stats.voxels_read += r.in.volume();
  }
  stats.regions = static_cast<int>(merged.size());
  return stats;
}

std::size_t DynamicField::last_upload_bytes() const {
  return engine_->upload_bytes();
}

ResidentField DynamicField::resident() {
  return engine_->resident();
}

DistanceField DynamicField::download() {
  engine_->run({}, {}, /*download=*/true, nullptr);
  DistanceField f = engine_->read_back();
  f.frame = frame_;
  return f;
}

}  // namespace voxfield::gpu

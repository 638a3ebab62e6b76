// The Vulkan backend's own checks: GPU against CPU field for field, the API traffic each operation
// costs (submits, fence waits, bytes), adopted devices, refusals (frames and resident scenes:
// test_gpu_render.cpp; work past one storage-buffer binding: test_gpu_ranges.cpp). The behaviour
// suites themselves have one body run on both backends (tests/backends.h: the brute-force sweep in
// test_distance.cpp, the incremental stream in test_edit.cpp). Integer fields must be
// bit-identical, f32 fields within gpu::kF32Tolerance; sizes that are not multiples of the
// workgroup or the chunk edge; the Khronos validation layer (with synchronisation validation) on,
// and not a single message from it. In CI this runs on Mesa's lavapipe.
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <random>
#include <set>

#include "gpu_fields.h"
#include "gpu_suite.h"
#include "shaders/layout.h"
#include "voxfield/edit.h"
#include "voxfield/gpu_distance.h"
#include "voxfield/gpu_vulkan.h"

using namespace voxfield;
using test::gpu_tests_wanted;
using test::random_world;
using test::validated_context;

using test::dense;
using test::expect_same_field;

TEST(Gpu, BackendNamesAndChoice) {
  EXPECT_EQ(parse_backend("vulkan"), Backend::kVulkan);
  EXPECT_THROW(parse_backend("metal"), InvalidArgument);
  std::string why;
  EXPECT_EQ(gpu::select_backend(Backend::kCpu, {}, &why), nullptr);
  EXPECT_NE(why.find("cpu"), std::string::npos);
  // auto never throws: a hardware GPU, or the CPU with the reason.
  const auto chosen = gpu::select_backend(Backend::kAuto, {}, &why);
  EXPECT_FALSE(why.empty());
  if (chosen) {
    EXPECT_TRUE(chosen->device().hardware);
  }
  if (!gpu::built_with_vulkan()) {
    EXPECT_THROW(gpu::Context::create(), GpuUnavailable);
  }
}

TEST(Gpu, DevicesAreChosenByIndexModuloTheirNumber) {
  // A node-local rank picks a device of its own (voxfield-mpi --device-per-rank): index k is device
  // k, modulo their number, among the usable devices of the most capable kind present, so any
  // index names one, and index 0 the first of them the loader lists.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  gpu::ContextOptions first;
  first.device_index = 0;
  const std::string name = gpu::Context::create(first)->device().name;
  std::set<std::string> names;
  for (int k : {1, 2, 3, 7}) {
    gpu::ContextOptions o;
    o.device_index = k;
    names.insert(gpu::Context::create(o)->device().name);
  }
  // Every index opened a device (none past the count is refused). With one usable device (this
  // machine's lavapipe) each is that device, the one chosen without an index too; which of
  // several devices an index names is the loader's order, not checked here.
  if (names.size() == 1 && *names.begin() == name)
    EXPECT_EQ(gpu::Context::create()->device().name, name);
}

TEST(Gpu, ExactFieldsEqualTheCpu) {
  if (!gpu_tests_wanted()) GTEST_SKIP() << "built without Vulkan, or VOXFIELD_SKIP_GPU_TESTS set";
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  for (const Vec3i size : {Vec3i{37, 29, 23}, Vec3i{70, 9, 65}}) {  // not multiples of 64 or 16
    const World w = random_world(size, 16, 0.02, 11u + static_cast<std::uint32_t>(size.x));
    for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
      for (bool sgn : {false, true})
        for (double clamp : {0.0, 6.0, 9.5})
          for (Storage st : {Storage::kU8, Storage::kU16, Storage::kF32}) {
            DistanceOptions o;
            o.metric = m;
            o.signed_distance = sgn;
            o.max_distance = clamp;
            o.storage = st;
            o.nearest_sites = st == Storage::kU16;  // sites once per metric, sign and clamp
            const std::string what = to_string(size) + " " + metric_name(m) +
                                     (sgn ? " signed" : "") + " clamp " + std::to_string(clamp) +
                                     " " + storage_name(st) + (o.nearest_sites ? " sites" : "");
            const gpu::Counters before = ctx->counters();
            const DistanceField g = gpu::compute_distance_field(*ctx, w, o);
            const gpu::Counters after = ctx->counters();
            expect_same_field(g, compute_distance_field(w, o), what);
            EXPECT_EQ(after.submits - before.submits, 1) << what;
            EXPECT_EQ(after.fence_waits - before.fence_waits, 1) << what;
          }
  }
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
}

TEST(Gpu, UnboundedWorldsAndEmptyDomains) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  World w(8);  // unbounded: the domain is the content grown by the clamp
  w.voxels.fill(Box3i{{-20, 3, 5}, {-12, 9, 7}}, 4);
  w.voxels.set({30, -4, 2}, 9);
  for (Metric m : {Metric::kManhattan, Metric::kEuclidean}) {
    DistanceOptions o;
    o.metric = m;
    o.max_distance = 5;
    o.storage = Storage::kU8;
    expect_same_field(gpu::compute_distance_field(*ctx, w, o), compute_distance_field(w, o),
                      metric_name(m));
  }
  const World empty(8);
  const DistanceField e = gpu::compute_distance_field(*ctx, empty, DistanceOptions{});
  EXPECT_TRUE(e.domain.empty());
  EXPECT_TRUE(ctx->validation_messages().empty());
}

TEST(Gpu, UnsupportedRequestsAreRefusedClearly) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  const World w = random_world({12, 12, 12}, 8, 0.05, 3);
  DistanceOptions spacing;
  spacing.metric = Metric::kEuclidean;
  spacing.spacing = {1, 2, 1};
  EXPECT_THROW(gpu::compute_distance_field(*ctx, w, spacing), InvalidArgument);
}

TEST(Gpu, TimestampsNameEveryPass) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  if (!ctx->has_timestamps()) GTEST_SKIP() << "no timestamps on this queue";
  const World w = random_world({20, 20, 20}, 8, 0.05, 5);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  std::vector<gpu::PassTiming> t;
  const auto t0 = std::chrono::steady_clock::now();
  gpu::compute_distance_field(*ctx, w, o, &t);
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::vector<std::string> names;
  for (const auto& p : t) names.push_back(p.pass);
  EXPECT_EQ(names,
            (std::vector<std::string>{"columns z", "lines x", "lines y", "columns z (to air)",
                                      "lines x (to air)", "lines y (to air)", "encode"}));
  // The passes run one after another inside the call: each took some time, and together no more
  // than the call did (a tick difference taken the wrong way round would wrap to ~10^13 ms).
  double sum_ms = 0;
  for (const auto& p : t) {
    EXPECT_GE(p.ms, 0) << p.pass;
    sum_ms += p.ms;
  }
  EXPECT_GT(sum_ms, 0);
  EXPECT_LE(sum_ms, wall_ms);
}

TEST(Gpu, IncrementalUpdatesEqualAFullRebuild) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  struct Case {
    Metric metric;
    bool is_signed;
    double clamp;
    Storage storage;
  };
  for (const Case& c : {Case{Metric::kEuclidean, false, 6, Storage::kU8},
                        Case{Metric::kManhattan, true, 5, Storage::kU16},
                        Case{Metric::kChebyshev, false, 4, Storage::kF32},
                        Case{Metric::kEuclidean, true, 0, Storage::kF32},
                        Case{Metric::kChebyshev, true, 5, Storage::kU8}}) {
    World w = random_world({53, 40, 34}, 8, 0.01, 21);
    DistanceOptions o;
    o.metric = c.metric;
    o.signed_distance = c.is_signed;
    o.max_distance = c.clamp;
    o.storage = c.storage;
    o.nearest_sites = c.storage != Storage::kF32;  // and with sites kept up to date too
    const std::string what = std::string(metric_name(c.metric)) + (c.is_signed ? " signed" : "") +
                             " clamp " + std::to_string(c.clamp) + " " + storage_name(c.storage) +
                             (o.nearest_sites ? " sites" : "");
    gpu::DynamicField live(ctx, w, o);
    DirtyRegions dirty(w.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> px(0, 52), py(0, 39), pz(0, 33), pr(1, 5), pm(0, 4);
    for (int i = 0; i < 25; ++i) {
      Edit e;
      const int m = pm(rng);
      e.op = m == 0 ? EditOp::kCarve : EditOp::kPlace;
      e.material = static_cast<std::uint8_t>(std::max(m, 1));
      e.brush = SphereBrush{{double(px(rng)), double(py(rng)), double(pz(rng))}, double(pr(rng))};
      apply_edit(w, e, &dirty);
      // Only the changed chunks travel: at most their bytes plus a page entry each.
      std::int64_t changed_bytes = 0;
      for (const Box3i& b : dirty.boxes()) {
        (void)b;
        changed_bytes += w.voxels.chunk_volume() + 4;
      }
      const gpu::Counters before = ctx->counters();
      live.update(dirty);
      const gpu::Counters after = ctx->counters();
      dirty.clear();
      EXPECT_LE(after.submits - before.submits, 1) << what;
      EXPECT_LE(after.fence_waits - before.fence_waits, 1) << what;
      EXPECT_EQ(after.bytes_downloaded, before.bytes_downloaded)
          << what << ": read-back inside an update";
      EXPECT_LE(after.bytes_uploaded - before.bytes_uploaded, changed_bytes) << what;
      if (i % 6 == 5 || i == 24)
        expect_same_field(live.download(), compute_distance_field(w, o),
                          what + " after edit " + std::to_string(i));
    }
  }
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
}

TEST(Gpu, BrickPoolReusesAndGrowsCorrectly) {
  // A chunk emptied, then many chunks filled in one update: the freed slot is reused and the pool
  // must grow for the rest, within one submission and without touching memory out of range.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  World w(8, Box3i::from_size({64, 64, 16}));
  for (int i = 0; i < 6; ++i) w.voxels.set({i * 8 + 3, 5, 5}, 9);  // six dense chunks
  DistanceOptions o;
  o.metric = Metric::kChebyshev;
  o.max_distance = 4;
  o.storage = Storage::kU8;
  gpu::DynamicField live(ctx, w, o);
  EXPECT_EQ(live.field_bytes(), 64u * 64 * 16);  // u8 resident as on the CPU: one byte per voxel
  DirtyRegions dirty(8, DirtyRegions::Track::kOccupancy);
  apply_edit(w, {EditOp::kCarve, BoxBrush{{0, 0, 0}, {7, 7, 7}}, 1}, &dirty);  // frees one slot
  live.update(dirty);
  dirty.clear();
  for (int x = 0; x < 8; ++x)
    for (int y = 2; y < 8; ++y)
      apply_edit(w, {EditOp::kPlace, SphereBrush{{x * 8.0 + 4, y * 8.0 + 4, 12}, 1}, 3}, &dirty);
  const gpu::Counters before = ctx->counters();
  live.update(dirty);
  EXPECT_EQ(ctx->counters().submits - before.submits, 1);
  expect_same_field(live.download(), compute_distance_field(w, o),
                    "after freeing one slot and filling 48 chunks");
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
}

TEST(Gpu, FieldsShareOneResidentWorld) {
  // A second field on the first's resident world: the device holds the world once, the second
  // field's updates upload nothing, and both fields stay equal to the CPU's through edits that
  // make the shared brick pool grow (the second field then reads the moved pool).
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  World w(8, Box3i::from_size({48, 40, 24}));
  w.voxels.set({5, 5, 5}, 4);
  DistanceOptions a;
  a.metric = Metric::kManhattan;
  a.max_distance = 6;
  a.storage = Storage::kU8;
  DistanceOptions b;
  b.metric = Metric::kEuclidean;
  b.signed_distance = true;
  b.storage = Storage::kF32;
  gpu::DynamicField owner(ctx, w, a);
  const gpu::Counters before_build = ctx->counters();
  gpu::DynamicField rider(owner, b);
  // Its header only: no page entry, no brick.
  EXPECT_EQ(ctx->counters().bytes_uploaded - before_build.bytes_uploaded,
            static_cast<std::int64_t>(sizeof(gpu::layout::Header)));
  EXPECT_EQ(rider.resident().bricks, owner.resident().bricks);
  const VkDeviceSize pool_before = owner.resident().bricks->size();
  DirtyRegions dirty(8, DirtyRegions::Track::kOccupancy);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> px(0, 47), py(0, 39), pz(0, 23), pr(2, 6);
  for (int i = 0; i < 8; ++i) {
    apply_edit(w,
               {i % 3 == 2 ? EditOp::kCarve : EditOp::kPlace,
                SphereBrush{{double(px(rng)), double(py(rng)), double(pz(rng))}, double(pr(rng))},
                static_cast<std::uint8_t>(1 + i)},
               &dirty);
    owner.update(dirty);
    const gpu::Counters before = ctx->counters();
    rider.update(dirty);
    EXPECT_EQ(ctx->counters().bytes_uploaded, before.bytes_uploaded) << "edit " << i;
    dirty.clear();
    expect_same_field(owner.download(), compute_distance_field(w, a),
                      "owner after edit " + std::to_string(i));
    expect_same_field(rider.download(), compute_distance_field(w, b),
                      "rider after edit " + std::to_string(i));
  }
  EXPECT_GT(owner.resident().bricks->size(), pool_before);  // the pool grew and moved
  DistanceOptions elsewhere = a;
  elsewhere.domain = Box3i{{0, 0, 0}, {16, 16, 16}};  // other chunks than the owner's
  EXPECT_THROW(gpu::DynamicField(owner, elsewhere), InvalidArgument);
  EXPECT_THROW(gpu::DynamicField(rider, a), InvalidArgument);  // a rider owns no world to ride on
  test::expect_no_validation_messages(*ctx);
}

TEST(Gpu, JumpFloodingEqualsTheCpu) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  const World w = random_world({45, 33, 27}, 16, 0.005, 41);
  for (Algorithm alg : {Algorithm::kJfaSeed, Algorithm::kJfa, Algorithm::kJfa1, Algorithm::kJfa2})
    for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
      for (bool sgn : {false, true}) {
        DistanceOptions o;
        o.metric = m;
        o.signed_distance = sgn;
        o.storage = m == Metric::kEuclidean ? Storage::kF32 : Storage::kU16;
        AlgorithmOptions a;
        a.algorithm = alg;
        AlgorithmStats gs, cs;
        const std::string what =
            std::string(algorithm_name(alg)) + " " + metric_name(m) + (sgn ? " signed" : "");
        const DistanceField g = gpu::compute_distance_field(*ctx, w, o, a, &gs);
        const DistanceField c = compute_distance_field(w, o, a, &cs);
        expect_same_field(g, c, what);
        EXPECT_EQ(gs.passes, cs.passes) << what;
        // Bit-identical, f32 included: the distances come from the same sites on both.
        if (o.storage == Storage::kF32) {
          EXPECT_EQ(dense<float>(g), dense<float>(c)) << what;
        }
      }
  AlgorithmOptions brute;
  brute.algorithm = Algorithm::kBruteChunked;
  EXPECT_THROW(gpu::compute_distance_field(*ctx, w, DistanceOptions{}, brute), InvalidArgument);
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
}

TEST(Gpu, IterativeMethodsEqualTheCpu) {
  // FIM, hybrid (JFA then FIM) and LOD (FIM in the focus chunks) as Jacobi passes that stop
  // themselves. Manhattan and Chebyshev converge to whole numbers, so every storage is bit for bit
  // the CPU's. The Euclidean (Godunov) rule settles within the CPU's tolerance of 1e-5 voxels in
  // either order of updates, and the GPU solves it in floats relative to the smallest neighbour:
  // values agree within kFimTolerance, and quantised storage within one step.
  constexpr double kFimTolerance = 1e-4;  // voxels: measured 1.4e-5 (a chain of sub-eps residuals)
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  const World w = random_world({41, 30, 23}, 8, 0.004, 52);
  for (Algorithm alg : {Algorithm::kFim, Algorithm::kHybrid, Algorithm::kLod})
    for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
      for (bool sgn : {false, true}) {
        DistanceOptions o;
        o.metric = m;
        o.signed_distance = sgn;
        o.storage = m == Metric::kEuclidean ? Storage::kF32 : (sgn ? Storage::kU16 : Storage::kU8);
        AlgorithmOptions a;
        a.algorithm = alg;
        a.focus = Box3i{{10, 8, 4}, {22, 17, 12}};
        AlgorithmStats gs, cs;
        const std::string what =
            std::string(algorithm_name(alg)) + " " + metric_name(m) + (sgn ? " signed" : "");
        const gpu::Counters before = ctx->counters();
        const DistanceField g = gpu::compute_distance_field(*ctx, w, o, a, &gs);
        const gpu::Counters after = ctx->counters();
        const DistanceField c = compute_distance_field(w, o, a, &cs);
        // No read-back decides anything: FIM is one submit per sign, hybrid and LOD add JFA's.
        EXPECT_LE(after.submits - before.submits, (alg == Algorithm::kFim ? 1 : 2) * (sgn ? 2 : 1))
            << what;
        EXPECT_GT(gs.iterations, 0) << what;
        if (m != Metric::kEuclidean) {
          expect_same_field(g, c, what);
          continue;
        }
        const auto a_values = dense<float>(g), b_values = dense<float>(c);
        ASSERT_EQ(a_values.size(), b_values.size());
        double worst = 0;
        for (std::size_t i = 0; i < a_values.size(); ++i)
          worst = std::max(worst, std::abs(double{a_values[i]} - b_values[i]));
        EXPECT_LE(worst, kFimTolerance) << what;
        // And a quantised copy moves by at most one step.
        o.storage = Storage::kU16;
        o.max_distance = 20;
        const auto gq = dense<std::uint16_t>(gpu::compute_distance_field(*ctx, w, o, a));
        const auto cq = dense<std::uint16_t>(compute_distance_field(w, o, a));
        for (std::size_t i = 0; i < gq.size(); ++i)
          ASSERT_LE(std::abs(int{gq[i]} - int{cq[i]}), 1) << what << " voxel " << i;
      }
  // An unreachable domain (no sites) stays "far" and still converges.
  const World empty(8, Box3i::from_size({9, 9, 9}));
  AlgorithmOptions fim;
  fim.algorithm = Algorithm::kFim;
  DistanceOptions o;
  expect_same_field(gpu::compute_distance_field(*ctx, empty, o, fim),
                    compute_distance_field(empty, o, fim), "no sites");
  DistanceOptions sites;
  sites.nearest_sites = true;
  EXPECT_THROW(gpu::compute_distance_field(*ctx, w, sites, fim), InvalidArgument);
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
}

// An application's own device (the demo's case), made here through the loader directly.
TEST(Gpu, AdoptsAnApplicationsDevice) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  void* loader = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(loader, nullptr);
  const auto get_instance_proc =
      reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(loader, "vkGetInstanceProcAddr"));
  ASSERT_NE(get_instance_proc, nullptr);
  const auto create_instance =
      reinterpret_cast<PFN_vkCreateInstance>(get_instance_proc(nullptr, "vkCreateInstance"));
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  VkInstance instance = VK_NULL_HANDLE;
  ASSERT_EQ(create_instance(&ici, nullptr, &instance), VK_SUCCESS);
  auto fn = [&](const char* name) { return get_instance_proc(instance, name); };
  const auto enumerate =
      reinterpret_cast<PFN_vkEnumeratePhysicalDevices>(fn("vkEnumeratePhysicalDevices"));
  const auto families_of = reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
      fn("vkGetPhysicalDeviceQueueFamilyProperties"));
  const auto create_device = reinterpret_cast<PFN_vkCreateDevice>(fn("vkCreateDevice"));
  const auto get_queue = reinterpret_cast<PFN_vkGetDeviceQueue>(fn("vkGetDeviceQueue"));
  const auto destroy_device = reinterpret_cast<PFN_vkDestroyDevice>(fn("vkDestroyDevice"));
  const auto destroy_instance = reinterpret_cast<PFN_vkDestroyInstance>(fn("vkDestroyInstance"));
  std::uint32_t count = 1;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  enumerate(instance, &count, &physical);
  ASSERT_NE(physical, VK_NULL_HANDLE);
  std::uint32_t nq = 0;
  families_of(physical, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  families_of(physical, &nq, families.data());
  std::uint32_t family = 0;
  while (family < nq && !(families[family].queueFlags & VK_QUEUE_COMPUTE_BIT)) ++family;
  ASSERT_LT(family, nq);
  const float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  VkDevice device = VK_NULL_HANDLE;
  ASSERT_EQ(create_device(physical, &dci, nullptr, &device), VK_SUCCESS);
  VkQueue queue = VK_NULL_HANDLE;
  get_queue(device, family, 0, &queue);
  {
    const auto ctx = gpu::adopt({instance, physical, device, queue, family});
    const World w = random_world({30, 22, 17}, 8, 0.03, 77);
    DistanceOptions o;
    o.metric = Metric::kEuclidean;
    o.storage = Storage::kU16;
    o.max_distance = 9;
    expect_same_field(gpu::compute_distance_field(*ctx, w, o), compute_distance_field(w, o),
                      "adopted device");
    EXPECT_THROW(gpu::adopt({instance, physical, VK_NULL_HANDLE, queue, family}), InvalidArgument);
  }  // the context is gone; the application's device and instance are still ours to destroy
  destroy_device(device, nullptr);
  destroy_instance(instance, nullptr);
  dlclose(loader);
}

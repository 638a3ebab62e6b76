// voxfield-demo — the terrain mode (terrain_mode.h).
#include "terrain_mode.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "clock.h"
#include "voxfield/error.h"
#include "voxfield/mesh_render.h"

namespace voxfield::demo {
namespace {

const TerrainStorage kStorages[] = {TerrainStorage::kI8, TerrainStorage::kI16,
                                    TerrainStorage::kF32};
const Mesher kMeshers[] = {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring};

// Rolling hills a third of the way up: a height map's first-order signed distance.
double hills(const Vec3d& p, double n) {
  const double h = n * (0.16 + 0.05 * std::sin(p.x / (n / 7.0)) * std::cos(p.y / (n / 5.0)) +
                        0.025 * std::sin((p.x + 2 * p.y) / (n / 3.0)));
  return p.z - h;
}

Palette terrain_palette() {
  Palette p{};
  p[1] = {96, 132, 68, 255};    // grass
  p[2] = {128, 118, 108, 255};  // rock
  p[3] = {214, 192, 128, 255};  // sand
  p[4] = {236, 238, 242, 255};  // snow
  p[5] = {150, 84, 56, 255};    // clay
  p[6] = {70, 96, 150, 255};    // slate
  p[7] = {60, 60, 64, 255};     // basalt
  p[8] = {196, 160, 60, 255};   // ochre
  p[9] = {170, 60, 60, 255};    // brick
  return p;
}

TerrainOptions options_of(const TerrainSettings& s) {
  TerrainOptions o;
  o.samples = {s.size, s.size, std::max(16, s.size / 2)};
  o.storage = kStorages[s.storage];
  o.palette = terrain_palette();
  return o;
}

}  // namespace

TerrainMode::TerrainMode(const TerrainSettings& settings, std::shared_ptr<gpu::Context> context)
    : settings_(settings), terrain_(options_of(settings)) {
  const double n = settings.size;
  terrain_.assign([n](const Vec3d& p) { return hills(p, n); }, 1);
  if (context && kMeshers[settings.mesher] == Mesher::kMarchingCubes) {
    try {
      const auto start = std::chrono::steady_clock::now();
      gpu_ = std::make_unique<gpu::TerrainRenderer>(std::move(context));
      gpu_->sync(terrain_);
      first_mesh_ms_ = last_mesh_ms_ = ms_since(start);
    } catch (const Error& e) {
      gpu_.reset();
      gpu_note_ = e.what();
    }
  } else if (context) {
    gpu_note_ = "the GPU draws marching cubes only";
  }
  // The CPU mesh: for the CPU's frames, and for triangle edges (which the GPU does not draw).
  if (!gpu_) mesh_on_cpu();
}

void TerrainMode::mesh_on_cpu() {
  MeshOptions mo;
  mo.algorithm = kMeshers[settings_.mesher];
  mo.chunk_edge = settings_.chunk;
  const auto start = std::chrono::steady_clock::now();
  chunks_.emplace(terrain_, mo);
  mesh_ = chunks_->merged();
  first_mesh_ms_ = last_mesh_ms_ = ms_since(start);
}

Box3i TerrainMode::box() const {
  return Box3i::from_size(terrain_.size());
}

std::size_t TerrainMode::triangles() const {
  return on_gpu() ? gpu_->last_triangles() : mesh_.triangle_count();
}

void TerrainMode::apply(const TerrainBrush& brush) {
  const auto start = std::chrono::steady_clock::now();
  const Box3i changed = terrain_.apply(brush);
  last_brush_ms_ = ms_since(start);
  const auto meshing = std::chrono::steady_clock::now();
  const std::uint64_t per_sample = settings_.storage == 0 ? 1 : settings_.storage == 1 ? 2 : 4;
  last_bytes_up_ = static_cast<std::uint64_t>(changed.volume()) * (per_sample + 1);
  last_chunks_ = 0;
  if (gpu_ && !changed.empty()) {  // uploaded with the frame's other edits (upload_edits)
    pending_.push_back(changed);
    // Many edits between GPU frames (the CPU drawing meanwhile): one box holding them all.
    if (pending_.size() > 16) {
      Box3i all;
      for (const Box3i& b : pending_) all = all.unite(b);
      pending_.assign(1, all);
    }
  }
  if (chunks_) {  // the CPU mesh, when there is one, follows
    last_chunks_ = chunks_->update(terrain_, changed).size();
    mesh_ = chunks_->merged();
    last_mesh_ms_ = ms_since(meshing);
  }
  ++edits_;
}

bool TerrainMode::edit_at(const Ray& ray, bool add, std::uint8_t material) {
  // March the ray through the lattice's box in half-sample steps until a sample below it reads
  // inside (nearest sample: a brush centre needs no more).
  const Vec3i n = terrain_.size();
  const Vec3d d = ray.direction.normalized();
  double t0 = 0, t1 = 1e9;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (ray.origin[a] < 0 || ray.origin[a] > n[a] - 1) return false;
      continue;
    }
    double lo = (0 - ray.origin[a]) / d[a], hi = (n[a] - 1 - ray.origin[a]) / d[a];
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  if (t0 > t1) return false;
  for (double t = t0; t <= t1; t += 0.5) {
    const Vec3d p = ray.origin + d * t;
    const Vec3i s{std::clamp(static_cast<int>(std::lround(p.x)), 0, n.x - 1),
                  std::clamp(static_cast<int>(std::lround(p.y)), 0, n.y - 1),
                  std::clamp(static_cast<int>(std::lround(p.z)), 0, n.z - 1)};
    if (terrain_.value(s) < 0) {
      TerrainBrush b;
      b.shape = settings_.shape == 0 ? TerrainBrush::Shape::kSphere : TerrainBrush::Shape::kBox;
      b.mode = add ? TerrainBrush::Mode::kAdd : TerrainBrush::Mode::kSubtract;
      b.centre_units = p;
      b.radius_units = settings_.radius;
      b.half_extents_units = {settings_.radius, settings_.radius, settings_.radius};
      b.smooth_units = settings_.smooth;
      b.material = material;
      apply(b);
      last_edit_ =
          std::string(add ? "added" : "carved") + (settings_.shape == 0 ? " a sphere" : " a box");
      return true;
    }
  }
  return false;
}

void TerrainMode::edit_above(double x, double y, bool add, std::uint8_t material) {
  const Vec3i n = terrain_.size();
  const Vec3i column{std::clamp(static_cast<int>(x), 0, n.x - 1),
                     std::clamp(static_cast<int>(y), 0, n.y - 1), 0};
  int z = n.z - 1;
  while (z > 0 && terrain_.value({column.x, column.y, z}) >= 0) --z;
  Ray down;
  down.origin = {x, y, static_cast<double>(std::min(n.z - 1, z + 2))};
  down.direction = {0, 0, -1};
  edit_at(down, add, material);
}

Image TerrainMode::render(const FlyCamera& camera, int width, int height) {
  MeshRenderOptions o;
  o.width = width;
  o.height = height;
  o.edges = settings_.edges;
  if (!chunks_) mesh_on_cpu();  // triangle edges asked of a mode the GPU draws
  return render_mesh(mesh_, camera.camera(), o);
}

void TerrainMode::upload_edits() {
  // The GPU draws from here on: the CPU mesh (made for triangle edges) is dropped, so edits do not
  // re-mesh on the CPU too.
  chunks_.reset();
  mesh_ = {};
  if (pending_.empty()) return;
  // The edits since the last frame: their boxes' samples, one submit.
  const auto start = std::chrono::steady_clock::now();
  last_bytes_up_ = gpu_->sync(terrain_, pending_);
  last_mesh_ms_ = ms_since(start);
  pending_.clear();
}

VkBuffer TerrainMode::record_frame(VkCommandBuffer cmd, const FlyCamera& camera, int width,
                                   int height, gpu::PixelOrder order) {
  MeshRenderOptions o;
  o.width = width;
  o.height = height;
  return gpu::record_render(*gpu_, cmd, terrain_view(camera.camera(), o), order);
}

void TerrainMode::frame(FlyCamera& camera, const TerrainSettings& s) {
  // From above the (-x, -y) corner, looking a little left of the centre so that the terrain shows
  // beside the panel.
  const double n = s.size, angle = 1.25 * 3.14159265358979323846;
  const Vec3d centre{0.5 * n, 0.5 * n, 0.15 * n};
  const Vec3d right{-std::sin(angle), std::cos(angle), 0};
  camera.look(centre + Vec3d{0.95 * n * std::cos(angle), 0.95 * n * std::sin(angle), 0.7 * n},
              centre - right * (0.3 * n));
}

bool TerrainMode::panel(TerrainSettings& s) {
  bool changed = false;
  const char* sizes[] = {"64", "128", "192", "256"};
  int size = s.size / 64 - 1;
  if (ImGui::Combo("terrain size", &size, sizes, 4)) {
    s.size = 64 * (size + 1);
    changed = true;
  }
  const char* storages[] = {"i8", "i16", "f32"};
  changed |= ImGui::Combo("storage", &s.storage, storages, 3);
  const char* meshers[] = {"marching cubes", "surface nets", "dual contouring"};
  changed |= ImGui::Combo("mesher", &s.mesher, meshers, 3);
  const char* chunks[] = {"8", "16", "32"};
  int chunk = s.chunk == 8 ? 0 : s.chunk == 16 ? 1 : 2;
  if (ImGui::Combo("mesh chunk", &chunk, chunks, 3)) {
    s.chunk = 8 << chunk;
    changed = true;
  }
  // The brush and the picture change without a rebuild.
  const char* shapes[] = {"sphere", "box"};
  ImGui::Combo("brush", &s.shape, shapes, 2);
  ImGui::SliderFloat("radius", &s.radius, 1, 24, "%.1f");
  ImGui::SliderFloat("blend", &s.smooth, 0, 12, "%.1f");
  ImGui::Checkbox("triangle edges", &s.edges);
  return changed;
}

void TerrainMode::stats_panel() const {
  const TerrainField::Memory m = terrain_.memory();
  ImGui::Text("%s field: %.1f MB, %lld of %lld chunks uniform",
              terrain_storage_name(terrain_.options().storage), static_cast<double>(m.bytes) / 1e6,
              static_cast<long long>(m.uniform_chunks), static_cast<long long>(m.chunks));
  ImGui::Text("%zu triangles; %s %.0f ms", triangles(), on_gpu() ? "first upload" : "first mesh",
              first_mesh_ms_);
  if (edits_ > 0) {
    if (on_gpu())
      ImGui::Text("%s: brush %.2f ms; the frame's upload %.2f ms", last_edit_.c_str(),
                  last_brush_ms_, last_mesh_ms_);
    else
      ImGui::Text("%s: brush %.2f ms, re-mesh %.2f ms (%zu chunks)", last_edit_.c_str(),
                  last_brush_ms_, last_mesh_ms_, last_chunks_);
    ImGui::Text("%.1f kB up for the %s (the whole field: %.1f MB)",
                static_cast<double>(last_bytes_up_) / 1e3, on_gpu() ? "last frame's edits" : "edit",
                static_cast<double>(box().volume()) *
                    (settings_.storage == 0   ? 1
                     : settings_.storage == 1 ? 2
                                              : 4) /
                    1e6);
  }
  if (on_gpu())
    ImGui::TextDisabled("marching cubes + HistoPyramid + indirect draw on the GPU");
  else
    ImGui::TextDisabled("drawn by the CPU rasteriser%s%s", gpu_note_.empty() ? "" : ": ",
                        gpu_note_.c_str());
}

}  // namespace voxfield::demo

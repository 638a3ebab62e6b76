// voxfield-demo — the ImGui panel: what draws the frames and how fast, the brush, the view (and
// the algorithm the error view measures), the field's metric and clamp, and the world (size,
// chunk edge, save and load); and the key help (F1).
#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <string>
#include <vector>

#include "demo.h"
#include "voxfield/error.h"

namespace voxfield::demo {

void Demo::panel() {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("voxfield");
  int mode = vectors_ ? 1 : terrain_ ? 2 : 0;
  const char* modes[] = {"world", "vectors", "terrain"};
  if (ImGui::Combo("mode", &mode, modes, 3)) set_mode(static_cast<Mode>(mode));
  if (terrain_) {
    ImGui::TextWrapped("%s", status_.c_str());
    ImGui::Text("frame %.1f ms (%.1f FPS), picture %.1f ms", last_.frame_ms,
                last_.frame_ms > 0 ? 1000.0 / last_.frame_ms : 0.0, last_.render_ms);
    terrain_->stats_panel();
    if (ImGui::CollapsingHeader("Terrain", ImGuiTreeNodeFlags_DefaultOpen)) {
      terrain_settings_ = terrain_->settings();
      if (TerrainMode::panel(terrain_settings_)) {
        try {
          set_mode(Mode::kTerrain);
        } catch (const Error& e) {
          status_ = e.what();
        }
      } else {
        terrain_->brush_settings() = terrain_settings_;
      }
    }
    ImGui::TextWrapped(
        "left click adds, right click carves; 1 .. 9 the material; wheel the radius");
    ImGui::End();
    return;
  }
  if (vectors_) {
    ImGui::TextWrapped("%s", status_.c_str());
    ImGui::Text("frame %.1f ms (%.1f FPS), picture %.1f ms", last_.frame_ms,
                last_.frame_ms > 0 ? 1000.0 / last_.frame_ms : 0.0, last_.render_ms);
    vectors_->stats_panel();
    if (ImGui::CollapsingHeader("Field", ImGuiTreeNodeFlags_DefaultOpen) &&
        VectorsMode::panel(vectors_settings_)) {
      try {
        set_mode(Mode::kVectors);
      } catch (const Error& e) {
        status_ = e.what();
      }
    }
    const char* backends[] = {"cpu", "vulkan"};
    if (vk_ && ImGui::Combo("backend", &ui_backend_, backends, 2))
      choose_path(backends[ui_backend_]);
    ImGui::End();
    return;
  }
  ImGui::TextWrapped("%s", gpu_can_draw()
                               ? path_.why.c_str()
                               : (path_.renderer ? "CPU renderer (this view is not on the GPU yet)"
                                                 : path_.why.c_str()));
  if (path_.device_fields)
    ImGui::TextWrapped("%s", world_->device_scene()
                                 ? "fields: computed and kept on the device"
                                 : "fields: on the host (the device could not hold them)");
  ImGui::Text("%s, chunk %d", world_->origin().c_str(), world_->settings().chunk_edge);
  ImGui::Separator();
  ImGui::Text("frame %.1f ms (%.1f FPS)", last_.frame_ms,
              last_.frame_ms > 0 ? 1000.0 / last_.frame_ms : 0.0);
  ImGui::Text("render %.1f ms, last update %.2f ms", last_.render_ms, last_.update_ms);
  std::vector<float> history(frame_history_.begin(), frame_history_.end());
  if (!history.empty())
    ImGui::PlotLines("##frames", history.data(), static_cast<int>(history.size()), 0, "frame ms",
                     0.0f, FLT_MAX, ImVec2(0, 50));
  ImGui::Text("%lld edits", static_cast<long long>(world_->edits()));
  if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());

  if (ImGui::CollapsingHeader("Brush", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::SliderInt("radius", &brush_.radius, 0, 32);
    int material = brush_.material;
    if (ImGui::SliderInt("material", &material, 1, 255))
      brush_.material = static_cast<std::uint8_t>(material);
    const Rgba c = world_->world().palette[brush_.material];
    ImGui::ColorButton("##swatch", ImVec4(c.r / 255.0f, c.g / 255.0f, c.b / 255.0f, 1.0f));
    ImGui::SameLine();
    ImGui::Checkbox("paint (P)", &brush_.paint);
  }
  if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) {
    const char* views[] = {"shaded", "distance", "error", "chunks"};
    int v = static_cast<int>(view_);
    if (ImGui::Combo("view", &v, views, 4)) view_ = static_cast<RenderView>(v);
    const std::vector<Algorithm> algorithms = all_algorithms();
    int a = static_cast<int>(std::find(algorithms.begin(), algorithms.end(), error_algorithm_) -
                             algorithms.begin());
    if (ImGui::BeginCombo("algorithm", algorithm_name(error_algorithm_))) {
      for (std::size_t i = 0; i < algorithms.size(); ++i)
        if (ImGui::Selectable(algorithm_name(algorithms[i]), static_cast<int>(i) == a))
          error_algorithm_ = algorithms[i];
      ImGui::EndCombo();
    }
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("the approximation the error view measures against the exact field");
    const char* backends[] = {"cpu", "vulkan"};
    if (vk_) {
      if (ImGui::Combo("backend", &ui_backend_, backends, 2)) choose_path(backends[ui_backend_]);
    } else {
      ImGui::TextDisabled("backend: cpu (no usable Vulkan device)");
    }
  }
  if (ImGui::CollapsingHeader("Field")) {
    const char* metrics[] = {"manhattan", "chebyshev", "euclidean"};
    ImGui::Combo("metric", &ui_metric_, metrics, 3);
    ImGui::SliderFloat("max distance", &ui_max_distance_, 1, ui_metric_ == 2 ? 63 : 255,
                       "%.0f voxels");
    if (ImGui::Button("rebuild the fields")) {
      try {
        world_->set_field(static_cast<Metric>(ui_metric_), ui_max_distance_);
        status_ = "fields rebuilt";
      } catch (const Error& e) {
        status_ = e.what();
      }
    }
  }
  if (ImGui::CollapsingHeader("World")) {
    ImGui::SliderInt("size", &ui_size_, 32, 512);
    const char* chunks[] = {"8", "16", "32", "64"};
    int c = ui_chunk_ == 8 ? 0 : ui_chunk_ == 16 ? 1 : ui_chunk_ == 32 ? 2 : 3;
    if (ImGui::Combo("chunk edge", &c, chunks, 4)) ui_chunk_ = 8 << c;
    if (ImGui::Button("regenerate")) {
      WorldSettings s = world_->settings();
      s.size = ui_size_;
      s.chunk_edge = ui_chunk_;
      try {
        replace_world(std::make_unique<DemoWorld>(s), "regenerated");
      } catch (const Error& e) {
        status_ = e.what();
      }
    }
    ImGui::InputText("save as", save_path_, sizeof save_path_);
    if (ImGui::Button("save")) {
      try {
        world_->save(save_path_);
        status_ = std::string("saved ") + save_path_;
      } catch (const Error& e) {
        status_ = e.what();
      }
    }
    ImGui::InputText("load", load_path_, sizeof load_path_);
    if (ImGui::Button("load .vox / .vfw / .npy")) {
      try {
        WorldSettings s = world_->settings();
        s.chunk_edge = ui_chunk_;
        replace_world(std::make_unique<DemoWorld>(s, load_path_),
                      std::string("loaded ") + load_path_);
      } catch (const Error& e) {
        status_ = e.what();  // the current world stays
      }
    }
  }
  ImGui::End();
}

void Demo::help() {
  ImGui::SetNextWindowPos(ImVec2(width() * 0.5f, height() * 0.5f), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::Begin("help (F1)", &show_help_, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("W A S D       fly; Space / Shift up and down; Ctrl faster");
  ImGui::Text("middle drag   look around; Tab toggles mouse look (edits at the centre)");
  ImGui::Text("left click    place a sphere of the material (paint in paint mode)");
  ImGui::Text("right click   carve a sphere");
  ImGui::Text("scroll        brush radius");
  ImGui::Text("1 .. 9        material; P toggles paint mode");
  ImGui::Text("F12           screenshot (voxfield-demo-N.png)");
  ImGui::Text("F1            this help");
  ImGui::Text("Ctrl+Q        quit");
  ImGui::End();
}

}  // namespace voxfield::demo

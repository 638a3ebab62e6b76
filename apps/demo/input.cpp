// voxfield-demo — the keyboard and the mouse: flying the camera, and brushes that place, carve
// and paint where the cursor points.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "demo.h"

namespace voxfield::demo {

Ray Demo::cursor_ray() {
  double x = 0, y = 0;
  if (look_mode_) {
    x = width() / 2.0;
    y = height() / 2.0;
  } else {
    glfwGetCursorPos(glfw(), &x, &y);
    int ww = 1, wh = 1;
    glfwGetWindowSize(glfw(), &ww, &wh);
    x *= static_cast<double>(width()) / std::max(ww, 1);
    y *= static_cast<double>(height()) / std::max(wh, 1);
  }
  return camera_.camera().projector(width(), height()).ray(x, y);
}

void Demo::edit_at_cursor(EditOp op) {
  if (terrain_) {  // left adds, right carves; the material keys choose what is added
    const auto t0 = Clock::now();
    if (terrain_->edit_at(cursor_ray(), op != EditOp::kCarve, brush_.material))
      last_.update_ms = ms_between(t0, Clock::now());
    return;
  }
  const Ray ray = cursor_ray();
  const RayHit hit = world_->pick(ray);
  if (!hit.hit) return;
  Vec3d centre{static_cast<double>(hit.voxel.x), static_cast<double>(hit.voxel.y),
               static_cast<double>(hit.voxel.z)};
  if (op == EditOp::kPlace && hit.face_axis >= 0)
    centre[hit.face_axis] += hit.face_sign * brush_.radius;
  const auto t0 = Clock::now();
  const auto st =
      world_->apply({op, SphereBrush{centre, static_cast<double>(brush_.radius)}, brush_.material});
  last_.update_ms = ms_between(t0, Clock::now());
  status_ = std::string(op == EditOp::kPlace   ? "placed"
                        : op == EditOp::kCarve ? "carved"
                                               : "painted") +
            " r " + std::to_string(brush_.radius) + ": " + std::to_string(st.chunks_changed) +
            " chunks refreshed";
}

void Demo::handle_input(double dt_s) {
  GLFWwindow* w = glfw();
  const ImGuiIO& io = ImGui::GetIO();
  auto down = [&](int key) { return glfwGetKey(w, key) == GLFW_PRESS; };
  // Keys that act once per press.
  const std::vector<int> keys = std::exchange(keys_pressed_, {});
  auto pressed = [&](int key) { return std::find(keys.begin(), keys.end(), key) != keys.end(); };
  if (pressed(GLFW_KEY_F1)) show_help_ = !show_help_;
  if (pressed(GLFW_KEY_F12))
    take_screenshot("voxfield-demo-" + std::to_string(++screenshots_) + ".png");
  if (pressed(GLFW_KEY_TAB)) {
    look_mode_ = !look_mode_;
    glfwSetInputMode(w, GLFW_CURSOR, look_mode_ ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
  }
  if (pressed(GLFW_KEY_ESCAPE) && look_mode_) {
    look_mode_ = false;
    glfwSetInputMode(w, GLFW_CURSOR, GLFW_CURSOR_NORMAL);
  }
  if (!io.WantCaptureKeyboard) {
    if (pressed(GLFW_KEY_P)) brush_.paint = !brush_.paint;
    for (int k = 1; k <= 9; ++k)
      if (pressed(GLFW_KEY_0 + k)) brush_.material = static_cast<std::uint8_t>(k);
    const double speed =
        (down(GLFW_KEY_LEFT_CONTROL) || down(GLFW_KEY_RIGHT_CONTROL) ? 4.0 : 1.0) *
        (vectors_   ? 4.0  // world units per second across the agents' 10-unit box
         : terrain_ ? std::max(16.0, terrain_->box().size().x * 0.35)
                    : std::max(16.0, world_->box().size().x * 0.35));  // voxels per second
    Vec3d move{0, 0, 0};
    const Vec3d f = camera_.forward(), r = camera_.right();
    if (down(GLFW_KEY_W)) move = move + f;
    if (down(GLFW_KEY_S)) move = move - f;
    if (down(GLFW_KEY_D)) move = move + r;
    if (down(GLFW_KEY_A)) move = move - r;
    if (down(GLFW_KEY_SPACE)) move = move + Vec3d{0, 0, 1};
    if (down(GLFW_KEY_LEFT_SHIFT) || down(GLFW_KEY_RIGHT_SHIFT)) move = move - Vec3d{0, 0, 1};
    if (move.length() > 0) camera_.eye = camera_.eye + move.normalized() * (speed * dt_s);
  }
  double x = 0, y = 0;
  glfwGetCursorPos(w, &x, &y);
  const bool turning =
      look_mode_ ||
      (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS && !io.WantCaptureMouse);
  if (turning) camera_.turn(-(x - last_x_) * 0.004, -(y - last_y_) * 0.004);
  last_x_ = x;
  last_y_ = y;
  const std::vector<int> clicks = std::exchange(clicks_, {});
  if (!io.WantCaptureMouse && !vectors_) {  // the vectors mode has nothing to edit
    if (scroll_ != 0 && terrain_) {
      float& r = terrain_->brush_settings().radius;
      r = std::clamp(r + static_cast<float>(scroll_), 1.0f, 24.0f);
    } else if (scroll_ != 0) {
      brush_.radius = std::clamp(brush_.radius + static_cast<int>(std::lround(scroll_)), 0, 32);
    }
    const EditOp left_op = brush_.paint ? EditOp::kPaint : EditOp::kPlace;
    // Every click edits once; held buttons repeat the edit ten times a second.
    for (int button : clicks)
      if (button == GLFW_MOUSE_BUTTON_LEFT || button == GLFW_MOUSE_BUTTON_RIGHT)
        edit_at_cursor(button == GLFW_MOUSE_BUTTON_RIGHT ? EditOp::kCarve : left_op);
    const bool left = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    const bool right = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    if (!clicks.empty()) {
      last_edit_ = Clock::now();
    } else if ((left || right) && ms_between(last_edit_, Clock::now()) >= 100) {
      edit_at_cursor(right ? EditOp::kCarve : left_op);
      last_edit_ = Clock::now();
    }
  }
  scroll_ = 0;
}

}  // namespace voxfield::demo

// voxfield-demo — presenting CPU frames through OpenGL when there is no Vulkan device.
#include "gl_window.h"

#include <GL/gl.h>

namespace voxfield::demo {

GlWindow::GlWindow(int width, int height, const std::string& title) {
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) throw WindowError("GLFW cannot open an OpenGL window either");
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  renderer_ = name ? name : "unknown OpenGL renderer";
}

GlWindow::~GlWindow() {
  if (window_) glfwDestroyWindow(window_);
}

int GlWindow::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return std::max(w, 1);
}

int GlWindow::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return std::max(h, 1);
}

void GlWindow::draw_frame(const Image& frame, const std::function<void()>& overlay,
                          VulkanWindow::Screenshot* screenshot) {
  glViewport(0, 0, width(), height());
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  // Images are top row first; OpenGL draws pixel rows upwards from the raster position, so start
  // at the top-left corner and zoom by -1 vertically.
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glRasterPos2f(-1.0f, 1.0f);
  glPixelZoom(1.0f, -1.0f);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glDrawPixels(frame.width, frame.height, GL_RGB, GL_UNSIGNED_BYTE, frame.rgb.data());
  glPixelZoom(1.0f, 1.0f);
  overlay();
  if (screenshot) {
    const int w = width(), h = height();
    std::vector<std::uint8_t> rows(static_cast<std::size_t>(w) * h * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
    screenshot->width = w;
    screenshot->height = h;
    screenshot->rgb.resize(rows.size());
    const std::size_t stride = static_cast<std::size_t>(w) * 3;
    for (int y = 0; y < h; ++y)  // bottom row first -> top row first
      std::copy_n(rows.data() + static_cast<std::size_t>(h - 1 - y) * stride, stride,
                  screenshot->rgb.data() + y * stride);
  }
  glfwSwapBuffers(window_);
}

}  // namespace voxfield::demo

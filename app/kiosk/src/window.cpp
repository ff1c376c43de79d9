#include "kiosk/window.hpp"
#include "formats/app_error.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl2.h>
#include <spdlog/spdlog.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace hk::app {
namespace {

std::vector<InputEvent>& queue_of(GLFWwindow* w) {
  return *static_cast<std::vector<InputEvent>*>(glfwGetWindowUserPointer(w));
}

}  // namespace

KioskWindow::KioskWindow(bool windowed) {
  glfwSetErrorCallback([](int code, const char* what) { spdlog::error("glfw {}: {}", code, what ? what : ""); });
  if (!glfwInit()) throw AppError("display: GLFW could not start (no X display? run under xvfb-run for headless use)");
  GLFWmonitor* monitor = windowed ? nullptr : glfwGetPrimaryMonitor();
  int w = 1280, h = 720;
  if (monitor) {
    const GLFWvidmode* mode = glfwGetVideoMode(monitor);
    w = mode->width;
    h = mode->height;
    glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
  }
  win_ = glfwCreateWindow(w, h, "haptic-kiosk", monitor, nullptr);
  if (!win_) {
    glfwTerminate();
    throw AppError("display: cannot open a window");
  }
  glfwMakeContextCurrent(win_);
  glfwSwapInterval(1);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui_ImplGlfw_InitForOpenGL(win_, false);  // our callbacks queue; the kiosk hands ImGui what is its
  ImGui_ImplOpenGL2_Init();
  glfwSetWindowUserPointer(win_, &queue_);
  glfwSetKeyCallback(win_, [](GLFWwindow* w, int key, int scancode, int action, int mods) {
    queue_of(w).push_back({InputEvent::Kind::key, key, scancode, action, mods, 0, 0});
  });
  glfwSetCharCallback(win_, [](GLFWwindow* w, unsigned c) {
    queue_of(w).push_back({InputEvent::Kind::character, 0, 0, 0, 0, c, 0});
  });
  glfwSetMouseButtonCallback(win_, [](GLFWwindow* w, int button, int action, int mods) {
    queue_of(w).push_back({InputEvent::Kind::mouse_button, 0, 0, action, mods, 0, button});
  });
  glfwSetScrollCallback(win_, [](GLFWwindow* w, double dx, double dy) { ImGui_ImplGlfw_ScrollCallback(w, dx, dy); });
}

KioskWindow::~KioskWindow() {
  ImGui_ImplOpenGL2_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(win_);
  glfwTerminate();
}

bool KioskWindow::should_close() const { return glfwWindowShouldClose(win_) != 0; }
void KioskWindow::request_close() { glfwSetWindowShouldClose(win_, 1); }

std::vector<InputEvent> KioskWindow::poll() {
  glfwPollEvents();
  std::vector<InputEvent> out;
  out.swap(queue_);
  return out;
}

void KioskWindow::to_imgui(const InputEvent& e) {
  switch (e.kind) {
    case InputEvent::Kind::key:
      ImGui_ImplGlfw_KeyCallback(win_, e.key, e.scancode, e.action, e.mods);
      break;
    case InputEvent::Kind::character:
      ImGui_ImplGlfw_CharCallback(win_, e.codepoint);
      break;
    case InputEvent::Kind::mouse_button:
      ImGui_ImplGlfw_MouseButtonCallback(win_, e.button, e.action, e.mods);
      break;
  }
}

void KioskWindow::begin_frame(const std::optional<ScriptedMouse>& mouse) {
  ImGui_ImplOpenGL2_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  if (mouse) {  // the backend has just read the real pointer: a script's replaces it for this frame
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = ImVec2(mouse->x, mouse->y);
    io.MouseDown[0] = mouse->down;
  }
  ImGui::NewFrame();
}

void KioskWindow::end_frame() {
  ImGui::Render();
  ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
}

void KioskWindow::swap() { glfwSwapBuffers(win_); }

std::pair<int, int> KioskWindow::framebuffer_size() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(win_, &w, &h);
  return {w, h};
}

std::pair<int, int> KioskWindow::window_size() const {
  int w = 0, h = 0;
  glfwGetWindowSize(win_, &w, &h);
  return {w, h};
}

std::pair<double, double> KioskWindow::cursor() const {
  double x = 0, y = 0;
  glfwGetCursorPos(win_, &x, &y);
  return {x, y};
}

cv::Mat KioskWindow::read_pixels() const {
  const auto [fw, fh] = framebuffer_size();
  glFinish();
  cv::Mat img(fh, fw, CV_8UC3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, img.data);
  cv::Mat out;
  cv::flip(img, out, 0);
  cv::cvtColor(out, out, cv::COLOR_RGB2BGR);
  return out;
}

}  // namespace hk::app

#include "viewer/viewer_window.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>

#include <GLFW/glfw3.h>

#include "core/input_error.h"
#include "image/image.h"

namespace narval {
namespace {

std::string& glfwLastError() {
  static std::string e;
  return e;
}

void onGlfwError(int, const char* description) { glfwLastError() = description ? description : "unknown error"; }

bool hasDisplayVariable() {
  for (const char* name : {"DISPLAY", "WAYLAND_DISPLAY"}) {
    const char* v = std::getenv(name);
    if (v && *v) return true;
  }
  return false;
}

}  // namespace

ViewerWindow::ViewerWindow(int width, int height, const std::string& title, bool headless) {
  if (!hasDisplayVariable()) {
    if (!headless)
      throw InputError("view: no display to open a window on (DISPLAY is not set); run it in a desktop session, "
                       "or headless with --script or --frames (narval then starts Xvfb itself)");
    xvfb_ = std::make_unique<PrivateXvfb>(width, height);
  }
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) throw InputError("view: cannot open a window: " + glfwLastError());
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    const std::string why = glfwLastError();
    glfwTerminate();
    throw InputError("view: cannot open a window: " + why);
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(0);  // the renderer sets the pace, not the display's refresh
  glfwSetWindowUserPointer(window_, this);
  glfwSetCharCallback(window_, onChar);
  glfwSetCursorPosCallback(window_, onCursor);
  glfwSetScrollCallback(window_, onScroll);
  glGenTextures(1, &texture_);
}

ViewerWindow::~ViewerWindow() {
  if (texture_) glDeleteTextures(1, &texture_);
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

void ViewerWindow::onChar(GLFWwindow* w, unsigned int codepoint) {
  auto* self = static_cast<ViewerWindow*>(glfwGetWindowUserPointer(w));
  if (codepoint >= 128 || !isViewerKey(char(codepoint))) return;
  ViewerInput in;
  in.kind = ViewerInput::Kind::Key;
  in.key = char(std::toupper(int(codepoint)));
  self->pending_.push_back(in);
}

void ViewerWindow::onCursor(GLFWwindow* w, double x, double y) {
  auto* self = static_cast<ViewerWindow*>(glfwGetWindowUserPointer(w));
  const bool left = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  const bool pan = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                   glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
  if (self->cursorKnown_ && (left || pan)) {
    ViewerInput in;
    in.kind = left ? ViewerInput::Kind::Orbit : ViewerInput::Kind::Pan;
    in.dx = float(x - self->cursorX_);
    in.dy = float(y - self->cursorY_);
    self->pending_.push_back(in);
  }
  self->cursorX_ = x;
  self->cursorY_ = y;
  self->cursorKnown_ = true;
}

void ViewerWindow::onScroll(GLFWwindow* w, double, double dy) {
  auto* self = static_cast<ViewerWindow*>(glfwGetWindowUserPointer(w));
  ViewerInput in;
  in.kind = ViewerInput::Kind::Zoom;
  in.dy = float(dy);
  self->pending_.push_back(in);
}

void ViewerWindow::show(ViewerSession& session) {
  const ImageRGB8& img = session.display();
  int fbW = 0, fbH = 0;
  glfwGetFramebufferSize(window_, &fbW, &fbH);
  glViewport(0, 0, fbW, fbH);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glEnable(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, img.width, img.height, 0, GL_RGB, GL_UNSIGNED_BYTE, img.rgb.data());
  // Pixel for pixel when the window has the image's size (the screenshot is then the frame's PNG
  // bit for bit); otherwise scaled to fit, keeping the aspect ratio.
  const bool exact = fbW == img.width && fbH == img.height;
  const GLint filter = exact ? GL_NEAREST : GL_LINEAR;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP);
  const float scale = std::min(float(fbW) / float(img.width), float(fbH) / float(img.height));
  const float sx = exact ? 1.0f : scale * img.width / float(fbW), sy = exact ? 1.0f : scale * img.height / float(fbH);
  glColor3f(1, 1, 1);
  glBegin(GL_QUADS);  // row 0 of the image at the top of the window
  glTexCoord2f(0, 1); glVertex2f(-sx, -sy);
  glTexCoord2f(1, 1); glVertex2f(sx, -sy);
  glTexCoord2f(1, 0); glVertex2f(sx, sy);
  glTexCoord2f(0, 0); glVertex2f(-sx, sy);
  glEnd();
  glDisable(GL_TEXTURE_2D);
  glfwSetWindowTitle(window_, session.title().c_str());
}

void ViewerWindow::saveScreenshot(const std::string& path) {
  int fbW = 0, fbH = 0;
  glfwGetFramebufferSize(window_, &fbW, &fbH);
  ImageRGB8 shot;
  shot.width = fbW;
  shot.height = fbH;
  shot.rgb.resize(size_t(fbW) * fbH * 3);
  std::vector<uint8_t> rows(shot.rgb.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, fbW, fbH, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  for (int y = 0; y < fbH; ++y)  // OpenGL's rows go bottom up
    std::copy_n(&rows[size_t(fbH - 1 - y) * fbW * 3], size_t(fbW) * 3, &shot.rgb[size_t(y) * fbW * 3]);
  writePng8(path, shot);
}

void ViewerWindow::run(ViewerSession& session, const Run& run) {
  using clock = std::chrono::steady_clock;
  size_t next = 0;         // the script's next input
  int framesOwed = 0;      // frames the script's current `frames N` still asks for
  auto last = clock::now();
  while (!glfwWindowShouldClose(window_)) {
    if (run.frames > 0 && session.frames() >= run.frames) break;
    if (run.scripted) {
      glfwPollEvents();  // keeps the window alive; the user's inputs are ignored
      pending_.clear();
      while (framesOwed == 0 && next < run.script.size()) {
        const ViewerInput& in = run.script[next++];
        if (in.kind == ViewerInput::Kind::Frames)
          framesOwed = in.frames;
        else
          session.apply(in);
      }
      if (framesOwed > 0) --framesOwed;  // past the script's end: still frames up to run.frames
    } else {
      if (session.idle())
        glfwWaitEventsTimeout(0.1);
      else
        glfwPollEvents();
      if (glfwGetKey(window_, GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
      const auto now = clock::now();
      const float dt = std::min(0.25f, std::chrono::duration<float>(now - last).count());
      last = now;
      // Flying keys held down move the camera for the time since the last frame.
      std::string held;
      for (const auto& [key, letter] : {std::pair{GLFW_KEY_W, 'W'}, {GLFW_KEY_A, 'A'}, {GLFW_KEY_S, 'S'},
                                        {GLFW_KEY_D, 'D'}, {GLFW_KEY_Q, 'Q'}, {GLFW_KEY_E, 'E'}})
        if (glfwGetKey(window_, key) == GLFW_PRESS) held += letter;
      ViewerInput fly;
      if (!held.empty() && flyAxes(held, &fly.axes)) {
        fly.kind = ViewerInput::Kind::Fly;
        fly.seconds = dt;
        pending_.push_back(fly);
      }
      for (const ViewerInput& in : pending_) session.apply(in);
      pending_.clear();
      if (session.idle()) continue;
    }
    session.renderFrame();
    for (const std::string& m : session.takeMessages()) std::cout << "narval view: " << m << "\n" << std::flush;
    const auto tShow = clock::now();
    show(session);
    if (run.frames > 0 && session.frames() >= run.frames && !run.screenshot.empty()) saveScreenshot(run.screenshot);
    glfwSwapBuffers(window_);
    glFinish();
    presentMs_.push_back(std::chrono::duration<double, std::milli>(clock::now() - tShow).count());
  }
}

}  // namespace narval

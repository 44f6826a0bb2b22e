// viewer_window.h: the viewer's GLFW window: shows the session's frames (through the host: an RGB8
// texture drawn as one quad, letterboxed when the window's shape differs), turns mouse and keys into
// ViewerInputs, and replays a script instead of a user for headless runs (under Xvfb in CI).
// OpenGL 1.1 calls only, so Mesa's software renderer serves as well as a GPU.
#pragma once

#include <string>
#include <vector>

#include <memory>

#include "viewer/private_xvfb.h"
#include "viewer/viewer_input.h"
#include "viewer/viewer_session.h"

struct GLFWwindow;

namespace narval {

class ViewerWindow {
 public:
  // Opens a window of width x height pixels. Without a display (DISPLAY and WAYLAND_DISPLAY unset), a
  // `headless` run (scripted, or a number of frames) starts an Xvfb of its own (PrivateXvfb);
  // otherwise, or without Xvfb, it throws InputError (one line, exit 2), as for GLFW's failures.
  ViewerWindow(int width, int height, const std::string& title, bool headless);
  ~ViewerWindow();
  ViewerWindow(const ViewerWindow&) = delete;
  ViewerWindow& operator=(const ViewerWindow&) = delete;

  struct Run {
    std::vector<ViewerInput> script;  // replayed instead of the user's inputs when `scripted`
    bool scripted = false;
    int frames = 0;                   // stop after this many frames (0: when the window closes; a script needs > 0)
    std::string screenshot;           // the window's last frame as PNG, when not empty
  };
  // Runs the session until the window closes, Escape, or the run's frames; prints the session's
  // messages as they come.
  void run(ViewerSession& session, const Run& run);
  // Milliseconds of each frame's presentation: texture upload, draw and buffer swap (the host's
  // share of showing a frame, which buffer sharing with OpenGL would save).
  const std::vector<double>& presentMs() const { return presentMs_; }

 private:
  void show(ViewerSession& session);  // uploads and draws the last frame, sets the title
  void saveScreenshot(const std::string& path);
  static void onChar(GLFWwindow* w, unsigned int codepoint);
  static void onCursor(GLFWwindow* w, double x, double y);
  static void onScroll(GLFWwindow* w, double dx, double dy);

  std::unique_ptr<PrivateXvfb> xvfb_;  // first declared, so it outlives the window
  GLFWwindow* window_ = nullptr;
  unsigned int texture_ = 0;
  std::vector<ViewerInput> pending_;  // the user's inputs since the last frame
  double cursorX_ = 0, cursorY_ = 0;
  bool cursorKnown_ = false;
  std::vector<double> presentMs_;
};

}  // namespace narval

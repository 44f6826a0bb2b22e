// display_server.h: streams a render in progress to a running tev (tev_ipc.h), as pbrt-v4's
// --display-server does. The renderer posts its image after a pass; a background thread sends
// the tiles that changed since the last send, at most every kUpdateInterval, so the render never
// waits on the network. A viewer that is not there or goes away costs a warning, never the render.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "image/image.h"

namespace narval {

// HOST:PORT (HOST a name or an IPv4/IPv6 address, [v6]:PORT too; PORT 1–65535). Throws
// InputError naming `flag` when it is not that.
struct HostPort {
  std::string host;
  int port = 0;
};
HostPort parseHostPort(const std::string& text, const std::string& flag);

class DisplayServer {
 public:
  static constexpr std::chrono::milliseconds kUpdateInterval{250};
  static constexpr int kTile = 64;  // tile edge in pixels: a changed region costs its tiles only

  // Connects (2 s at most) and creates image `name` of width x height, channels R, G, B. A failed
  // connection is a warning (warnings()) and every later call does nothing.
  DisplayServer(const HostPort& where, std::string name, int width, int height);
  ~DisplayServer();
  DisplayServer(const DisplayServer&) = delete;
  DisplayServer& operator=(const DisplayServer&) = delete;

  // The image so far (width x height); the thread sends what changed at its next tick.
  void post(const ImageRGB& image);
  // Sends `image` (the final state) now, stops the thread and closes the connection.
  void finish(const ImageRGB& image);
  // Connected and not lost: whether a post() can reach the viewer (else snapshots are wasted).
  bool receiving() const;
  // What went wrong (connection refused, viewer gone), one line each, for the command to print.
  std::vector<std::string> warnings() const;

 private:
  void run();
  bool sendChangedTiles(const ImageRGB& image);  // false once the connection is lost
  bool sendAll(const std::vector<char>& packet);
  bool peerClosed();
  void lose(const std::string& why);

  std::string where_, name_;
  int width_, height_;
  int fd_ = -1;  // the sending thread's (finish(): after it stopped)
  std::vector<float> sent_;  // what the viewer holds (NaN before the first send: every tile differs)
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  ImageRGB pending_;
  bool alive_ = false;  // connected and not lost: post() keeps images
  bool hasPending_ = false, stop_ = false;
  std::vector<std::string> warnings_;
  std::thread thread_;
};

}  // namespace narval

#include "display/display_server.h"

#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/input_error.h"
#include "display/tev_ipc.h"

namespace narval {
namespace {

const std::vector<std::string> kChannels = {"R", "G", "B"};
constexpr int kConnectTimeoutMs = 2000;

// Non-blocking connect with a timeout to each address getaddrinfo gives; the socket or -1 and why.
int connectTo(const HostPort& hp, std::string* why) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* list = nullptr;
  if (const int rc = getaddrinfo(hp.host.c_str(), std::to_string(hp.port).c_str(), &hints, &list); rc != 0) {
    *why = gai_strerror(rc);
    return -1;
  }
  int fd = -1;
  for (addrinfo* a = list; a && fd < 0; a = a->ai_next) {
    fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int flags = fcntl(fd, F_GETFL, 0);
    fcntl(fd, F_SETFL, flags | O_NONBLOCK);
    int err = 0;
    if (connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
      err = errno;
      if (err == EINPROGRESS) {
        pollfd p{fd, POLLOUT, 0};
        const int n = poll(&p, 1, kConnectTimeoutMs);
        socklen_t len = sizeof(err);
        if (n == 1) getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
        else err = ETIMEDOUT;
      }
    }
    if (err != 0) {
      *why = std::strerror(err);
      close(fd);
      fd = -1;
      continue;
    }
    fcntl(fd, F_SETFL, flags);  // blocking again: sends go out whole
  }
  freeaddrinfo(list);
  return fd;
}

}  // namespace

HostPort parseHostPort(const std::string& text, const std::string& flag) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size())
    throw inputError(flag, "", "expected HOST:PORT (e.g. localhost:14158), got '" + text + "'");
  HostPort hp;
  hp.host = text.substr(0, colon);
  if (hp.host.size() > 2 && hp.host.front() == '[' && hp.host.back() == ']') hp.host = hp.host.substr(1, hp.host.size() - 2);
  const std::string port = text.substr(colon + 1);
  if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) < 1 ||
      std::stoi(port) > 65535)
    throw inputError(flag, "", "the port must be a number from 1 to 65535, got '" + port + "'");
  hp.port = std::stoi(port);
  return hp;
}

DisplayServer::DisplayServer(const HostPort& where, std::string name, int width, int height)
    : where_(where.host + ":" + std::to_string(where.port)),
      name_(std::move(name)),
      width_(width),
      height_(height),
      sent_(size_t(width) * height * 3, std::numeric_limits<float>::quiet_NaN()) {
  std::string why;
  fd_ = connectTo(where, &why);
  if (fd_ < 0) {
    warnings_.push_back("--display-server " + where_ + ": cannot connect (" + why + "); the render goes on without it");
    return;
  }
  if (!sendAll(tevCreateImage(name_, width_, height_, kChannels))) return;
  alive_ = true;
  thread_ = std::thread([this] { run(); });
}

DisplayServer::~DisplayServer() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) close(fd_);
}

void DisplayServer::post(const ImageRGB& image) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!alive_) return;
  pending_ = image;
  hasPending_ = true;
}

void DisplayServer::finish(const ImageRGB& image) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (fd_ < 0) return;
  if (sendChangedTiles(image)) {
    shutdown(fd_, SHUT_WR);
    close(fd_);
    fd_ = -1;
  }
}

bool DisplayServer::receiving() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return alive_;
}

std::vector<std::string> DisplayServer::warnings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return warnings_;
}

void DisplayServer::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    wake_.wait_for(lock, kUpdateInterval, [this] { return stop_; });
    if (stop_ || !hasPending_) continue;
    const ImageRGB image = std::move(pending_);
    hasPending_ = false;
    lock.unlock();
    const bool ok = sendChangedTiles(image);
    lock.lock();
    if (!ok) return;
  }
}

bool DisplayServer::sendChangedTiles(const ImageRGB& image) {
  if (fd_ < 0) return false;
  if (image.width != width_ || image.height != height_) return true;  // not this image
  // tev never writes to us: readable means it closed (0) or reset the connection.
  if (peerClosed()) {
    lose("the viewer closed the connection");
    return false;
  }
  std::vector<float> tile;
  for (int ty = 0; ty < height_; ty += kTile)
    for (int tx = 0; tx < width_; tx += kTile) {
      const int w = std::min(kTile, width_ - tx), h = std::min(kTile, height_ - ty);
      bool changed = false;
      tile.clear();
      for (int y = ty; y < ty + h; ++y) {
        const float* row = image.pixel(tx, y);
        float* old = &sent_[(size_t(y) * width_ + tx) * 3];
        // Bitwise, so that NaN pixels (and the NaN "never sent") compare as written.
        changed |= std::memcmp(row, old, size_t(w) * 3 * sizeof(float)) != 0;
        tile.insert(tile.end(), row, row + size_t(w) * 3);
      }
      if (!changed) continue;
      if (!sendAll(tevUpdateImage(name_, kChannels, tx, ty, w, h, tile))) return false;
      for (int y = ty; y < ty + h; ++y)
        std::memcpy(&sent_[(size_t(y) * width_ + tx) * 3], image.pixel(tx, y), size_t(w) * 3 * sizeof(float));
    }
  return true;
}

bool DisplayServer::sendAll(const std::vector<char>& packet) {
  size_t at = 0;
  while (at < packet.size()) {
    const ssize_t n = send(fd_, packet.data() + at, packet.size() - at, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      lose(std::strerror(errno));
      return false;
    }
    at += size_t(n);
  }
  return true;
}

bool DisplayServer::peerClosed() {
  char byte;
  const ssize_t n = recv(fd_, &byte, 1, MSG_DONTWAIT | MSG_PEEK);
  return n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR);
}

void DisplayServer::lose(const std::string& why) {
  close(fd_);
  fd_ = -1;
  std::lock_guard<std::mutex> lock(mutex_);
  alive_ = false;
  warnings_.push_back("--display-server " + where_ + ": " + why + "; the render goes on without it");
}

}  // namespace narval

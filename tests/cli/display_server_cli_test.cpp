// Live preview: `narval render --display-server HOST:PORT` streams the render to tev, and
// --write-partial-images writes the EXR so far. The receiver here decodes tev's protocol from its
// published description (github.com/Tom94/tev, its IPC packets; pbrt-v4 speaks the same), not
// from narval's encoder: each packet is a uint32 total length (those four bytes included), a type
// byte, then the fields, little-endian, strings NUL-terminated, bools one byte. CreateImage (4):
// grabFocus, name, width, height, channel count, channel names. UpdateImageV3 (6): grabFocus,
// name, channel count, channel names, x, y, width, height, int64 offsets, int64 strides, floats.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "cli_fixture.h"
#include "fog_scene.h"
#include "image/image.h"

namespace narval::test {
namespace {

namespace fs = std::filesystem;

// One decoded packet.
struct Packet {
  int type = -1;
  bool grabFocus = false;
  std::string name;
  std::vector<std::string> channels;
  int x = 0, y = 0, width = 0, height = 0;
  std::vector<int64_t> offsets, strides;
  std::vector<float> data;
};

class Reader {
 public:
  explicit Reader(const std::vector<char>& b) : b_(b) {}
  template <typename T>
  T get() {
    if (at_ + sizeof(T) > b_.size()) throw std::runtime_error("packet too short");
    T v;
    std::memcpy(&v, &b_[at_], sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::string str() {
    std::string s;
    while (true) {
      const char c = get<char>();
      if (c == '\0') return s;
      s += c;
    }
  }
  size_t left() const { return b_.size() - at_; }

 private:
  const std::vector<char>& b_;
  size_t at_ = 0;
};

Packet decode(const std::vector<char>& bytes) {  // bytes: the packet after its length field
  Reader r(bytes);
  Packet p;
  p.type = r.get<uint8_t>();
  if (p.type == 4) {
    p.grabFocus = r.get<uint8_t>() != 0;
    p.name = r.str();
    p.width = r.get<int32_t>();
    p.height = r.get<int32_t>();
    const int n = r.get<int32_t>();
    for (int c = 0; c < n; ++c) p.channels.push_back(r.str());
  } else if (p.type == 6) {
    p.grabFocus = r.get<uint8_t>() != 0;
    p.name = r.str();
    const int n = r.get<int32_t>();
    for (int c = 0; c < n; ++c) p.channels.push_back(r.str());
    p.x = r.get<int32_t>();
    p.y = r.get<int32_t>();
    p.width = r.get<int32_t>();
    p.height = r.get<int32_t>();
    for (int c = 0; c < n; ++c) p.offsets.push_back(r.get<int64_t>());
    for (int c = 0; c < n; ++c) p.strides.push_back(r.get<int64_t>());
    if (r.left() % 4 != 0) throw std::runtime_error("float data not a whole number of floats");
    while (r.left() > 0) p.data.push_back(r.get<float>());
  }
  if (r.left() != 0) throw std::runtime_error("bytes left over in a packet of type " + std::to_string(p.type));
  return p;
}

// A tev stand-in on 127.0.0.1 (a free port): accepts one connection and records its packets until
// the sender closes, or closes itself after the first packet when `hangUpAfterCreate`.
class Receiver {
 public:
  explicit Receiver(bool hangUpAfterCreate) {
    listen_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    if (bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 || ::listen(listen_, 1) != 0)
      throw std::runtime_error("cannot listen");
    socklen_t len = sizeof(a);
    getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
    thread_ = std::thread([this, hangUpAfterCreate] {
      const int fd = accept(listen_, nullptr, nullptr);
      if (fd < 0) return;
      while (true) {
        uint32_t length = 0;
        if (!readAll(fd, &length, 4)) break;
        std::vector<char> bytes(length - 4);
        if (length < 5 || !readAll(fd, bytes.data(), bytes.size())) {
          error = "a packet cut short";
          break;
        }
        try {
          packets.push_back(decode(bytes));
        } catch (const std::exception& e) {
          error = e.what();
          break;
        }
        if (hangUpAfterCreate) break;
      }
      close(fd);
    });
  }
  ~Receiver() {
    shutdown(listen_, SHUT_RDWR);
    if (thread_.joinable()) thread_.join();
    close(listen_);
  }
  void join() { thread_.join(); }

  int port = 0;
  std::vector<Packet> packets;
  std::string error;

 private:
  static bool readAll(int fd, void* to, size_t n) {
    char* p = static_cast<char*>(to);
    while (n > 0) {
      const ssize_t k = recv(fd, p, n, 0);
      if (k <= 0) return false;
      p += k;
      n -= size_t(k);
    }
    return true;
  }
  int listen_ = -1;
  std::thread thread_;
};

class DisplayServerCli : public CliFixture {
 protected:
  // 100x70: four tiles of 64, three of them partial.
  void SetUp() override { write("fog.json", fogSceneJson(100, 70, 300)); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
};

// The stream: CreateImage first (the output's name, the render's size, R G B), then only
// UpdateImageV3 tiles of that image, inside it, interleaved RGB, sent while the render runs and at
// its end; applied in order they leave exactly the EXR the render wrote, bit for bit.
TEST_F(DisplayServerCli, StreamEndsWithTheImageTheRenderWrote) {
  Receiver tev(false);
  const RunResult r = run("render fog.json -o out.exr --spp 1500 --samples-per-pass 1 --display-server 127.0.0.1:" +
                          std::to_string(tev.port));
  tev.join();
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  ASSERT_EQ(tev.error, "");
  ASSERT_GE(tev.packets.size(), 5u);
  const Packet& create = tev.packets[0];
  EXPECT_EQ(create.type, 4);
  EXPECT_EQ(create.name, "out.exr");
  EXPECT_EQ(create.width, 100);
  EXPECT_EQ(create.height, 70);
  EXPECT_EQ(create.channels, (std::vector<std::string>{"R", "G", "B"}));

  std::vector<float> state(100 * 70 * 3, std::nanf(""));
  int rounds = 0;
  for (size_t i = 1; i < tev.packets.size(); ++i) {
    const Packet& p = tev.packets[i];
    ASSERT_EQ(p.type, 6) << "packet " << i;
    EXPECT_EQ(p.name, "out.exr");
    ASSERT_EQ(p.channels, (std::vector<std::string>{"R", "G", "B"}));
    ASSERT_EQ(p.offsets, (std::vector<int64_t>{0, 1, 2}));
    ASSERT_EQ(p.strides, (std::vector<int64_t>{3, 3, 3}));
    ASSERT_TRUE(p.x >= 0 && p.y >= 0 && p.width > 0 && p.height > 0 && p.x + p.width <= 100 && p.y + p.height <= 70)
        << p.x << "," << p.y << " " << p.width << "x" << p.height;
    ASSERT_EQ(p.data.size(), size_t(p.width) * p.height * 3);
    rounds += p.x == 0 && p.y == 0;
    for (int y = 0; y < p.height; ++y)
      for (int x = 0; x < p.width; ++x)
        for (int c = 0; c < 3; ++c)
          state[(size_t(p.y + y) * 100 + p.x + x) * 3 + c] =
              p.data[size_t(p.offsets[c] + (int64_t(y) * p.width + x) * p.strides[c])];
  }
  std::printf("[ display ] %zu packets, %d sends of the first tile\n", tev.packets.size(), rounds);
  // 1500 passes take seconds here (1.5–3 s on 2 cores): the 250 ms ticks send during the render,
  // and the end sends the rest.
  EXPECT_GE(rounds, 2);
  const ImageRGB exr = readExr(file("out.exr"));
  ASSERT_EQ(exr.rgb.size(), state.size());
  EXPECT_EQ(std::memcmp(exr.rgb.data(), state.data(), state.size() * sizeof(float)), 0);
}

// The viewer goes away after creating the image: the render still ends with every sample, exit 0,
// and one warning line.
TEST_F(DisplayServerCli, ViewerThatHangsUpCostsAWarningNotTheRender) {
  Receiver tev(true);
  const std::string at = "127.0.0.1:" + std::to_string(tev.port);
  const RunResult r = run("render fog.json -o out.exr --samples-per-pass 1 --display-server " + at);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readExrAttributes(file("out.exr")).at("narval:spp"), "300");
  const std::string prefix = "narval: warning: --display-server " + at + ": ";
  const std::string suffix = "; the render goes on without it\n";
  EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
  ASSERT_GE(r.err.size(), suffix.size());
  EXPECT_EQ(r.err.substr(r.err.size() - suffix.size()), suffix) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  std::printf("[ display ] %s", r.err.c_str());
}

// Nobody listening: the same render, and the warning says so.
TEST_F(DisplayServerCli, NoViewerIsAWarning) {
  int port = 0;
  {
    Receiver closed(true);  // a port that was free a moment ago, closed again
    port = closed.port;
    const int fd = socket(AF_INET, SOCK_STREAM, 0);  // let its accept return
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(uint16_t(port));
    connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    close(fd);
  }
  const std::string at = "127.0.0.1:" + std::to_string(port);
  const RunResult r = run("render fog.json -o out.exr --spp 4 --display-server " + at);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "narval: warning: --display-server " + at +
                       ": cannot connect (Connection refused); the render goes on without it\n");
  EXPECT_EQ(readExrAttributes(file("out.exr")).at("narval:spp"), "4");
}

TEST_F(DisplayServerCli, BadFlagsFailBeforeRendering) {
  RunResult r = run("render fog.json -o out.exr --display-server nonsense");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --display-server: expected HOST:PORT (e.g. localhost:14158), got 'nonsense'\n");
  r = run("render fog.json -o out.exr --display-server localhost:99999");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --display-server: the port must be a number from 1 to 65535, got '99999'\n");
  r = run("render fog.json -o out.exr --algorithm raymarch --write-partial-images 1");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "narval: --write-partial-images: only path-traced renders write partial images; the algorithm is "
            "raymarch\n");
  EXPECT_EQ(outputs({"fog.json"}), std::vector<std::string>{});
}

// --write-partial-images: while the render runs, the output holds a complete EXR of the samples so
// far (written atomically); it is resumable, and resuming it gives the full render bit for bit.
TEST_F(DisplayServerCli, PartialImagesAreCompleteAndResumable) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir_.c_str()) != 0) _exit(127);
    const int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, STDOUT_FILENO);
    dup2(devnull, STDERR_FILENO);
    execl(NARVAL_BINARY, NARVAL_BINARY, "render", "fog.json", "-o", "out.exr", "--spp", "1000", "--samples-per-pass",
          "1", "--write-partial-images", "0.05", static_cast<char*>(nullptr));
    _exit(127);
  }
  // Copy the first partial image that appears (the process still running).
  bool copied = false;
  int status = 0;
  while (!copied) {
    if (fs::exists(dir_ / "out.exr")) {
      fs::copy_file(dir_ / "out.exr", dir_ / "partial.exr");
      copied = true;
    } else if (waitpid(pid, &status, WNOHANG) == pid) {
      break;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  if (copied) waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_TRUE(copied) << "no partial image while the render ran";
  const int k = std::stoi(readExrAttributes(file("partial.exr")).at("narval:spp"));
  EXPECT_GT(k, 0);
  EXPECT_LT(k, 1000);
  const RunResult r = run("render fog.json -o partial.exr --spp 1000 --resume");
  ASSERT_EQ(r.code, 0) << r.err;
  const ImageRGB full = readExr(file("out.exr")), resumed = readExr(file("partial.exr"));
  ASSERT_EQ(full.rgb.size(), resumed.rgb.size());
  EXPECT_EQ(std::memcmp(full.rgb.data(), resumed.rgb.data(), full.rgb.size() * sizeof(float)), 0);
}

}  // namespace
}  // namespace narval::test

#include "display/tev_ipc.h"

#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace narval {
namespace {

// Appends fields in tev's wire format; the first four bytes hold the packet's total length.
class PacketWriter {
 public:
  explicit PacketWriter(TevPacketType type) : bytes_(4, 0) { put(uint8_t(type)); }
  template <typename T>
  void put(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(&bytes_[at], &v, sizeof(T));  // little-endian hosts only (x86-64, AArch64)
  }
  void put(bool v) { put(uint8_t(v ? 1 : 0)); }
  void put(const std::string& s) {
    if (s.find('\0') != std::string::npos) throw std::invalid_argument("tev packet: a name with a NUL byte");
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back('\0');
  }
  std::vector<char> finish() {
    const uint32_t n = uint32_t(bytes_.size());
    std::memcpy(bytes_.data(), &n, 4);
    return std::move(bytes_);
  }

 private:
  std::vector<char> bytes_;
};

}  // namespace

std::vector<char> tevCreateImage(const std::string& name, int width, int height,
                                 const std::vector<std::string>& channels) {
  PacketWriter w(TevPacketType::CreateImage);
  w.put(false);  // grabFocus
  w.put(name);
  w.put(int32_t(width));
  w.put(int32_t(height));
  w.put(int32_t(channels.size()));
  for (const std::string& c : channels) w.put(c);
  return w.finish();
}

std::vector<char> tevUpdateImage(const std::string& name, const std::vector<std::string>& channels, int x, int y,
                                 int width, int height, const std::vector<float>& interleaved) {
  const size_t n = channels.size();
  if (n == 0 || interleaved.size() != size_t(width) * size_t(height) * n)
    throw std::invalid_argument("tev packet: " + std::to_string(interleaved.size()) + " floats for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " tile of " +
                                std::to_string(n) + " channels");
  PacketWriter w(TevPacketType::UpdateImageV3);
  w.put(false);  // grabFocus
  w.put(name);
  w.put(int32_t(n));
  for (const std::string& c : channels) w.put(c);
  w.put(int32_t(x));
  w.put(int32_t(y));
  w.put(int32_t(width));
  w.put(int32_t(height));
  for (size_t c = 0; c < n; ++c) w.put(int64_t(c));
  for (size_t c = 0; c < n; ++c) w.put(int64_t(n));
  for (float v : interleaved) w.put(v);
  return w.finish();
}

std::vector<char> tevCloseImage(const std::string& name) {
  PacketWriter w(TevPacketType::CloseImage);
  w.put(name);
  return w.finish();
}

}  // namespace narval

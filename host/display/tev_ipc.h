// tev_ipc.h: the packets of tev's TCP protocol (https://github.com/Tom94/tev, "IPC"), the display
// server pbrt-v4's --display-server streams to. Every packet: uint32 total length (these four
// bytes included), one type byte, then the fields, little-endian; strings end with a NUL, bools
// are one byte.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace narval {

enum class TevPacketType : uint8_t {
  CloseImage = 2,
  CreateImage = 4,
  UpdateImageV3 = 6,  // channels with their own offset and stride into the float data
};

// CreateImage: grabFocus, name, width, height, channel count, channel names.
std::vector<char> tevCreateImage(const std::string& name, int width, int height,
                                 const std::vector<std::string>& channels);

// UpdateImageV3 of the tile (x, y, width, height): grabFocus, name, channel count, channel names,
// x, y, width, height, int64 offset per channel, int64 stride per channel, then the floats;
// channel c of the tile's pixel p is data[offset_c + p·stride_c], pixels row by row. Here the
// channels are interleaved: offset c, stride channels.size().
std::vector<char> tevUpdateImage(const std::string& name, const std::vector<std::string>& channels, int x, int y,
                                 int width, int height, const std::vector<float>& interleaved);

// CloseImage: name.
std::vector<char> tevCloseImage(const std::string& name);

}  // namespace narval

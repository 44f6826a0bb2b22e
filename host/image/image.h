// image.h: linear RGB float images, EXR and PNG output, display transform.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "image/display_transform.h"

namespace narval {

struct ImageRGB {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width*height*3, row 0 at the top
  float* pixel(int x, int y) { return &rgb[(size_t(y) * width + x) * 3]; }
  const float* pixel(int x, int y) const { return &rgb[(size_t(y) * width + x) * 3]; }
};

// A named channel of width*height values, row 0 at the top, as 32-bit float or as 32-bit unsigned
// int (OpenEXR's UINT: the path tracer's exact accumulator words, e.g. "accum.R.w0").
struct ExrChannel {
  std::string name;
  std::vector<float> values;
};
struct ExrUintChannel {
  std::string name;
  std::vector<uint32_t> values;
};

// A header attribute, stored with its value's OpenEXR type (tools read them typed: pbrt-v4's samplesPerPixel).
struct ExrAttribute {
  using Value = std::variant<std::string, int, float, double, std::vector<std::string>>;
  std::string name;
  Value value;
};

// 32-bit float linear RGB EXR with `attributes` in the header and `extra` UINT channels beside R, G and B
// (viewers show them as layers). Written to a temporary file beside `path`, then renamed: a failure never
// leaves a broken file or touches an existing `path`; it throws std::runtime_error "PATH: cannot write: REASON".
void writeExr(const std::string& path, const ImageRGB& image, const std::vector<ExrAttribute>& attributes = {},
              const std::vector<ExrUintChannel>& extra = {});
// R, G and B as 32-bit float (half or uint channels converted), the data window's size (any window). A
// missing, unreadable or corrupt file, or a missing R, G or B channel, throws InputError "PATH: what".
ImageRGB readExr(const std::string& path);
// The header attributes writeExr can write, by name, as text: strings as they are, ints in decimal, floats
// and doubles in the fewest digits that read back, string vectors one element per line; throws as readExr.
std::map<std::string, std::string> readExrAttributes(const std::string& path);
// The named channels as 32-bit float, width*height values each in the data window's size; a
// missing channel throws InputError "PATH: no NAME channel (channels: ...)", like readExr.
std::vector<ExrChannel> readExrChannels(const std::string& path, const std::vector<std::string>& names);
// The data window's size, the attributes (as readExrAttributes) and the channels' names, from the header alone.
struct ExrHeader {
  int width = 0, height = 0;
  std::map<std::string, std::string> attributes;
  std::vector<std::string> channels;
};
ExrHeader readExrHeader(const std::string& path);
// R, G and B (as readExr), the named UINT channels (as readExrUintChannels) and the attributes (as
// readExrAttributes) from one opening and one pixel read: what `narval merge` reads of each part.
struct ExrContents {
  ImageRGB image;
  std::vector<ExrUintChannel> uints;
  std::map<std::string, std::string> attributes;
};
ExrContents readExrWithUintChannels(const std::string& path, const std::vector<std::string>& uintNames);
// The named channels as stored, bit for bit: each must be a UINT channel, else InputError "PATH: NAME:
// not a UINT channel"; a missing one throws like readExrChannels.
std::vector<ExrUintChannel> readExrUintChannels(const std::string& path, const std::vector<std::string>& names);

// 8-bit RGB pictures (display images, figures); row 0 at the top.
struct ImageRGB8 {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

// Atomic RGB8 PNG write of an 8-bit picture.
void writePng8(const std::string& path, const ImageRGB8& image);

// Display transform (display_transform.h): 2^exposure, tone map, clamp to [0, 1], sRGB transfer, round to 8
// bit (NaN: 0, +inf: 255), into an sRGB-chunk RGB8 PNG written atomically; failing: std::runtime_error naming `path`.
void writePng(const std::string& path, const ImageRGB& image, float exposureStops, ToneMapping tm);

}  // namespace narval

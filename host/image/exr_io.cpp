// exr_io.cpp: 32-bit float linear RGB OpenEXR files (DESIGN.md, Output and Platform facts:
// Imf::RgbaOutputFile writes half only, so this uses Imf::OutputFile with FLOAT slices, which
// round-trips every float bit-exactly, denormals, negatives, infinities and NaN payloads included).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <IexBaseExc.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "core/atomic_file.h"
#include "core/input_error.h"
#include "core/number_format.h"
#include "image/image.h"

namespace narval {
namespace {

// Imf output stream over the AtomicFile's FILE*. Imf swallows errors that happen in
// ~OutputFile (the line offset table is written there), so every error is also kept here and
// checked once the OutputFile is gone.
class FileOStream : public Imf::OStream {
 public:
  FileOStream(FILE* file, const std::string& name) : Imf::OStream(name.c_str()), file_(file) {}
  void write(const char c[], int n) override {
    if (!error_.empty()) throw Iex::IoExc(error_);
    if (n > 0 && std::fwrite(c, 1, size_t(n), file_) != size_t(n)) failed();
  }
  uint64_t tellp() override {
    const off_t pos = ::ftello(file_);
    if (pos < 0) failed();
    return uint64_t(pos);
  }
  void seekp(uint64_t pos) override {
    if (!error_.empty()) throw Iex::IoExc(error_);
    if (::fseeko(file_, off_t(pos), SEEK_SET) != 0) failed();
  }
  const std::string& error() const { return error_; }

 private:
  [[noreturn]] void failed() {
    error_ = std::strerror(errno ? errno : EIO);
    throw Iex::IoExc(error_);
  }
  FILE* file_;
  std::string error_;
};

// Opens an EXR for reading; every failure is an InputError "PATH: what".
std::unique_ptr<Imf::InputFile> openExr(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw inputError(path, "", "file not found");
  if (std::filesystem::is_directory(status)) throw inputError(path, "", "is a directory, not an EXR file");
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw inputError(path, "", std::string("cannot open: ") + std::strerror(errno));
    unsigned char magic[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(magic), 4);
    // OpenEXR magic number 20000630, little endian (OpenEXR file layout, "Magic Number").
    if (in.gcount() != 4 || magic[0] != 0x76 || magic[1] != 0x2f || magic[2] != 0x31 || magic[3] != 0x01)
      throw inputError(path, "", "not an OpenEXR file");
  }
  try {
    return std::make_unique<Imf::InputFile>(path.c_str());
  } catch (const std::exception& e) {
    throw inputError(path, "", "corrupt OpenEXR file: " + oneLine(e.what()));
  }
}

}  // namespace

void writeExr(const std::string& path, const ImageRGB& image, const std::vector<ExrAttribute>& attributes,
              const std::vector<ExrUintChannel>& extra) {
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(writeErrorMessage(path, "empty image (" + std::to_string(image.width) + "x" +
                                                         std::to_string(image.height) + ")"));
  if (image.rgb.size() != size_t(image.width) * size_t(image.height) * 3)
    throw std::runtime_error(writeErrorMessage(path, "pixel buffer size does not match the image size"));
  const size_t pixels = size_t(image.width) * size_t(image.height);
  for (const ExrUintChannel& c : extra)
    if (c.values.size() != pixels)
      throw std::runtime_error(writeErrorMessage(path, "channel " + c.name + " does not match the image size"));

  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.channels().insert("R", Imf::Channel(Imf::FLOAT));
  header.channels().insert("G", Imf::Channel(Imf::FLOAT));
  header.channels().insert("B", Imf::Channel(Imf::FLOAT));
  for (const ExrUintChannel& c : extra) header.channels().insert(c.name, Imf::Channel(Imf::UINT));
  for (const ExrAttribute& a : attributes) {
    try {
      std::visit(
          [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, std::string>) header.insert(a.name, Imf::StringAttribute(v));
            else if constexpr (std::is_same_v<T, int>) header.insert(a.name, Imf::IntAttribute(v));
            else if constexpr (std::is_same_v<T, float>) header.insert(a.name, Imf::FloatAttribute(v));
            else if constexpr (std::is_same_v<T, double>) header.insert(a.name, Imf::DoubleAttribute(v));
            else header.insert(a.name, Imf::StringVectorAttribute(v));
          },
          a.value);
    } catch (const std::exception& e) {
      throw std::runtime_error(writeErrorMessage(path, "attribute \"" + a.name + "\": " + oneLine(e.what())));
    }
  }

  AtomicFile out(path);
  FileOStream stream(out.file(), path);
  try {
    Imf::OutputFile file(stream, header);
    const size_t xStride = 3 * sizeof(float);
    const size_t yStride = xStride * size_t(image.width);
    char* base = const_cast<char*>(reinterpret_cast<const char*>(image.rgb.data()));
    Imf::FrameBuffer frame;
    frame.insert("R", Imf::Slice(Imf::FLOAT, base + 0 * sizeof(float), xStride, yStride));
    frame.insert("G", Imf::Slice(Imf::FLOAT, base + 1 * sizeof(float), xStride, yStride));
    frame.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xStride, yStride));
    for (const ExrUintChannel& c : extra)
      frame.insert(c.name, Imf::Slice(Imf::UINT, const_cast<char*>(reinterpret_cast<const char*>(c.values.data())),
                                      sizeof(uint32_t), sizeof(uint32_t) * size_t(image.width)));
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    out.fail(stream.error().empty() ? oneLine(e.what()) : stream.error());
  }
  if (!stream.error().empty()) out.fail(stream.error());  // from ~OutputFile, which swallows it
  out.commit();
}

namespace {

// The data window of `header`, checked (not empty, not too large); every channel in `names` must
// exist, and with `type` UINT be stored as UINT (other types convert to FLOAT as they are read).
Imath::Box2i checkedWindow(const std::string& path, const Imf::Header& header, const std::vector<std::string>& names,
                           Imf::PixelType type) {
  for (const std::string& name : names) {
    const Imf::Channel* channel = header.channels().findChannel(name);
    if (channel && type == Imf::UINT && channel->type != Imf::UINT)
      throw inputError(path, name, "not a UINT channel");
    if (!channel) {
      std::string found;
      for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        found += (found.empty() ? "" : ", ") + std::string(it.name());
      throw inputError(path, "", "no " + name + " channel (channels: " + (found.empty() ? "none" : found) + ")");
    }
  }
  const Imath::Box2i window = header.dataWindow();
  const int64_t w = int64_t(window.max.x) - window.min.x + 1;
  const int64_t h = int64_t(window.max.y) - window.min.y + 1;
  if (w <= 0 || h <= 0) throw inputError(path, "", "empty data window");
  if (w * h > (int64_t(1) << 28))
    throw inputError(path, "", "image too large (" + std::to_string(w) + "x" + std::to_string(h) + ")");
  return window;
}

// Slices for the channels `names` into `out`, interleaved (names.size() values per pixel, in that
// order), sized for `window`. T is float (FLOAT) or uint32_t (UINT).
template <typename T>
void addSlices(Imf::FrameBuffer& frame, const Imath::Box2i& window, const std::vector<std::string>& names,
               std::vector<T>& out) {
  constexpr Imf::PixelType type = std::is_same_v<T, float> ? Imf::FLOAT : Imf::UINT;
  const size_t w = size_t(window.max.x - window.min.x + 1), h = size_t(window.max.y - window.min.y + 1);
  const size_t stride = names.size();
  out.assign(w * h * stride, T(0));
  const size_t xStride = stride * sizeof(T), yStride = xStride * w;
  char* base = reinterpret_cast<char*>(out.data());
  // Slice::Make offsets the base pointer by the data window origin without overflow.
  for (size_t i = 0; i < names.size(); ++i)
    frame.insert(names[i], Imf::Slice::Make(type, base + i * sizeof(T), window, xStride, yStride));
}

void readFrame(const std::string& path, Imf::InputFile& file, const Imf::FrameBuffer& frame, const Imath::Box2i& window) {
  try {
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
  } catch (const std::exception& e) {
    throw inputError(path, "", "corrupt OpenEXR file: " + oneLine(e.what()));
  }
}

// Reads the channels `names` into `out`, interleaved; *width and *height are the data window's size.
template <typename T>
void readChannels(const std::string& path, Imf::InputFile& file, const std::vector<std::string>& names,
                  std::vector<T>& out, int* width, int* height) {
  const Imath::Box2i window =
      checkedWindow(path, file.header(), names, std::is_same_v<T, float> ? Imf::FLOAT : Imf::UINT);
  *width = window.max.x - window.min.x + 1;
  *height = window.max.y - window.min.y + 1;
  Imf::FrameBuffer frame;
  addSlices(frame, window, names, out);
  readFrame(path, file, frame, window);
}

// Interleaved values (n per pixel) as one channel each.
template <typename Channel, typename T>
std::vector<Channel> deinterleave(const std::vector<std::string>& names, const std::vector<T>& interleaved) {
  const size_t n = names.size(), pixels = n ? interleaved.size() / n : 0;
  std::vector<Channel> channels(n);
  for (size_t c = 0; c < n; ++c) {
    channels[c].name = names[c];
    channels[c].values.resize(pixels);
    for (size_t i = 0; i < pixels; ++i) channels[c].values[i] = interleaved[i * n + c];
  }
  return channels;
}

// The attributes writeExr can write, as text (readExrAttributes).
std::map<std::string, std::string> attributesOf(const Imf::Header& header) {
  std::map<std::string, std::string> result;
  for (auto it = header.begin(); it != header.end(); ++it) {
    const Imf::Attribute& a = it.attribute();
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a)) {
      result[it.name()] = s->value();
    } else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a)) {
      result[it.name()] = std::to_string(i->value());
    } else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a)) {
      result[it.name()] = formatShortest(f->value());
    } else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) {
      result[it.name()] = formatShortest(d->value());
    } else if (const auto* v = dynamic_cast<const Imf::StringVectorAttribute*>(&a)) {
      std::string text;
      for (size_t k = 0; k < v->value().size(); ++k) text += (k ? "\n" : "") + v->value()[k];
      result[it.name()] = text;
    }
  }
  return result;
}

}  // namespace

ImageRGB readExr(const std::string& path) {
  auto file = openExr(path);
  ImageRGB image;
  readChannels(path, *file, {"R", "G", "B"}, image.rgb, &image.width, &image.height);
  return image;
}

namespace {
// The named channels of `path`, one Channel (ExrChannel or ExrUintChannel) each.
template <typename Channel>
std::vector<Channel> readNamedChannels(const std::string& path, const std::vector<std::string>& names) {
  auto file = openExr(path);
  std::vector<typename decltype(Channel::values)::value_type> interleaved;
  int width = 0, height = 0;
  readChannels(path, *file, names, interleaved, &width, &height);
  return deinterleave<Channel>(names, interleaved);
}
}  // namespace

std::vector<ExrChannel> readExrChannels(const std::string& path, const std::vector<std::string>& names) {
  return readNamedChannels<ExrChannel>(path, names);
}

std::vector<ExrUintChannel> readExrUintChannels(const std::string& path, const std::vector<std::string>& names) {
  return readNamedChannels<ExrUintChannel>(path, names);
}

ExrContents readExrWithUintChannels(const std::string& path, const std::vector<std::string>& uintNames) {
  auto file = openExr(path);
  const Imf::Header& header = file->header();
  const std::vector<std::string> rgb = {"R", "G", "B"};
  const Imath::Box2i window = checkedWindow(path, header, rgb, Imf::FLOAT);
  checkedWindow(path, header, uintNames, Imf::UINT);
  ExrContents c;
  c.attributes = attributesOf(header);
  c.image.width = window.max.x - window.min.x + 1;
  c.image.height = window.max.y - window.min.y + 1;
  std::vector<uint32_t> uints;
  Imf::FrameBuffer frame;
  addSlices(frame, window, rgb, c.image.rgb);
  addSlices(frame, window, uintNames, uints);
  readFrame(path, *file, frame, window);
  c.uints = deinterleave<ExrUintChannel>(uintNames, uints);
  return c;
}

std::map<std::string, std::string> readExrAttributes(const std::string& path) {
  auto file = openExr(path);
  return attributesOf(file->header());
}

ExrHeader readExrHeader(const std::string& path) {
  auto file = openExr(path);
  const Imath::Box2i window = checkedWindow(path, file->header(), {}, Imf::FLOAT);
  std::vector<std::string> channels;
  for (auto it = file->header().channels().begin(); it != file->header().channels().end(); ++it)
    channels.push_back(it.name());
  return {window.max.x - window.min.x + 1, window.max.y - window.min.y + 1, attributesOf(file->header()),
          std::move(channels)};
}

}  // namespace narval

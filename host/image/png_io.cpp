// png_io.cpp: the display image, RGB 8 bit, through libpng's simplified write API (libpng 1.6),
// which does its own error handling (no setjmp/longjmp across C++ frames) and marks 8-bit output
// as sRGB.
#include <png.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "image/display_transform.h"
#include "image/image.h"

namespace narval {

void writePng8(const std::string& path, const ImageRGB8& image) {
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(writeErrorMessage(path, "empty image (" + std::to_string(image.width) + "x" +
                                                         std::to_string(image.height) + ")"));
  if (image.rgb.size() != size_t(image.width) * size_t(image.height) * 3)
    throw std::runtime_error(writeErrorMessage(path, "pixel buffer size does not match the image size"));
  AtomicFile out(path);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGB;
  const png_int_32 rowStride = png_int_32(image.width) * 3;
  const int ok = png_image_write_to_stdio(&png, out.file(), 0, image.rgb.data(), rowStride, nullptr);
  const std::string message = png.message;
  png_image_free(&png);
  if (!ok) out.fail(message.empty() ? "libpng error" : message);
  out.commit();
}

// The sizes are checked by writePng8 (the 8-bit copy keeps them).
void writePng(const std::string& path, const ImageRGB& image, float exposureStops, ToneMapping tm) {
  ImageRGB8 display;
  display.width = image.width;
  display.height = image.height;
  display.rgb.resize(image.rgb.size());
  const float scale = exposureScale(exposureStops);
  for (size_t i = 0; i < display.rgb.size(); ++i)
    display.rgb[i] = displayTo8Bit(displayEncoded(image.rgb[i], scale, tm));
  writePng8(path, display);
}

}  // namespace narval

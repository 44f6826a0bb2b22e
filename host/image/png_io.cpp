// png_io.cpp: the display image, RGB 8 bit, through libpng's simplified write API (libpng 1.6),
// which does its own error handling (no setjmp/longjmp across C++ frames) and marks 8-bit output
// as sRGB.
#include <png.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "image/atomic_file.h"
#include "image/display_transform.h"
#include "image/image.h"

namespace narval {

void writePng(const std::string& path, const ImageRGB& image, float exposureStops, ToneMapping tm) {
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(writeErrorMessage(path, "empty image (" + std::to_string(image.width) + "x" +
                                                         std::to_string(image.height) + ")"));
  if (image.rgb.size() != size_t(image.width) * size_t(image.height) * 3)
    throw std::runtime_error(writeErrorMessage(path, "pixel buffer size does not match the image size"));

  const float scale = exposureScale(exposureStops);
  std::vector<uint8_t> pixels(image.rgb.size());
  for (size_t i = 0; i < pixels.size(); ++i)
    pixels[i] = displayTo8Bit(displayEncoded(image.rgb[i], scale, tm));

  AtomicFile out(path);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGB;
  const png_int_32 rowStride = png_int_32(image.width) * 3;
  const int ok = png_image_write_to_stdio(&png, out.file(), 0, pixels.data(), rowStride, nullptr);
  const std::string message = png.message;
  png_image_free(&png);
  if (!ok) out.fail(message.empty() ? "libpng error" : message);
  out.commit();
}

}  // namespace narval

#include "analysis/sweep.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <regex>
#include <stdexcept>

#include "colour/cielab.h"
#include "core/input_error.h"
#include "core/number_format.h"
#include "image/bitmap_font.h"

namespace narval {
namespace {


// The shortest text that reads back as the same double (CSV cells); non-finite values as JSON's null
// would be are written as "nan".
std::string exact(double v) { return std::isfinite(v) ? nlohmann::json(v).dump() : "nan"; }

}  // namespace

const char* sweepParameterName(SweepParameter p) { return p == SweepParameter::Spp ? "spp" : "bounces"; }

std::vector<int> parseSweepList(const std::string& text, const std::string& option) {
  static const std::regex item(R"(^\s*(\d{1,10})\s*$)");
  const InputError bad =
      inputError(option, "", "expected a comma-separated list of positive integers, got '" + text + "'");
  std::vector<int> values;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    std::smatch m;
    if (!std::regex_match(part, m, item)) throw bad;
    const long long v = std::stoll(m[1]);
    if (v <= 0 || v > INT_MAX) throw bad;
    if (std::find(values.begin(), values.end(), int(v)) != values.end())
      throw inputError(option, "", std::to_string(v) + " is listed twice in '" + text + "'");
    values.push_back(int(v));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return values;
}

std::string sweepFileName(SweepParameter p, int value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, p == SweepParameter::Spp ? "spp_%05d.exr" : "bounces_%04d.exr", value);
  return buf;
}

std::string sweepLabel(SweepParameter p, int value) {
  if (p == SweepParameter::Spp) return std::to_string(value) + " spp";
  return std::to_string(value) + (value == 1 ? " bounce" : " bounces");
}

DisplaySettings sceneDisplaySettings(const Scene& scene) {
  DisplaySettings d;
  d.exposureStops = scene.renderer.exposure;
  d.toneMapping = scene.renderer.toneMapping;
  return d;
}

void checkSweepReference(const Scene& scene, const ImageRGB& reference, const std::string& name) {
  const int W = scene.renderer.width, H = scene.renderer.height;
  if (reference.width != W || reference.height != H)
    throw inputError(name, "",
                     "size " + std::to_string(reference.width) + "x" + std::to_string(reference.height) +
                         " differs from the sweep's " + std::to_string(W) + "x" + std::to_string(H) +
                         " (use --resolution or a matching reference)");
  long long bad = 0;
  for (float v : reference.rgb) bad += std::isfinite(v) ? 0 : 1;
  if (bad > 0)
    throw inputError(name, "", "holds " + std::to_string(bad) + (bad == 1 ? " non-finite value" : " non-finite values"));
}

SweepResult runSweep(const Scene& scene, const SweepSpec& spec, const SweepRenderer& render,
                     const std::function<void(const SweepRow&)>& onRow) {
  if (spec.values.empty()) throw std::invalid_argument("runSweep: no values");
  std::vector<int> values = spec.values;
  std::sort(values.begin(), values.end(), std::greater<int>());
  if (std::adjacent_find(values.begin(), values.end()) != values.end())
    throw std::invalid_argument("runSweep: a value is listed twice");
  if (spec.reference) checkSweepReference(scene, *spec.reference, spec.referenceName);

  SweepResult r;
  r.parameter = spec.parameter;
  r.fixedValue = spec.parameter == SweepParameter::Spp ? scene.renderer.bounces : scene.renderer.spp;
  r.scene = scene.sourcePath;
  r.width = scene.renderer.width;
  r.height = scene.renderer.height;
  r.seed = scene.renderer.seed;
  r.display = sceneDisplaySettings(scene);
  r.speedupBaseline = values.front();
  if (spec.reference) {
    r.referenceFile = spec.referenceName;
    r.referenceImage = *spec.reference;
  }

  auto sceneFor = [&](int value) {
    Scene s = scene;
    s.renderer.algorithm = Algorithm::Pathtrace;
    (spec.parameter == SweepParameter::Spp ? s.renderer.spp : s.renderer.bounces) = value;
    return s;
  };
  // The first launch of a kernel compiles it for the device and local size: keep that out of
  // the timings with one untimed sample per pixel.
  if (spec.warmUp) {
    Scene s = sceneFor(values.back());
    s.renderer.spp = 1;
    render(s);
  }

  const size_t pixels = size_t(r.width) * size_t(r.height);
  const std::string referenceName = spec.reference ? spec.referenceName : sweepFileName(spec.parameter, values.front());
  for (size_t i = 0; i < values.size(); ++i) {
    RenderResult rendered = render(sceneFor(values[i]));
    SweepRow row;
    row.value = values[i];
    row.stats = rendered.stats;
    row.seconds = rendered.stats.seconds;
    if (r.device.empty()) r.device = rendered.stats.device;
    if (i == 0 && !spec.reference) {
      // The reference's own row: exactly zero error and unit speed-up, by definition.
      row.isReference = true;
      r.referenceImage = rendered.image;
      row.dE76Map.assign(pixels, 0.0f);
    } else {
      ImageComparison c = compareImages(r.referenceImage, rendered.image, r.display, referenceName,
                                        sweepFileName(spec.parameter, values[i]));
      row.dE76 = c.stats76;
      row.dE2000 = c.stats2000;
      row.dE76Map = std::move(c.dE76);
    }
    row.image = std::move(rendered.image);
    if (i == 0)
      row.speedup = 1.0;
    else
      row.speedup = row.seconds > 0 ? r.rows.front().seconds / row.seconds : 0.0;
    r.rows.push_back(std::move(row));
    if (onRow) onRow(r.rows.back());
  }
  return r;
}

std::string sweepCsv(const SweepResult& r) {
  std::string s = "value,seconds,speedup,mean_dE76,jnd76_pct,mean_dE2000,jnd2000_pct\n";
  for (const SweepRow& row : r.rows)
    s += std::to_string(row.value) + "," + exact(row.seconds) + "," + exact(row.speedup) + "," +
         exact(row.dE76.mean) + "," + exact(row.dE76.jndPercent) + "," + exact(row.dE2000.mean) + "," +
         exact(row.dE2000.jndPercent) + "\n";
  return s;
}

nlohmann::ordered_json sweepJson(const SweepResult& r) {
  const char* fixedName = r.parameter == SweepParameter::Spp ? "bounces" : "spp";
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const SweepRow& row : r.rows) {
    nlohmann::ordered_json j = {{"value", row.value}, {"seconds", row.seconds}, {"speedup", row.speedup}};
    addDeltaEJson(j, row.dE76, row.dE2000);
    j["kernel_seconds"] = row.stats.kernelSeconds;
    j["samples_per_second"] = row.stats.samplesPerSecond;
    j["nan_pixels"] = row.stats.nanPixels;
    j["reference"] = row.isReference;
    j["exr"] = sweepFileName(r.parameter, row.value);
    rows.push_back(std::move(j));
  }
  nlohmann::ordered_json reference = r.referenceFile.empty()
                                         ? nlohmann::ordered_json{{"value", r.rows.empty() ? 0 : r.rows.front().value}}
                                         : nlohmann::ordered_json{{"file", r.referenceFile}};
  return nlohmann::ordered_json{{"parameter", sweepParameterName(r.parameter)},
          {"scene", r.scene},
          {"fixed", {{fixedName, r.fixedValue}}},
          {"device", r.device},
          {"algorithm", "pathtrace"},
          {"width", r.width},
          {"height", r.height},
          {"seed", r.seed},
          {"display", {{"exposure", r.display.exposureStops}, {"toneMapping", toneMappingName(r.display.toneMapping)}}},
          {"jnd_threshold", kJnd},
          {"reference", reference},
          {"speedup_baseline", r.speedupBaseline},
          {"rows", rows}};
}

// ------------------------------------------------------------------------------------ figure

ImageRGB8 resizeImage(const ImageRGB8& src, int width, int height) {
  ImageRGB8 dst;
  dst.width = width;
  dst.height = height;
  dst.rgb.assign(size_t(width) * size_t(height) * 3, 0);
  if (src.width <= 0 || src.height <= 0 || width <= 0 || height <= 0) return dst;
  const double sx = double(src.width) / width, sy = double(src.height) / height;
  for (int y = 0; y < height; ++y) {
    const double y0 = y * sy, y1 = (y + 1) * sy;
    for (int x = 0; x < width; ++x) {
      const double x0 = x * sx, x1 = (x + 1) * sx;
      double acc[3] = {0, 0, 0}, wsum = 0;
      for (int j = int(y0); j < src.height && j < y1; ++j) {
        const double wy = std::min<double>(j + 1, y1) - std::max<double>(j, y0);
        if (wy <= 0) continue;
        for (int i = int(x0); i < src.width && i < x1; ++i) {
          const double w = wy * (std::min<double>(i + 1, x1) - std::max<double>(i, x0));
          if (w <= 0) continue;
          const uint8_t* p = &src.rgb[(size_t(j) * src.width + i) * 3];
          for (int c = 0; c < 3; ++c) acc[c] += w * p[c];
          wsum += w;
        }
      }
      uint8_t* q = &dst.rgb[(size_t(y) * width + x) * 3];
      for (int c = 0; c < 3; ++c) q[c] = uint8_t(std::lround(wsum > 0 ? acc[c] / wsum : 0.0));
    }
  }
  return dst;
}

namespace {

void blit(ImageRGB8& dst, const ImageRGB8& src, int x0, int y0) {
  for (int y = 0; y < src.height; ++y) {
    const int ty = y0 + y;
    if (ty < 0 || ty >= dst.height) continue;
    for (int x = 0; x < src.width; ++x) {
      const int tx = x0 + x;
      if (tx < 0 || tx >= dst.width) continue;
      const uint8_t* p = &src.rgb[(size_t(y) * src.width + x) * 3];
      uint8_t* q = &dst.rgb[(size_t(ty) * dst.width + tx) * 3];
      q[0] = p[0];
      q[1] = p[1];
      q[2] = p[2];
    }
  }
}

// Each pixel repeated k×k times (k >= 1): `channels` floats per pixel.
std::vector<float> enlarge(const std::vector<float>& v, int width, int height, int channels, int k) {
  std::vector<float> out(size_t(width) * k * size_t(height) * k * channels);
  const int ow = width * k;
  for (int y = 0; y < height * k; ++y)
    for (int x = 0; x < ow; ++x)
      for (int c = 0; c < channels; ++c)
        out[(size_t(y) * ow + x) * channels + c] = v[(size_t(y / k) * width + x / k) * channels + c];
  return out;
}

// A one-pixel grey frame just outside the rectangle (x0, y0, w, h), so white renders stand out on
// the white page.
void frame(ImageRGB8& dst, int x0, int y0, int w, int h) {
  auto put = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= dst.width || y >= dst.height) return;
    uint8_t* q = &dst.rgb[(size_t(y) * dst.width + x) * 3];
    q[0] = q[1] = q[2] = 160;
  };
  for (int x = x0 - 1; x <= x0 + w; ++x) {
    put(x, y0 - 1);
    put(x, y0 + h);
  }
  for (int y = y0; y < y0 + h; ++y) {
    put(x0 - 1, y);
    put(x0 + w, y);
  }
}

struct Column {
  std::string label, sublabel;
  const ImageRGB* image = nullptr;
  const std::vector<float>* dE76 = nullptr;
  DeltaEStats stats;
  ImageRGB8 pictures[3];  // render, ΔE heat map (with its legend), JND map
  std::string captions[3];
};

// Each column's three pictures. Tiny renders are enlarged by a whole factor (pixels repeated, the
// maps drawn at that size so their text stays sharp); strips wider than availableWidth are shrunk
// (maps drawn at full size, then box-filtered: a JND map's red shows the share of pixels over the JND).
void drawPictures(std::vector<Column>& cols, int W, int H, int availableWidth, const DisplaySettings& display) {
  const double avail = double(availableWidth);
  const int n = int(cols.size());
  int enlargeBy = W < 160 ? int(std::ceil(160.0 / W)) : 1;
  while (enlargeBy > 1 && double(n) * W * enlargeBy > avail) --enlargeBy;
  const double shrink = double(n) * W * enlargeBy > avail ? std::max(avail / (double(n) * W), 1.0 / W) : 1.0;
  for (Column& c : cols) {
    ImageRGB image = *c.image;
    std::vector<float> dE = *c.dE76;
    if (enlargeBy > 1) {
      image.rgb = enlarge(image.rgb, W, H, 3, enlargeBy);
      image.width *= enlargeBy;
      image.height *= enlargeBy;
      dE = enlarge(dE, W, H, 1, enlargeBy);
    }
    c.pictures[0] = displayImage(image, display);
    c.pictures[1] = deltaEHeatmapImage(dE, image.width, image.height);
    c.pictures[2] = jndMapImage(image, display, dE, c.stats.jndPercent);
    if (shrink < 1.0)
      for (ImageRGB8& p : c.pictures)
        p = resizeImage(p, std::max(1, int(p.width * shrink)), std::max(1, int(p.height * shrink)));
  }
}

}  // namespace

ImageRGB8 sweepFigure(const SweepResult& r, int maxWidth) {
  const int W = r.width, H = r.height;
  if (W <= 0 || H <= 0) throw std::invalid_argument("sweepFigure: empty images");
  const std::vector<float> zeros(size_t(W) * size_t(H), 0.0f);
  std::vector<Column> cols;
  auto addColumn = [&](const std::string& label, const std::string& sublabel, const ImageRGB& image,
                       const std::vector<float>& dE, const DeltaEStats& st) {
    Column c;
    c.label = label;
    c.sublabel = sublabel;
    c.image = &image;
    c.dE76 = &dE;
    c.stats = st;
    c.captions[1] = "mean dE " + formatFixed(st.mean, 2);
    c.captions[2] = "JND " + formatFixed(st.jndPercent, 2) + "%";
    cols.push_back(std::move(c));
  };
  if (!r.referenceFile.empty()) addColumn("reference", "file", r.referenceImage, zeros, DeltaEStats{});
  for (const SweepRow& row : r.rows)
    addColumn(sweepLabel(r.parameter, row.value), row.isReference ? "reference" : formatFixed(row.speedup, 2) + "x faster",
              row.image, row.dE76Map, row.dE76);
  const int n = int(cols.size()), pad = 8;
  drawPictures(cols, W, H, maxWidth - (n + 1) * pad, r.display);

  int colW = 0, rowH[3] = {0, 0, 0};
  for (const Column& c : cols)
    for (int k = 0; k < 3; ++k) {
      colW = std::max(colW, c.pictures[k].width);
      rowH[k] = std::max(rowH[k], c.pictures[k].height);
    }
  auto widestText = [&](int s) {
    int w = 0;
    for (const Column& c : cols) {
      w = std::max({w, fontTextWidth(c.label, s), fontTextWidth(c.sublabel, s)});
      for (const std::string& t : c.captions) w = std::max(w, fontTextWidth(t, s));
    }
    return w;
  };
  int scale = colW >= 200 ? 2 : 1;
  if (scale > 1 && widestText(scale) > colW) scale = 1;
  colW = std::max(colW, widestText(scale));
  const int line = (kFontHeight + 3) * scale;
  const std::string title = std::string(sweepParameterName(r.parameter)) + " sweep at " +
                            (r.parameter == SweepParameter::Spp ? sweepLabel(SweepParameter::Bounces, r.fixedValue)
                                                                : sweepLabel(SweepParameter::Spp, r.fixedValue));

  ImageRGB8 fig;
  fig.width = std::max(n * colW + (n + 1) * pad, fontTextWidth(title, scale) + 2 * pad);
  fig.height = pad + line + pad + 2 * line + (rowH[0] + pad) + (rowH[1] + line + pad) + (rowH[2] + line + pad);
  fig.rgb.assign(size_t(fig.width) * size_t(fig.height) * 3, 255);
  drawText(fig, pad, pad, title, scale, 0, 0, 0);
  for (int i = 0; i < n; ++i) {
    const Column& c = cols[size_t(i)];
    const int x = pad + i * (colW + pad);
    auto centred = [&](const std::string& t, int y, uint8_t grey) {
      drawText(fig, x + (colW - fontTextWidth(t, scale)) / 2, y, t, scale, grey, grey, grey);
    };
    int y = pad + line + pad;
    centred(c.label, y, 0);
    centred(c.sublabel, y + line, 90);
    y += 2 * line;
    for (int k = 0; k < 3; ++k) {
      const int px = x + (colW - c.pictures[k].width) / 2;
      blit(fig, c.pictures[k], px, y);
      frame(fig, px, y, c.pictures[k].width, c.pictures[k].height);
      y += rowH[k];
      if (!c.captions[k].empty()) {
        centred(c.captions[k], y + 2 * scale, 0);
        y += line;
      }
      y += pad;
    }
  }
  return fig;
}

}  // namespace narval

#include "viewer/viewer_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>

#include <glm/geometric.hpp>

#include "core/atomic_file.h"
#include "core/number_format.h"
#include "image/bitmap_font.h"
#include "render/render_common.h"
#include "render/render_exr.h"
#include "render/scene_upload.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

constexpr int kLevels[] = {1, 2, 4, 8};  // resolution divisors while moving

const char* const kHelp[] = {
    "LEFT DRAG: ORBIT   RIGHT DRAG: PAN   WHEEL: ZOOM",
    "W A S D Q E: FLY   F: FRAME THE MEDIUM",
    "1 2 3: PATHTRACE, RAYMARCH, LOBE",
    "[ ]: STEPS, LOBE POINTS, SPP PER FRAME",
    "P: SAVE EXR, PNG, JSON   R: RESET   H: HELP",
};

std::string sizeName(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }


// Whether the camera is where the scene put it, to 1e-4 of the look-at distance (the reference's
// pose: orbiting away and back leaves rounding in the last bits).
bool samePose(const Camera& a, const Camera& b) {
  const glm::vec3 pa(a.position[0], a.position[1], a.position[2]), pb(b.position[0], b.position[1], b.position[2]);
  const glm::vec3 la(a.lookAt[0], a.lookAt[1], a.lookAt[2]), lb(b.lookAt[0], b.lookAt[1], b.lookAt[2]);
  const glm::vec3 ua(a.up[0], a.up[1], a.up[2]), ub(b.up[0], b.up[1], b.up[2]);
  const float tolerance = 1e-4f * std::max(1e-6f, glm::length(lb - pb));
  return glm::length(pa - pb) <= tolerance && glm::length(la - lb) <= tolerance &&
         glm::length(glm::normalize(ua) - glm::normalize(ub)) <= 1e-4f;
}

}  // namespace

ViewerSession::ViewerSession(ClRuntime& rt, const Scene& scene, SceneGrids grid, const ViewerOptions& options)
    : rt_(rt),
      scene_(scene),
      grid_(grid),
      options_(options),
      camera_(scene.camera),
      algorithm_(scene.renderer.algorithm),
      raymarchSteps_(scene.renderer.raymarch.steps),
      lobePoints_(scene.renderer.lobe.lobePoints) {}

ViewerSession::~ViewerSession() = default;

Scene ViewerSession::currentScene() const {
  Scene s = scene_;
  s.camera = camera_.toCamera();
  s.renderer.algorithm = algorithm_;
  s.renderer.raymarch.steps = raymarchSteps_;
  s.renderer.lobe.lobePoints = lobePoints_;
  return s;
}

void ViewerSession::apply(const ViewerInput& input) {
  switch (input.kind) {
    case ViewerInput::Kind::Orbit:
      camera_.orbit(0.25f * input.dx, -0.25f * input.dy);  // a quarter degree per pixel; drag up: look from above
      moved_ = true;
      break;
    case ViewerInput::Kind::Pan: {
      const float h = float(std::max(1, scene_.renderer.height));
      camera_.pan(-input.dx / h, input.dy / h);  // the medium follows the mouse
      moved_ = true;
      break;
    }
    case ViewerInput::Kind::Zoom:
      camera_.zoom(std::pow(0.9f, input.dy));
      moved_ = true;
      break;
    case ViewerInput::Kind::Fly:
      camera_.fly(input.axes, input.seconds);
      moved_ = true;
      break;
    case ViewerInput::Kind::Frames:
      break;
    case ViewerInput::Kind::Key:
      switch (input.key) {
        case '1': case '2': case '3': {
          const Algorithm next = input.key == '1'   ? Algorithm::Pathtrace
                                 : input.key == '2' ? Algorithm::Raymarch
                                                    : Algorithm::Lobe;
          if (next != algorithm_) {
            algorithm_ = next;
            restart_ = true;
          }
          break;
        }
        case '[': case ']': {
          const bool up = input.key == ']';
          switch (algorithm_) {
            case Algorithm::Raymarch:
              raymarchSteps_ = up ? std::min(4096, raymarchSteps_ * 3 / 2 + 1) : std::max(2, raymarchSteps_ * 2 / 3);
              messages_.push_back("raymarch: " + std::to_string(raymarchSteps_) + " steps");
              break;
            case Algorithm::Lobe:
              lobePoints_ = up ? std::min(1024, lobePoints_ * 2) : std::max(1, lobePoints_ / 2);
              messages_.push_back("lobe: " + std::to_string(lobePoints_) + " lobe points");
              break;
            case Algorithm::Pathtrace:
              pathtraceSppPerFrame_ =
                  up ? std::min(256, pathtraceSppPerFrame_ * 2) : std::max(1, pathtraceSppPerFrame_ / 2);
              messages_.push_back("pathtrace: " + std::to_string(pathtraceSppPerFrame_) + " spp per frame");
              break;
          }
          break;
        }
        case 'P': snapshot_ = true; break;
        case 'R': restart_ = true; break;
        case 'H': help_ = !help_; break;
        case 'F': {
          float lo[3], hi[3];
          const DeviceScene* ds = raymarch_    ? &raymarch_->deviceScene()
                                  : lobe_      ? &lobe_->deviceScene()
                                  : pathtrace_ ? &pathtrace_->deviceScene()
                                               : nullptr;
          if (ds && mediumWorldBounds(*ds, lo, hi)) {
            camera_.frame({lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]},
                          float(scene_.renderer.width) / float(scene_.renderer.height));
            moved_ = true;
          }
          break;
        }
        default: throw std::invalid_argument(std::string("ViewerSession: not a viewer key: ") + input.key);
      }
      break;
  }
}

bool ViewerSession::idle() const {
  return algorithm_ == Algorithm::Pathtrace && !moved_ && !restart_ && !snapshot_ && pathtrace_ &&
         pathtrace_->samples() >= scene_.renderer.spp && lastWidth_ == scene_.renderer.width;
}

int ViewerSession::chooseLevel() const {
  const auto it = msPerPixel_.find(algorithm_);
  if (it == msPerPixel_.end()) return 1;  // nothing measured yet: full size
  const double perSample = algorithm_ == Algorithm::Pathtrace ? pathtraceSppPerFrame_ : 1;
  const double fullPixels = double(scene_.renderer.width) * scene_.renderer.height;
  for (const int level : kLevels)
    if (it->second * perSample * fullPixels / (level * level) <= options_.targetMs) return level;
  return kLevels[std::size(kLevels) - 1];
}

RealtimeRenderer& ViewerSession::realtime(const Scene& view) {
  std::unique_ptr<RealtimeRenderer>& r = algorithm_ == Algorithm::Raymarch ? raymarch_ : lobe_;
  if (!r) {
    // Made at the full size, whatever this frame's: the automatic light cache is weighed against it.
    Scene full = view;
    full.renderer.width = scene_.renderer.width;
    full.renderer.height = scene_.renderer.height;
    r = std::make_unique<RealtimeRenderer>(rt_, full, grid_, options_.render);
    if (options_.msCacheIn && algorithm_ == Algorithm::Raymarch) r->restoreMsCache(*options_.msCacheIn);
    for (const std::string& w : r->warnings()) messages_.push_back("warning: " + w);
  }
  r->setView(view);
  return *r;
}

PathtraceRenderer& ViewerSession::pathtrace(const Scene& view) {
  if (!pathtrace_) {
    pathtrace_ = std::make_unique<PathtraceRenderer>(rt_, view, grid_, options_.render);
    for (const std::string& w : pathtrace_->warnings()) messages_.push_back("warning: " + w);
    pathtraceViewKey_.clear();
  }
  // Any change of camera or size starts the accumulation over (setView), as does R.
  const std::string key = rawBytes(buildCamera(view));
  if (key != pathtraceViewKey_) {
    pathtrace_->setView(view);
    pathtraceViewKey_ = key;
  } else if (restart_) {
    pathtrace_->reset();
  }
  return *pathtrace_;
}

void ViewerSession::renderFrame() {
  const auto t0 = std::chrono::steady_clock::now();
  const bool moving = moved_ && !snapshot_;
  const int level = moving ? chooseLevel() : 1;
  const int fullW = scene_.renderer.width, fullH = scene_.renderer.height;
  Scene view = currentScene();
  view.renderer.width = std::max(1, fullW / level);
  view.renderer.height = std::max(1, fullH / level);
  const int W = view.renderer.width, H = view.renderer.height;

  RenderResult result;
  double ms = 0;
  if (algorithm_ == Algorithm::Pathtrace) {
    PathtraceRenderer& r = pathtrace(view);
    // While moving each frame starts over; when still, frames add samples up to the scene's spp.
    if (moving) r.reset();
    const int count = std::min(pathtraceSppPerFrame_, std::max(0, view.renderer.spp - r.samples()));
    if (count > 0 || r.samples() == 0) ms = r.addSamples(std::max(1, count));
    result.stats = r.stats();
    r.readBack(result);
    if (snapshot_) result.mediumMask = r.mediumMask();
    spp_ = r.samples();
  } else {
    RealtimeRenderer& r = realtime(view);
    // The multiple-scattering cache takes what the frame leaves of its budget (a quarter at least), so
    // no frame waits for all of it; a snapshot must be what `narval render` of its scene draws: the
    // cache complete first.
    ms = r.renderFrame(snapshot_ ? 0 : cacheBudgetMs(options_.targetMs, lastMs_));
    result = r.result();
    cacheProgress_ = result.stats.msCache.builds > 0 ? result.stats.msCache.progress : -1;
    if (snapshot_) result.mediumMask = r.mediumMask();
    spp_ = 1;
  }
  if (ms > 0)
    msPerPixel_[algorithm_] = ms / (double(W) * H * (algorithm_ == Algorithm::Pathtrace ? pathtraceSppPerFrame_ : 1));
  lastMs_ = ms;
  ++frames_;
  ++framesPerResolution_[sizeName(W, H)];
  lastWidth_ = W;
  lastHeight_ = H;

  liveError_ = LiveError{};
  if (options_.reference && level == 1 && samePose(view.camera, scene_.camera) &&
      options_.reference->width == W && options_.reference->height == H) {
    // A comparison costs about as much as a still ray-marched frame (0.3 s at 1200x600), and a
    // real-time frame that nothing changed is the same image: compare only a new one.
    if (result.image.rgb != comparedRgb_) {
      const ImageComparison c =
          compareImages(*options_.reference, result.image, {scene_.renderer.exposure, scene_.renderer.toneMapping},
                        options_.referenceName, "the viewer's frame");
      comparedError_ = {true, c.stats76.mean, c.stats76.jndPercent};
      comparedRgb_ = result.image.rgb;
    }
    liveError_ = comparedError_;
  }
  compose(result.image);
  FrameTimes& times = frameTimes_[sizeName(W, H)];
  times.kernelMs.push_back(ms);
  times.frameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  if (snapshot_) {
    if (algorithm_ == Algorithm::Pathtrace) view.renderer.spp = spp_;
    writeSnapshot(result, view);
  }
  moved_ = restart_ = snapshot_ = false;
}

void ViewerSession::compose(const ImageRGB& image) {
  const ImageRGB8 frame = displayImage(image, {scene_.renderer.exposure, scene_.renderer.toneMapping});
  const int fullW = scene_.renderer.width, fullH = scene_.renderer.height;
  display_.width = fullW;
  display_.height = fullH;
  display_.rgb.resize(size_t(fullW) * fullH * 3);
  for (int y = 0; y < fullH; ++y) {
    const int sy = std::min(frame.height - 1, y * frame.height / fullH);
    for (int x = 0; x < fullW; ++x) {
      const int sx = std::min(frame.width - 1, x * frame.width / fullW);
      for (int c = 0; c < 3; ++c)
        display_.rgb[(size_t(y) * fullW + x) * 3 + c] = frame.rgb[(size_t(sy) * frame.width + sx) * 3 + c];
    }
  }
  if (!help_) return;
  // The help overlay: a dimmed box with the keys, then the status line, at the top left.
  std::vector<std::string> lines(std::begin(kHelp), std::end(kHelp));
  lines.push_back(algorithmName(algorithm_) + std::string("  ") + formatFixed(lastMs_, 1) + " MS  " + sizeName(lastWidth_, lastHeight_) + "  " +
                  std::to_string(spp_) + " SPP");
  if (cacheProgress_ >= 0 && algorithm_ == Algorithm::Raymarch) lines.push_back("MS CACHE " + std::to_string(int(cacheProgress_ * 100)) + "%");
  if (liveError_.valid)
    lines.push_back("DE76 " + formatFixed(liveError_.meanDeltaE76, 2) + "  JND " + formatFixed(liveError_.jndPercent, 1) + "%");
  const int scale = fullW >= 960 ? 2 : 1, lineHeight = (kFontHeight + 3) * scale;
  int boxW = 0;
  for (const std::string& l : lines) boxW = std::max(boxW, fontTextWidth(l, scale));
  boxW = std::min(fullW, boxW + 8 * scale);
  const int boxH = std::min(fullH, int(lines.size()) * lineHeight + 6 * scale);
  for (int y = 0; y < boxH; ++y)
    for (int x = 0; x < boxW; ++x)
      for (int c = 0; c < 3; ++c) {
        uint8_t& v = display_.rgb[(size_t(y) * fullW + x) * 3 + c];
        v = uint8_t(v / 4);
      }
  for (size_t i = 0; i < lines.size(); ++i)
    drawText(display_, 4 * scale, 4 * scale + int(i) * lineHeight, lines[i], scale, 255, 255, 255);
}

void ViewerSession::writeSnapshot(const RenderResult& result, const Scene& view) {
  fs::create_directories(options_.outputDir);
  const std::string stem = fs::path(scene_.sourcePath).stem().string() + "_view_";
  fs::path base;
  for (int n = 1;; ++n) {  // the first number whose three files are all free: never overwrite
    char number[16];
    std::snprintf(number, sizeof number, "%03d", n);
    base = fs::path(options_.outputDir) / (stem + number);
    if (!fs::exists(base.string() + ".exr") && !fs::exists(base.string() + ".png") &&
        !fs::exists(base.string() + ".json"))
      break;
  }
  // The scene as loaded (with --set applied), with this camera, algorithm, quality and spp, and the
  // volume files as absolute paths, so it renders from wherever it is written.
  nlohmann::json doc = view.document;
  auto vec = [](const Vec3f& v) { return nlohmann::json::array({double(v[0]), double(v[1]), double(v[2])}); };
  doc["camera"]["position"] = vec(view.camera.position);
  doc["camera"]["lookAt"] = vec(view.camera.lookAt);
  doc["camera"]["up"] = vec(view.camera.up);
  doc["renderer"]["algorithm"] = algorithmName(view.renderer.algorithm);
  doc["renderer"]["resolution"] = {view.renderer.width, view.renderer.height};
  switch (view.renderer.algorithm) {  // its quality parameter ([ ]), and the path tracer's spp so far
    case Algorithm::Pathtrace: doc["renderer"]["spp"] = view.renderer.spp; break;
    case Algorithm::Raymarch: doc["renderer"]["raymarch"]["steps"] = view.renderer.raymarch.steps; break;
    case Algorithm::Lobe: doc["renderer"]["lobe"]["lobePoints"] = view.renderer.lobe.lobePoints; break;
  }
  for (size_t i = 0; i < view.materials.size() && doc.contains("materials") && i < doc["materials"].size(); ++i)
    if (!view.materials[i].path.empty() && doc["materials"][i].contains("path"))
      doc["materials"][i]["path"] = fs::absolute(view.materials[i].path).lexically_normal().string();
  writeRenderExr(base.string() + ".exr", result, renderIdentity(view));
  writePng(base.string() + ".png", result.image, view.renderer.exposure, view.renderer.toneMapping);
  writeTextAtomic(base.string() + ".json", doc.dump(2) + "\n");
  messages_.push_back("wrote " + base.string() + ".exr, .png and .json (" + algorithmName(view.renderer.algorithm) + ", " +
                      sizeName(view.renderer.width, view.renderer.height) +
                      (view.renderer.algorithm == Algorithm::Pathtrace ? ", " + std::to_string(spp_) + " spp" : "") + ")");
}

std::vector<std::string> ViewerSession::takeMessages() {
  std::vector<std::string> m;
  m.swap(messages_);
  return m;
}

std::string ViewerSession::title() const {
  std::string t = "narval view: " + fs::path(scene_.sourcePath).filename().string() + " | " + algorithmName(algorithm_) + " | " +
                  formatFixed(lastMs_, 1) + " ms | " + sizeName(lastWidth_, lastHeight_) + " | " + std::to_string(spp_) +
                  " spp | " + rt_.selected.info.name;
  if (cacheProgress_ >= 0 && algorithm_ == Algorithm::Raymarch)
    t += " | ms cache " + std::to_string(int(cacheProgress_ * 100)) + "%";
  if (liveError_.valid)
    t += " | ΔE76 " + formatFixed(liveError_.meanDeltaE76, 2) + ", JND " + formatFixed(liveError_.jndPercent, 1) + "%";
  return t;
}

}  // namespace narval

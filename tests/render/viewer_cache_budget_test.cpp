// The viewer's frame budget and the ray marcher's multiple-scattering cache (viewer/viewer_session.h):
// the cache is built in what each frame leaves of --target-ms, so a frame never waits for all of it,
// and the title says how much of it is built.
#include <gtest/gtest.h>

#include <string>

#include "render/device_ms_cache.h"
#include "render_fixture.h"
#include "viewer/viewer_session.h"

namespace narval::test {
namespace {

// The number after "ms cache " in the title, -1 when it shows none.
int cachePercent(const std::string& title) {
  const size_t at = title.find("| ms cache ");
  return at == std::string::npos ? -1 : std::stoi(title.substr(at + 11));
}

// The lit box with the cache at 5³ nodes and 16 paths (sweeps of 1, 1, 2, 4, 8 paths), drawn with a
// budget of 0.001 ms (below any launch: one slice of a node at least a frame). The first frame shows
// part of the cache, later frames more, never less, until all; the lobe shows no cache.
TEST(ViewerCacheBudget, TheTitleShowsTheCacheFillingFrameByFrame) {
  Scene scene = litBox();
  scene.renderer.raymarch.msCache.paths = 16;
  ViewerOptions options;
  options.targetMs = 0.001;
  ViewerSession session(runtime(), scene, nullptr, options);
  session.renderFrame();
  const int first = cachePercent(session.title());
  EXPECT_GE(first, 0);
  EXPECT_LT(first, 100) << session.title();
  int last = first, frames = 1;
  for (; last < 100 && frames < 2000; ++frames) {
    session.renderFrame();
    const int now = cachePercent(session.title());
    ASSERT_GE(now, last) << session.title();
    last = now;
  }
  EXPECT_EQ(last, 100);
  EXPECT_GT(frames, 10);
  ViewerInput lobe;
  lobe.kind = ViewerInput::Kind::Key;
  lobe.key = '3';
  session.apply(lobe);
  session.renderFrame();
  EXPECT_EQ(cachePercent(session.title()), -1) << session.title();
}

// A cache read at the start (--ms-cache-in: a snapshot of one `narval render` built) is whole at the
// first frame, whatever the budget: nothing is left to build.
TEST(ViewerCacheBudget, ARestoredCacheIsWholeAtTheFirstFrame) {
  Scene scene = litBox();
  scene.renderer.raymarch.msCache.paths = 16;
  MsCacheSnapshot baked;
  RenderOptions bake;
  bake.msCacheOut = &baked;
  renderRealtime(runtime(), scene, nullptr, 1, bake);
  EXPECT_EQ(baked.paths, 16);
  ViewerOptions options;
  options.targetMs = 0.001;
  options.msCacheIn = &baked;
  ViewerSession session(runtime(), scene, nullptr, options);
  session.renderFrame();
  EXPECT_EQ(cachePercent(session.title()), 100) << session.title();
}

}  // namespace
}  // namespace narval::test

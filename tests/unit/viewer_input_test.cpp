// The viewer's script: every input it reads, and the exact line for every mistake.
#include "viewer/viewer_input.h"

#include <gtest/gtest.h>

#include "core/input_error.h"
#include "test_support.h"

namespace narval {
namespace {

TEST(ViewerScript, ReadsEveryInput) {
  const auto in = parseViewerScript(
      "# a comment\n"
      "frames 3\n"
      "\n"
      "drag left 40 -10   # orbit\n"
      "drag right 2.5 7\n"
      "scroll -2\n"
      "hold WD 0.5\n"
      "key p\n"
      "key [\n",
      "s.txt");
  ASSERT_EQ(in.size(), 7u);
  EXPECT_EQ(in[0].kind, ViewerInput::Kind::Frames);
  EXPECT_EQ(in[0].frames, 3);
  EXPECT_EQ(in[1].kind, ViewerInput::Kind::Orbit);
  EXPECT_EQ(in[1].dx, 40.0f);
  EXPECT_EQ(in[1].dy, -10.0f);
  EXPECT_EQ(in[2].kind, ViewerInput::Kind::Pan);
  EXPECT_EQ(in[2].dx, 2.5f);
  EXPECT_EQ(in[3].kind, ViewerInput::Kind::Zoom);
  EXPECT_EQ(in[3].dy, -2.0f);
  EXPECT_EQ(in[4].kind, ViewerInput::Kind::Fly);
  EXPECT_EQ(in[4].axes.x, 1.0f);  // D: right
  EXPECT_EQ(in[4].axes.y, 0.0f);
  EXPECT_EQ(in[4].axes.z, 1.0f);  // W: forward
  EXPECT_EQ(in[4].seconds, 0.5f);
  EXPECT_EQ(in[5].kind, ViewerInput::Kind::Key);
  EXPECT_EQ(in[5].key, 'P');  // letters upper-cased
  EXPECT_EQ(in[6].key, '[');
}

TEST(ViewerScript, FlyAxesOfOpposingKeysCancel) {
  glm::vec3 a;
  ASSERT_TRUE(flyAxes("wsqe", &a));
  EXPECT_EQ(a.x, 0.0f);
  EXPECT_EQ(a.y, 0.0f);
  EXPECT_EQ(a.z, 0.0f);
  ASSERT_TRUE(flyAxes("AQ", &a));
  EXPECT_EQ(a.x, -1.0f);
  EXPECT_EQ(a.y, -1.0f);
  EXPECT_FALSE(flyAxes("WX", &a));
}

std::string errorOf(const std::string& text) {
  try {
    parseViewerScript(text, "s.txt");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ViewerScript, EachMistakeIsOneLineNamingTheLine) {
  EXPECT_EQ(errorOf("frames 1\njump 3\n"), "s.txt:2: unknown input 'jump' (inputs: key, drag, scroll, hold, frames)");
  EXPECT_EQ(errorOf("key X"), "s.txt:1: unknown key 'X' (keys: 1 2 3 [ ] P R H F)");
  EXPECT_EQ(errorOf("key"), "s.txt:1: expected 'key K'");
  EXPECT_EQ(errorOf("drag middle 1 2"), "s.txt:1: the drag button must be left or right, got 'middle'");
  EXPECT_EQ(errorOf("drag left 1"), "s.txt:1: expected 'drag left|right DX DY'");
  EXPECT_EQ(errorOf("drag left 1 2x"), "s.txt:1: DY must be a number, got '2x'");
  EXPECT_EQ(errorOf("scroll nan"), "s.txt:1: DY must be a number, got 'nan'");
  EXPECT_EQ(errorOf("hold WZ 1"), "s.txt:1: hold takes the flying keys W A S D Q E, got 'WZ'");
  EXPECT_EQ(errorOf("hold W -1"), "s.txt:1: SECONDS must be at least 0, got '-1'");
  EXPECT_EQ(errorOf("frames 0"), "s.txt:1: N must be a whole number from 1 to 1000000, got '0'");
  EXPECT_EQ(errorOf("frames 1.5"), "s.txt:1: N must be a whole number from 1 to 1000000, got '1.5'");
}

TEST(ViewerScript, MissingFileIsAnInputError) {
  try {
    readViewerScript("/nonexistent/script.txt");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/script.txt: cannot open the script");
  }
}

}  // namespace
}  // namespace narval

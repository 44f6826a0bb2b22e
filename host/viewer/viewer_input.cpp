#include "viewer/viewer_input.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/input_error.h"

namespace narval {
namespace {

// A finite number filling the whole word, or throws "NAME:LINE: WHAT must be a number, got 'W'".
float number(const std::string& word, const std::string& what, const std::string& where) {
  size_t used = 0;
  float v = 0;
  try {
    v = std::stof(word, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != word.size() || !std::isfinite(v))
    throw InputError(where + ": " + what + " must be a number, got '" + word + "'");
  return v;
}

}  // namespace

bool isViewerKey(char key) {
  switch (std::toupper(static_cast<unsigned char>(key))) {
    case '1': case '2': case '3': case '[': case ']': case 'P': case 'R': case 'H': case 'F': return true;
    default: return false;
  }
}

bool flyAxes(const std::string& keys, glm::vec3* axes) {
  glm::vec3 a{0, 0, 0};
  for (const char c : keys) {
    switch (std::toupper(static_cast<unsigned char>(c))) {
      case 'W': a.z += 1; break;
      case 'S': a.z -= 1; break;
      case 'D': a.x += 1; break;
      case 'A': a.x -= 1; break;
      case 'E': a.y += 1; break;
      case 'Q': a.y -= 1; break;
      default: return false;
    }
  }
  *axes = a;
  return true;
}

std::vector<ViewerInput> parseViewerScript(const std::string& text, const std::string& name) {
  std::vector<ViewerInput> inputs;
  std::istringstream lines(text);
  std::string line;
  for (int number_ = 1; std::getline(lines, line); ++number_) {
    const std::string where = name + ":" + std::to_string(number_);
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream in(line);
    std::vector<std::string> w;
    for (std::string word; in >> word;) w.push_back(word);
    if (w.empty()) continue;
    auto expect = [&](size_t count, const char* usage) {
      if (w.size() != count) throw InputError(where + ": expected '" + usage + "'");
    };
    ViewerInput v;
    if (w[0] == "key") {
      expect(2, "key K");
      if (w[1].size() != 1 || !isViewerKey(w[1][0]))
        throw InputError(where + ": unknown key '" + w[1] + "' (keys: 1 2 3 [ ] P R H F)");
      v.kind = ViewerInput::Kind::Key;
      v.key = char(std::toupper(static_cast<unsigned char>(w[1][0])));
    } else if (w[0] == "drag") {
      expect(4, "drag left|right DX DY");
      if (w[1] != "left" && w[1] != "right")
        throw InputError(where + ": the drag button must be left or right, got '" + w[1] + "'");
      v.kind = w[1] == "left" ? ViewerInput::Kind::Orbit : ViewerInput::Kind::Pan;
      v.dx = number(w[2], "DX", where);
      v.dy = number(w[3], "DY", where);
    } else if (w[0] == "scroll") {
      expect(2, "scroll DY");
      v.kind = ViewerInput::Kind::Zoom;
      v.dy = number(w[1], "DY", where);
    } else if (w[0] == "hold") {
      expect(3, "hold KEYS SECONDS");
      if (!flyAxes(w[1], &v.axes))
        throw InputError(where + ": hold takes the flying keys W A S D Q E, got '" + w[1] + "'");
      v.kind = ViewerInput::Kind::Fly;
      v.seconds = number(w[2], "SECONDS", where);
      if (v.seconds < 0) throw InputError(where + ": SECONDS must be at least 0, got '" + w[2] + "'");
    } else if (w[0] == "frames") {
      expect(2, "frames N");
      const float n = number(w[1], "N", where);
      if (n < 1 || n != std::floor(n) || n > 1e6f)
        throw InputError(where + ": N must be a whole number from 1 to 1000000, got '" + w[1] + "'");
      v.kind = ViewerInput::Kind::Frames;
      v.frames = int(n);
    } else {
      throw InputError(where + ": unknown input '" + w[0] + "' (inputs: key, drag, scroll, hold, frames)");
    }
    inputs.push_back(v);
  }
  return inputs;
}

std::vector<ViewerInput> readViewerScript(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw inputError(path, "", "cannot open the script");
  std::ostringstream text;
  text << in.rdbuf();
  return parseViewerScript(text.str(), path);
}

}  // namespace narval

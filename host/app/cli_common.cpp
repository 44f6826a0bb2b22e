#include "app/cli_common.h"

#include <cstdio>
#include <regex>

#include "image/atomic_file.h"
#include "scene/input_error.h"

namespace narval {

std::pair<int, int> parseSize(const std::string& text, const std::string& what) {
  std::smatch m;
  static const std::regex re(R"(^(\d{1,6})x(\d{1,6})$)");
  if (!std::regex_match(text, m, re) || std::stoi(m[1]) == 0 || std::stoi(m[2]) == 0)
    throw inputError(what, "", "expected WIDTHxHEIGHT with positive integers, got '" + text + "'");
  return {std::stoi(m[1]), std::stoi(m[2])};
}

std::string resolutionOverride(const std::string& text) {
  const auto [w, h] = parseSize(text, "--resolution");
  return "renderer.resolution=[" + std::to_string(w) + "," + std::to_string(h) + "]";
}

}  // namespace narval

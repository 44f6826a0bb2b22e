// json_override.cpp: see json_override.h.
#include "scene/json_override.h"

#include <vector>

#include "core/input_error.h"
#include "scene/json_reader.h"

namespace narval::scene_detail {

namespace {

struct Segment {
  std::string text;
  bool bracketed = false;  // written as [n]: an array index only
};

bool isIndex(const std::string& s) {
  return !s.empty() && s.size() <= 9 && s.find_first_not_of("0123456789") == std::string::npos;
}

// "a.b[2].c" -> a, b, [2], c. Empty result on malformed paths ("a..b", "a[x]", "").
std::vector<Segment> splitPath(const std::string& path) {
  std::vector<Segment> out;
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '[') {
      const size_t close = path.find(']', i);
      if (close == std::string::npos) return {};
      Segment s{path.substr(i + 1, close - i - 1), true};
      if (!isIndex(s.text)) return {};
      out.push_back(s);
      i = close + 1;
      if (i < path.size() && path[i] != '.' && path[i] != '[') return {};
      if (i < path.size() && path[i] == '.') {
        ++i;
        if (i == path.size()) return {};
      }
      continue;
    }
    const size_t end = path.find_first_of(".[", i);
    const std::string name = path.substr(i, end == std::string::npos ? std::string::npos : end - i);
    if (name.empty()) return {};
    out.push_back({name, false});
    if (end == std::string::npos) break;
    i = end;
    if (path[i] == '.') {
      ++i;
      if (i == path.size()) return {};
    }
  }
  return out;
}

}  // namespace

std::string applyOverride(nlohmann::json& doc, const std::string& spec, const std::string& file) {
  const size_t eq = spec.find('=');
  const std::string path = eq == std::string::npos ? spec : spec.substr(0, eq);
  const std::vector<Segment> segments = splitPath(path);
  if (eq == std::string::npos || segments.empty())
    throw inputError(file, "--set " + spec, "expected PATH=VALUE, e.g. renderer.spp=16");

  // Anything that is not JSON is a bare string, so "--set renderer.algorithm=lobe" needs no quotes.
  nlohmann::json value = nlohmann::json::parse(spec.substr(eq + 1), nullptr, false);
  if (value.is_discarded()) value = spec.substr(eq + 1);

  const auto noSuchKey = [&]() { return inputError(file, "--set " + path, "no such key"); };
  nlohmann::json* node = &doc;
  std::string key;
  for (size_t i = 0; i < segments.size(); ++i) {
    const Segment& seg = segments[i];
    if (node->is_object() && !seg.bracketed) {
      key = childKey(key, seg.text);
      if (!node->contains(seg.text)) {
        const bool last = i + 1 == segments.size();
        // A new object can be made for a name, not for an array index.
        if (!last && (segments[i + 1].bracketed || isIndex(segments[i + 1].text))) throw noSuchKey();
        (*node)[seg.text] = last ? value : nlohmann::json::object();
      }
      node = &(*node)[seg.text];
    } else if (node->is_array() && isIndex(seg.text)) {
      const size_t index = std::stoul(seg.text);
      if (index >= node->size()) throw noSuchKey();
      key = indexKey(key, index);
      node = &(*node)[index];
    } else {
      throw noSuchKey();
    }
  }
  *node = value;
  return key;
}

}  // namespace narval::scene_detail

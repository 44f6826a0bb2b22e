// scene_path.cpp: see scene_path.h.
#include "scene/scene_path.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>

#include "core/input_error.h"

namespace narval::scene_detail {

namespace fs = std::filesystem;

namespace {

constexpr size_t kMaxPathLength = 4096;

bool isNameChar(char c, bool first) {
  return c == '_' || std::isalpha(static_cast<unsigned char>(c)) ||
         (!first && std::isdigit(static_cast<unsigned char>(c)));
}

// Index of the '}' closing the reference whose body starts at `from`, allowing nested ${...}.
size_t findClose(const std::string& text, size_t from) {
  int depth = 1;
  for (size_t i = from; i < text.size(); ++i) {
    if (text[i] == '$' && i + 1 < text.size() && text[i + 1] == '{') {
      ++depth;
      ++i;
    } else if (text[i] == '}' && --depth == 0) {
      return i;
    }
  }
  return std::string::npos;
}

// For a path that was not found: what its first ${NAME} reference says to check, "" without one.
std::string variableHint(const std::string& raw) {
  const size_t at = raw.find("${");
  if (at == std::string::npos) return "";
  size_t n = at + 2;
  while (n < raw.size() && isNameChar(raw[n], n == at + 2)) ++n;
  const std::string name = raw.substr(at + 2, n - at - 2);
  if (name.empty()) return "";
  const char* value = std::getenv(name.c_str());
  if (value && *value) return " (from " + name + "=" + value + ")";
  return " (" + name + " is not set: set it to the folder that holds the file)";
}

}  // namespace

std::string expandEnvironment(const std::string& text, const std::string& file, const std::string& key) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    if (text[i] != '$' || i + 1 >= text.size() || text[i + 1] != '{') {
      out += text[i++];
      continue;
    }
    const size_t close = findClose(text, i + 2);
    if (close == std::string::npos) throw inputError(file, key, "unterminated ${ in \"" + text + "\"");
    const std::string body = text.substr(i + 2, close - i - 2);
    size_t n = 0;
    while (n < body.size() && isNameChar(body[n], n == 0)) ++n;
    const std::string name = body.substr(0, n);
    const bool hasDefault = body.compare(n, 2, ":-") == 0;
    if (name.empty() || (n != body.size() && !hasDefault))
      throw inputError(file, key,
                       "bad variable reference ${" + body + "} (expected ${NAME} or ${NAME:-default})");
    const char* env = std::getenv(name.c_str());
    if (env && *env) {
      out += env;
    } else if (hasDefault) {
      out += expandEnvironment(body.substr(n + 2), file, key);
    } else {
      throw inputError(file, key,
                       "environment variable " + name + " is not set (write ${" + name +
                           ":-default} to give a fallback)");
    }
    i = close + 1;
  }
  return out;
}

std::string resolveVolumePath(const std::string& raw, const std::string& sceneFile,
                              const std::string& key) {
  if (raw.empty()) throw inputError(sceneFile, key, "must not be empty (leave it out for a homogeneous medium)");
  // No file name is longer (PATH_MAX), and expanding a long chain of nested ${...} costs time and
  // memory quadratic in its length.
  if (raw.size() > kMaxPathLength)
    throw inputError(sceneFile, key, "must be at most " + std::to_string(kMaxPathLength) +
                                         " characters long, got " + std::to_string(raw.size()));
  fs::path p = expandEnvironment(raw, sceneFile, key);
  // Relative to the scene file, not the working directory, so scenes can be run from anywhere.
  if (p.is_relative()) p = fs::absolute(fs::path(sceneFile)).parent_path() / p;
  const std::string resolved = p.lexically_normal().string();

  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".vdb" && ext != ".vol")
    throw inputError(sceneFile, key,
                     "unsupported volume file type \"" + p.extension().string() + "\" (allowed: .vdb, .vol): " + resolved);
  std::error_code ec;
  const fs::file_status status = fs::status(resolved, ec);
  if (!fs::exists(status)) throw inputError(sceneFile, key, "volume file not found: " + resolved + variableHint(raw));
  if (!fs::is_regular_file(status)) throw inputError(sceneFile, key, "volume path is not a file: " + resolved);
  return resolved;
}

}  // namespace narval::scene_detail

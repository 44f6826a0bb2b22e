#include "app/cli_common.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <regex>

#include "core/atomic_file.h"
#include "core/input_error.h"
#include "core/near_miss.h"

namespace narval {

std::pair<int, int> parseSize(const std::string& text, const std::string& what) {
  std::smatch m;
  static const std::regex re(R"(^(\d{1,6})x(\d{1,6})$)");
  if (!std::regex_match(text, m, re) || std::stoi(m[1]) == 0 || std::stoi(m[2]) == 0)
    throw inputError(what, "", "expected WIDTHxHEIGHT with positive integers, got '" + text + "'");
  return {std::stoi(m[1]), std::stoi(m[2])};
}

std::pair<int, int> parseSampleRange(const std::string& text, const std::string& what) {
  std::smatch m;
  static const std::regex re(R"(^(\d{1,10}):(\d{1,10})$)");
  if (std::regex_match(text, m, re)) {
    const long long a = std::stoll(m[1]), b = std::stoll(m[2]);
    if (a < b && b <= 0x7fffffffLL) return {int(a), int(b)};
  }
  throw inputError(what, "", "expected A:B, the sample indices [A, B) with 0 <= A < B <= 2147483647, got '" + text + "'");
}

std::string resolutionOverride(const std::string& text) {
  const auto [w, h] = parseSize(text, "--resolution");
  return "renderer.resolution=[" + std::to_string(w) + "," + std::to_string(h) + "]";
}

namespace {
// Reads the integer in `text`; false when it is not one (CLI11 validates the text before converting).
bool parseInteger(const std::string& text, long long* out) {
  static const std::regex re(R"(^[+-]?\d{1,18}$)");
  if (!std::regex_match(text, re)) return false;
  *out = std::stoll(text);
  return true;
}
}  // namespace

CLI::Validator atLeast(long long min) {
  return CLI::Validator(
      [min](std::string& text) -> std::string {
        long long v = 0;
        if (!parseInteger(text, &v)) return "expected an integer, got '" + text + "'";
        if (v < min) return "must be at least " + std::to_string(min) + ", got " + text;
        // The options it checks are ints: a larger value would fail CLI11's conversion, unnamed.
        if (v > std::numeric_limits<int>::max())
          return "must be at most " + std::to_string(std::numeric_limits<int>::max()) + ", got " + text;
        return std::string();
      },
      "INT >= " + std::to_string(min));
}

CLI::Validator between(long long min, long long max) {
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        long long v = 0;
        if (!parseInteger(text, &v)) return "expected an integer, got '" + text + "'";
        return v < min || v > max
                   ? "must be between " + std::to_string(min) + " and " + std::to_string(max) + ", got " + text
                   : std::string();
      },
      "INT in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
}

CLI::Validator greaterThanZero() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0') return "expected a number, got '" + text + "'";
        return v > 0 && std::isfinite(v) ? std::string() : "must be a finite number greater than 0, got " + text;
      },
      "NUMBER > 0");
}

void addThreadsOption(CLI::App* sub) {
  sub->add_option_function<int>(
         "--threads",
         [](const int& n) {
           // PoCL reads its thread count once, when the platform is first created (narval opens no
           // device before the command runs). POCL_CPU_MAX_CU_NUM is the name newer PoCL reads.
           const std::string v = std::to_string(n);
           setenv("POCL_MAX_PTHREAD_COUNT", v.c_str(), 1);
           setenv("POCL_CPU_MAX_CU_NUM", v.c_str(), 1);
         },
         "Worker threads of a PoCL CPU device (sets POCL_MAX_PTHREAD_COUNT; default: one per core; other "
         "OpenCL drivers ignore it)")
      ->check(between(1, 4096));
}

void checkOutputWritable(const std::string& path, const std::string& option) {
  namespace fs = std::filesystem;
  if (path.empty()) return;
  const fs::path p(path);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw inputError(option, "", "cannot write " + path + ": it is a folder");
  if (p.has_parent_path()) {
    fs::create_directories(p.parent_path(), ec);
    if (ec) throw inputError(option, "", "cannot write " + path + ": cannot create its folder: " + ec.message());
  }
  try {
    AtomicFile probe(path);  // a temporary beside `path`; destroyed uncommitted, it is removed
  } catch (const std::exception& e) {
    std::string reason = e.what();
    const std::string prefix = path + ": cannot write: ";
    if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
    throw inputError(option, "", "cannot write " + path + ": " + reason);
  }
}

void checkLocalSize(int lx, int ly, const cl::Device& device, const std::string& deviceName) {
  const size_t items = size_t(lx) * size_t(ly);
  const size_t most = device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
  const std::vector<size_t> sides = device.getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
  const std::string shape = std::to_string(lx) + "x" + std::to_string(ly);
  if (items > most)
    throw inputError("--local-size", "", shape + " is " + std::to_string(items) + " work-items; " + deviceName +
                                             " takes at most " + std::to_string(most) + " per group");
  for (size_t i = 0; i < 2 && i < sides.size(); ++i)
    if (size_t(i == 0 ? lx : ly) > sides[i])
      throw inputError("--local-size", "", shape + ": " + deviceName + " takes at most " + std::to_string(sides[i]) +
                                               " work-items along " + (i == 0 ? "x" : "y"));
}

std::string unknownFlag(const CLI::App& app, int argc, char** argv) {
  const CLI::App* sub = nullptr;
  for (const CLI::App* c : app.get_subcommands())
    if (c->parsed()) sub = c;
  std::vector<std::string> names;  // the command's long flags, without their dashes
  if (sub)
    for (const CLI::Option* o : sub->get_options())
      for (const std::string& n : o->get_lnames()) names.push_back(n);
  const std::string help = sub ? "narval " + sub->get_name() + " --help" : "narval --help";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-' || std::isdigit(static_cast<unsigned char>(arg[1])) || arg[1] == '.')
      continue;  // a value ("--exposure -2"), not a flag
    const std::string bare = arg.substr(arg.find_first_not_of('-'), arg.find('=') - arg.find_first_not_of('-'));
    bool known = false, singleDash = arg[1] != '-';
    std::string meant;
    for (const std::string& n : names) {
      if (n == bare) known = !singleDash, meant = n;
      if (meant.empty() && (nearMiss(bare, n) || (bare.size() >= 3 && n.rfind(bare, 0) == 0))) meant = n;
    }
    if (known || (!singleDash && arg.size() == 2)) continue;
    if (singleDash && sub)  // -q and other one-letter flags are the parser's; "-spp" is a typo
      for (const CLI::Option* o : sub->get_options())
        for (const std::string& n : o->get_snames())
          if (arg == "-" + n) known = true;
    if (known) continue;
    return arg + ": unknown flag" + (meant.empty() ? " (see " + help + ")" : " (did you mean --" + meant + "?)");
  }
  return "";
}

}  // namespace narval

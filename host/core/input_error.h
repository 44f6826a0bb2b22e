// input_error.h: bad input from the user (scene, grid, image, command line). The CLI prints
// what() as one line and exits with code 2 (DESIGN.md, command line).
#pragma once

#include <stdexcept>
#include <string>

namespace narval {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "FILE: KEY: message" (KEY omitted when empty): the one shape every input error has. Always one
// line: control characters that came from the input (a newline in a JSON string or a file name)
// are written as escapes, \n \r \t or \xHH.
inline InputError inputError(const std::string& file, const std::string& key, const std::string& what) {
  const std::string line = key.empty() ? file + ": " + what : file + ": " + key + ": " + what;
  std::string out;
  for (const char c : line) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) out += c;
    else if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else out += std::string{'\\', 'x', "0123456789abcdef"[u >> 4], "0123456789abcdef"[u & 15]};
  }
  return InputError(out);
}

// A library's own message (OpenVDB's, OpenEXR's) quoted inside one of ours: one line of printable
// ASCII, blanks collapsed, at most 160 characters. A corrupt file's bytes can reach such messages
// (OpenVDB's "Map is not registered" names the map type it read).
inline std::string oneLine(const std::string& what) {
  std::string out;
  for (const char c : what) {
    const unsigned char u = static_cast<unsigned char>(c);
    const bool printable = u > 0x20 && u < 0x7f;
    if (printable) out += c;
    else if (!out.empty() && out.back() != ' ') out += ' ';
    if (out.size() >= 160) return out + "...";
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace narval

// input_error.h: bad input from the user (scene, grid, image, command line). The CLI prints
// what() as one line and exits with code 2 (DESIGN.md, command line).
#pragma once

#include <stdexcept>
#include <string>

namespace narval {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "FILE: KEY: message" (KEY omitted when empty): the one shape every input error has.
inline InputError inputError(const std::string& file, const std::string& key, const std::string& what) {
  return InputError(key.empty() ? file + ": " + what : file + ": " + key + ": " + what);
}

}  // namespace narval

// fuzz_check.h: the contract both fuzz targets check. Bad input ends in narval::InputError whose
// message is one line starting with "FILE: " (input_error.h); anything else is a finding: another
// exception escapes LLVMFuzzerTestOneInput (std::terminate), or fuzz_fail aborts.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/input_error.h"

namespace narval::fuzz {

[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz contract broken: %s\n", what.c_str());
  std::abort();
}

inline void checkInputError(const InputError& e, const std::string& file) {
  const std::string message = e.what();
  if (message.rfind(file + ": ", 0) != 0) fail("InputError does not start with \"" + file + ": \": " + message);
  if (message.find('\n') != std::string::npos) fail("InputError spans several lines: " + message);
}

}  // namespace narval::fuzz

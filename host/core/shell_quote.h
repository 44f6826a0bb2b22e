// shell_quote.h: one argument as a POSIX shell reads it back (for the command line an EXR records
// and the scripts `narval farm` writes).
#pragma once

#include <string>
#include <vector>

namespace narval {

// Bare when every character is safe in a shell word, else in single quotes ('\'' for a quote).
std::string shellQuoted(const std::string& arg);
// The arguments quoted and joined by spaces.
std::string shellJoined(const std::vector<std::string>& args);

}  // namespace narval

// near_miss.h: whether a name is a typo of another, for messages that suggest the name meant (an
// unknown scene key, an unknown command-line flag).
#pragma once

#include <string>

namespace narval {

// True when `a` and `b` differ only by letter case or by one edit (a letter inserted, deleted,
// replaced, or two neighbours swapped), after case is ignored.
bool nearMiss(const std::string& a, const std::string& b);

std::string lowercase(std::string s);

}  // namespace narval

#include "core/near_miss.h"

#include <cctype>
#include <utility>

namespace narval {

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool nearMiss(const std::string& a, const std::string& b) {
  std::string x = lowercase(a), y = lowercase(b);
  if (x == y) return true;
  if (x.size() > y.size()) std::swap(x, y);
  if (y.size() - x.size() > 1) return false;
  size_t i = 0;
  while (i < x.size() && x[i] == y[i]) ++i;  // the first difference
  if (x.size() < y.size()) return x.compare(i, std::string::npos, y, i + 1, std::string::npos) == 0;  // insertion
  if (x.compare(i + 1, std::string::npos, y, i + 1, std::string::npos) == 0) return true;            // replacement
  return i + 1 < x.size() && x[i] == y[i + 1] && x[i + 1] == y[i] &&                                 // swap
         x.compare(i + 2, std::string::npos, y, i + 2, std::string::npos) == 0;
}

}  // namespace narval

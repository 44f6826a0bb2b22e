// number_format.h: numbers as narval writes them in tables, files and messages.
#pragma once

#include <string>

namespace narval {

// printf's "%.*f": `digits` after the point ("0.125", "12.50").
std::string formatFixed(double v, int digits);
// The fewest significant digits (1 to 17) that read back as the same double.
std::string formatShortest(double v);
// The fewest significant digits (1 to 9) that read back as the same float.
std::string formatShortest(float v);

}  // namespace narval

#pragma once

#include <cstdio>
#include <string>

namespace stcalib {

// Up to four numbers printed into `format` (a printf format whose conversions all take doubles;
// unused arguments are ignored), for the reasons and messages the verdict and the check write.
inline std::string FormatNumbers(const char* format, double a, double b = 0, double c = 0,
                                 double d = 0) {
  char text[512];
  std::snprintf(text, sizeof(text), format, a, b, c, d);
  return text;
}

}  // namespace stcalib

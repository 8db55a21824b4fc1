#pragma once
// Numbers in messages: as a user typed them ("5", "0.15", "1.6e-08"), not
// std::to_string's fixed six decimals ("5.000000", "0.000000").
#include <cstdio>
#include <string>

namespace exsynth {

inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace exsynth

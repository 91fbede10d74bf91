// Number formatting for messages: shortest form that reads naturally ("-1", "0.25", "1e-09").
#pragma once

#include <cstdio>
#include <string>

namespace homesh {

inline std::string formatNumber(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

}  // namespace homesh

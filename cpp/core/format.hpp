// Formatting for messages: numbers in their shortest natural form ("-1", "0.25", "1e-09"), lists
// joined with commas, and text from files made safe to quote in a one-line message.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace homesh {

inline std::string formatNumber(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

// "a, b, c": the words of a list in a message.
inline std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

// At most `max` characters of `text`, control characters (newlines included) shown as '?', and
// "..." where it was cut: a file's content quoted in an error stays on one line.
inline std::string excerpt(const std::string& text, std::size_t max = 40) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out += c < 0x20 || c == 0x7f ? '?' : text[i];
  }
  if (text.size() > max) out += "...";
  return out;
}

}  // namespace homesh

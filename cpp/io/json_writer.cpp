#include "io/json_writer.hpp"

#include <cmath>
#include <cstdio>

#include "core/error.hpp"

namespace homesh {

std::string jsonQuote(const std::string& s) {
  std::string q = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        q += "\\\"";
        break;
      case '\\':
        q += "\\\\";
        break;
      case '\n':
        q += "\\n";
        break;
      case '\t':
        q += "\\t";
        break;
      case '\r':
        q += "\\r";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          q += buf;
        } else {
          q += ch;
        }
    }
  }
  return q + "\"";
}

namespace {

std::string numberText(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

template <typename T, typename Format>
std::string inlineArray(const std::vector<T>& v, Format format) {
  std::string text = "[";
  for (std::size_t k = 0; k < v.size(); ++k) text += (k ? ", " : "") + format(v[k]);
  return text + "]";
}

}  // namespace

void JsonWriter::prefix(const std::string& key) {
  if (!first_.empty()) {
    if (!first_.back()) out_ += ",";
    first_.back() = false;
    out_ += "\n" + std::string(2 * first_.size(), ' ');
  }
  if (!key.empty()) out_ += jsonQuote(key) + ": ";
}

void JsonWriter::raw(const std::string& key, const std::string& text) {
  prefix(key);
  out_ += text;
}

JsonWriter& JsonWriter::open(const std::string& key, char bracket) {
  raw(key, std::string(1, bracket));
  first_.push_back(true);
  return *this;
}

JsonWriter& JsonWriter::close(char bracket) {
  if (first_.empty()) throw Error(std::string("JsonWriter: '") + bracket + "' closes nothing");
  const bool empty = first_.back();
  first_.pop_back();
  if (!empty) out_ += "\n" + std::string(2 * first_.size(), ' ');
  out_ += bracket;
  if (first_.empty()) out_ += "\n";
  return *this;
}

JsonWriter& JsonWriter::beginObject(const std::string& key) {
  return open(key, '{');
}
JsonWriter& JsonWriter::endObject() {
  return close('}');
}
JsonWriter& JsonWriter::beginArray(const std::string& key) {
  return open(key, '[');
}
JsonWriter& JsonWriter::endArray() {
  return close(']');
}

JsonWriter& JsonWriter::value(const std::string& key, double v) {
  raw(key, numberText(v));
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& key, long long v) {
  raw(key, std::to_string(v));
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& key, bool v) {
  raw(key, v ? "true" : "false");
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& key, const std::string& v) {
  raw(key, jsonQuote(v));
  return *this;
}

JsonWriter& JsonWriter::numbers(const std::string& key, const std::vector<double>& v) {
  raw(key, inlineArray(v, numberText));
  return *this;
}

JsonWriter& JsonWriter::numbers(const std::string& key, const std::vector<std::size_t>& v) {
  raw(key, inlineArray(v, [](std::size_t n) { return std::to_string(n); }));
  return *this;
}

}  // namespace homesh

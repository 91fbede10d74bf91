// A minimal streaming JSON writer (objects, arrays, strings, numbers, booleans) with two-space
// indentation. Numbers are written with up to 15 significant digits; NaN and infinity as null.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace homesh {

class JsonWriter {
 public:
  JsonWriter& beginObject(const std::string& key = {});
  JsonWriter& endObject();
  JsonWriter& beginArray(const std::string& key = {});
  JsonWriter& endArray();
  JsonWriter& value(const std::string& key, double v);
  JsonWriter& value(const std::string& key, long long v);
  JsonWriter& value(const std::string& key, std::size_t v) {
    return value(key, static_cast<long long>(v));
  }
  JsonWriter& value(const std::string& key, int v) { return value(key, static_cast<long long>(v)); }
  JsonWriter& value(const std::string& key, bool v);
  JsonWriter& value(const std::string& key, const std::string& v);
  JsonWriter& value(const std::string& key, const char* v) { return value(key, std::string(v)); }
  // Array elements use an empty key.
  // A short array of numbers on one line (histogram edges and counts).
  JsonWriter& numbers(const std::string& key, const std::vector<double>& v);
  JsonWriter& numbers(const std::string& key, const std::vector<std::size_t>& v);
  const std::string& str() const { return out_; }

 private:
  JsonWriter& open(const std::string& key, char bracket);
  JsonWriter& close(char bracket);
  void prefix(const std::string& key);
  void raw(const std::string& key, const std::string& text);
  std::string out_;
  std::vector<bool> first_;  // per open container: no element written yet
};

std::string jsonQuote(const std::string& s);

}  // namespace homesh

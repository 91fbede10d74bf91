// A position in a whole file read into memory, for the readers of formats that mix text and
// binary blocks (Gmsh's MSH, legacy VTK): white-space separated words, the rest of a line, and
// the line number for messages. Each reader derives its cursor from this one and adds its own
// numbers, binary values and error messages (which name the format).
#pragma once

#include <cctype>
#include <cstddef>
#include <string>
#include <utility>

namespace homesh {

class TextCursor {
 public:
  explicit TextCursor(std::string data) : data_(std::move(data)) {}

  // Whether only white space is left (skipped).
  bool atEnd() {
    skipSpace();
    return pos_ >= data_.size();
  }
  void skipSpace() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_])) != 0) {
      if (data_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  // The next white-space separated word ("" at the end of the data).
  std::string word() {
    skipSpace();
    const std::size_t start = pos_;
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_])) == 0)
      ++pos_;
    return data_.substr(start, pos_ - start);
  }
  // The next word, left to be read again.
  std::string peekWord() {
    const std::size_t pos = pos_;
    const int line = line_;
    std::string w = word();
    pos_ = pos;
    line_ = line;
    return w;
  }
  // The rest of the current line without its line break (LF or CR LF), and the cursor on the
  // next line: before a binary block, whose bytes may look like white space, this consumes
  // exactly the keyword's line.
  std::string restOfLine() {
    const std::size_t start = pos_;
    while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
    std::string s = data_.substr(start, pos_ - start);
    if (!s.empty() && s.back() == '\r') s.pop_back();
    if (pos_ < data_.size()) {
      ++pos_;
      ++line_;
    }
    return s;
  }
  void endOfLine() { restOfLine(); }

  std::size_t position() const { return pos_; }  // bytes from the start
  int line() const { return line_; }             // from 1

 protected:
  std::string data_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

}  // namespace homesh

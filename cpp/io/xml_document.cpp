#include "io/xml_document.hpp"

#include <cctype>
#include <cstring>
#include <utility>

#include "core/error.hpp"
#include "core/format.hpp"

namespace homesh {

const XmlElement* XmlElement::child(const std::string& childName) const {
  for (const auto& c : children)
    if (c->name == childName) return c.get();
  return nullptr;
}

std::vector<const XmlElement*> XmlElement::childrenNamed(const std::string& childName) const {
  std::vector<const XmlElement*> out;
  for (const auto& c : children)
    if (c->name == childName) out.push_back(c.get());
  return out;
}

std::string XmlElement::attribute(const std::string& key, const std::string& fallback) const {
  const auto it = attributes.find(key);
  return it == attributes.end() ? fallback : it->second;
}

namespace {

class Parser {
 public:
  Parser(const std::string& text, std::string source) : s_(text), source_(std::move(source)) {}

  std::unique_ptr<XmlElement> document() {
    skipMisc();
    if (!startsWith("<")) fail("no root element");
    auto root = element();
    skipMisc();
    if (pos_ < s_.size()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    std::size_t line = 1;
    for (std::size_t i = 0; i < pos_ && i < s_.size(); ++i)
      if (s_[i] == '\n') ++line;
    throw IoError("'" + source_ + "' is not valid XML: " + what + ", line " + std::to_string(line));
  }
  bool startsWith(const char* t) const { return s_.compare(pos_, std::strlen(t), t) == 0; }
  void skipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])) != 0) ++pos_;
  }
  void skipTo(const char* end) {
    const std::size_t at = s_.find(end, pos_);
    if (at == std::string::npos) fail(std::string("'") + end + "' missing");
    pos_ = at + std::strlen(end);
  }
  // Declarations, comments and processing instructions between elements.
  void skipMisc() {
    for (;;) {
      skipSpace();
      if (startsWith("<?"))
        skipTo("?>");
      else if (startsWith("<!--"))
        skipTo("-->");
      else if (startsWith("<!"))
        skipTo(">");
      else
        return;
    }
  }
  std::string name() {
    const std::size_t start = pos_;
    while (pos_ < s_.size() &&
           (std::isalnum(static_cast<unsigned char>(s_[pos_])) != 0 || s_[pos_] == '_' ||
            s_[pos_] == '-' || s_[pos_] == ':' || s_[pos_] == '.'))
      ++pos_;
    if (pos_ == start) fail("a name was expected");
    return s_.substr(start, pos_ - start);
  }
  std::string unescape(const std::string& raw) const {
    std::string out;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] != '&') {
        out += raw[i];
        continue;
      }
      const std::size_t semi = raw.find(';', i);
      if (semi == std::string::npos || semi - i > 8)
        fail("'&' does not start an entity (&lt; &gt; &amp; &quot; &apos;) near '" +
             excerpt(raw.substr(i, 12)) + "'");
      const std::string entity = raw.substr(i + 1, semi - i - 1);
      if (entity == "lt")
        out += '<';
      else if (entity == "gt")
        out += '>';
      else if (entity == "amp")
        out += '&';
      else if (entity == "quot")
        out += '"';
      else if (entity == "apos")
        out += '\'';
      else
        fail("unknown entity &" + excerpt(entity) + ";");
      i = semi;
    }
    return out;
  }
  // `depth`: elements open around this one. Nesting is bounded so that a hostile file cannot
  // exhaust the stack (our formats nest a handful of levels).
  std::unique_ptr<XmlElement> element(int depth = 0) {
    if (depth >= kMaxDepth) fail("elements are nested deeper than " + std::to_string(kMaxDepth));
    ++pos_;  // '<'
    auto e = std::make_unique<XmlElement>();
    e->name = name();
    for (;;) {
      skipSpace();
      if (startsWith("/>")) {
        pos_ += 2;
        return e;
      }
      if (startsWith(">")) {
        ++pos_;
        break;
      }
      const std::string key = name();
      skipSpace();
      if (!startsWith("=")) fail("'=' expected after attribute " + key);
      ++pos_;
      skipSpace();
      const char quote = pos_ < s_.size() ? s_[pos_] : '\0';
      if (quote != '"' && quote != '\'') fail("quoted value expected for attribute " + key);
      const std::size_t end = s_.find(quote, pos_ + 1);
      if (end == std::string::npos) fail("unterminated attribute " + key);
      e->attributes[key] = unescape(s_.substr(pos_ + 1, end - pos_ - 1));
      pos_ = end + 1;
    }
    for (;;) {  // content
      const std::size_t lt = s_.find('<', pos_);
      if (lt == std::string::npos) fail("element <" + e->name + "> is not closed");
      e->text += unescape(s_.substr(pos_, lt - pos_));
      pos_ = lt;
      if (startsWith("</")) {
        pos_ += 2;
        const std::string closing = name();
        if (closing != e->name) fail("</" + closing + "> closes <" + e->name + ">");
        skipSpace();
        if (!startsWith(">")) fail("'>' expected");
        ++pos_;
        return e;
      }
      if (startsWith("<!--")) {
        skipTo("-->");
      } else if (startsWith("<![CDATA[")) {
        const std::size_t start = pos_ + 9;
        skipTo("]]>");
        e->text += s_.substr(start, pos_ - 3 - start);
      } else if (startsWith("<?")) {
        skipTo("?>");
      } else {
        e->children.push_back(element(depth + 1));
      }
    }
  }

  static constexpr int kMaxDepth = 100;
  const std::string& s_;
  std::string source_;
  std::size_t pos_ = 0;
};

}  // namespace

std::unique_ptr<XmlElement> parseXml(const std::string& text, const std::string& source) {
  return Parser(text, source).document();
}

}  // namespace homesh

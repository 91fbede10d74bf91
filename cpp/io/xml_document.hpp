// A small XML reader (elements, attributes, text) for the XML formats HOMesh reads back: no
// namespaces, DTDs or entities beyond the five predefined ones. Comments, processing
// instructions and CDATA are skipped or kept as text as usual.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace homesh {

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;  // concatenated character data directly inside this element
  std::vector<std::unique_ptr<XmlElement>> children;

  // The first child with this name, or nullptr.
  const XmlElement* child(const std::string& childName) const;
  std::vector<const XmlElement*> childrenNamed(const std::string& childName) const;
  // The attribute's value, or `fallback`.
  std::string attribute(const std::string& key, const std::string& fallback = "") const;
  bool has(const std::string& key) const { return attributes.count(key) > 0; }
};

// Parses a whole document; throws IoError("'<source>' ...: what, line N") on malformed XML.
std::unique_ptr<XmlElement> parseXml(const std::string& text, const std::string& source);

}  // namespace homesh

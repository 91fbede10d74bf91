#include "io/mcf_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/input_file.hpp"
#include "io/xml_document.hpp"

namespace homesh {
namespace {

// Concatenates its arguments in one buffer (no temporaries per '+').
std::string cat(std::initializer_list<std::string_view> parts) {
  std::string out;
  for (const std::string_view p : parts) out += p;
  return out;
}

namespace fs = std::filesystem;

// Keys NekMesh reads, by section, and what HOMesh does with them.
const std::vector<std::string> kInformationKeys = {"CADFile", "MeshType"};
const std::vector<std::string> kNumberKeys = {"MinDelta", "MaxDelta", "EPS",  "Order", "Xmin",
                                              "Ymin",     "Xmax",     "Ymax", "AOA"};
const std::vector<std::string> kBoundaryLayerKeys = {
    "BndLayerSurfaces",   "BndLayerThickness", "BndLayerLayers", "BndLayerProgression",
    "BndLayerAdjustment", "SpaceOutBndLayer",  "NoSpaceOutSurf"};
const std::vector<std::string> kNacaKeys = {"Xmin", "Ymin", "Xmax", "Ymax", "AOA"};
// Known to NekMesh, not used by HOMesh yet.
const std::vector<std::string> kUnsupportedBoolKeys = {"SurfaceOptimiser", "VariationalOptimiser",
                                                       "BndLayerAdjustEverywhere", "SmoothBndLayer",
                                                       "WriteOctree"};
const std::vector<std::string> kUnsupportedSections = {"PERIODIC", "VOIDPOINTS"};
const std::vector<std::string> kMeshTypes = {"3D", "2D", "3DBndLayer", "2DBndLayer"};

bool contains(const std::vector<std::string>& list, const std::string& key) {
  return std::find(list.begin(), list.end(), key) != list.end();
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(const std::string& s) {
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  std::size_t b = 0, e = s.size();
  while (b < e && space(s[b])) ++b;
  while (e > b && space(s[e - 1])) --e;
  return s.substr(b, e - b);
}

// The whole (trimmed) text as a finite number, locale-independent; nullopt otherwise.
std::optional<double> toDouble(const std::string& text) {
  std::string t = trim(text);
  if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.erase(0, 1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (t.empty() || ec != std::errc() || end != t.data() + t.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

std::optional<int> toInt(const std::string& text) {
  std::string t = trim(text);
  if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.erase(0, 1);
  int value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (t.empty() || ec != std::errc() || end != t.data() + t.size()) return std::nullopt;
  return value;
}

// Numbers separated by whitespace and/or single commas ("1 2 3", "1,2,3", "1, 2, 3").
std::optional<std::vector<double>> toNumbers(const std::string& text) {
  std::vector<double> out;
  std::size_t i = 0;
  bool needNumber = false;  // just after a comma
  while (true) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i])) != 0) ++i;
    if (i == text.size()) break;
    if (text[i] == ',') {
      if (out.empty() || needNumber) return std::nullopt;
      needNumber = true;
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && text[j] != ',' &&
           std::isspace(static_cast<unsigned char>(text[j])) == 0)
      ++j;
    const auto v = toDouble(text.substr(i, j - i));
    if (!v) return std::nullopt;
    out.push_back(*v);
    needNumber = false;
    i = j;
  }
  if (needNumber) return std::nullopt;
  return out;
}

class Reader {
 public:
  explicit Reader(const std::string& path) : file_(fs::path(path).filename().string()) {
    case_.path = path;
  }

  McfCase read();

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw ParameterError(file_ + ": " + what);
  }
  void notice(const std::string& what) { case_.notices.push_back(file_ + ": " + what); }
  // "unknown SECTION key 'k' is ignored", with a hint when k differs from a known key only in
  // case or belongs to another section.
  void unknownKey(const std::string& section, const std::string& key,
                  const std::vector<std::string>& known);

  void readInformation(const XmlElement& section);
  void readParameters(const XmlElement& section);
  void readBoolParameters(const XmlElement& section);
  void readRefinement(const XmlElement& section);
  RefinementLine readLine(const XmlElement& line, const std::string& where);
  void validate();

  // The attribute or a ParameterError naming the element.
  std::string required(const XmlElement& e, const std::string& attribute,
                       const std::string& section) const;
  double number(const std::string& text, const std::string& where) const;

  std::string file_;
  McfCase case_;
  std::map<std::string, std::string> information_;
};

void Reader::unknownKey(const std::string& section, const std::string& key,
                        const std::vector<std::string>& known) {
  std::string line = "unknown " + section + " key '" + excerpt(key) + "' is ignored";
  for (const auto& k : known) {
    if (lower(k) == lower(key)) {
      notice(cat({line, "; did you mean '", k, "'? (keys are case-sensitive)"}));
      return;
    }
  }
  const std::vector<std::pair<std::string, std::vector<std::string>>> others = {
      {"INFORMATION", kInformationKeys},
      {"PARAMETERS",
       [] {
         auto all = kNumberKeys;
         all.insert(all.end(), kBoundaryLayerKeys.begin(), kBoundaryLayerKeys.end());
         return all;
       }()},
      {"BOOLPARAMETERS", kUnsupportedBoolKeys}};
  for (const auto& [name, keys] : others) {
    if (name == section) continue;
    for (const auto& k : keys) {
      if (lower(k) == lower(key)) {
        notice(cat({line, "; '", k, "' belongs in ", name}));
        return;
      }
    }
  }
  notice(line);
}

std::string Reader::required(const XmlElement& e, const std::string& attribute,
                             const std::string& section) const {
  if (!e.has(attribute)) fail(section + ": a <" + e.name + "> has no " + attribute + " attribute");
  return e.attribute(attribute);
}

double Reader::number(const std::string& text, const std::string& where) const {
  const auto v = toDouble(text);
  if (!v) fail(where + " must be a number, got '" + excerpt(trim(text)) + "'");
  return *v;
}

void Reader::readInformation(const XmlElement& section) {
  for (const auto& child : section.children) {
    if (child->name != "I") {
      notice("unknown element <" + excerpt(child->name) + "> in INFORMATION is ignored");
      continue;
    }
    const std::string key = required(*child, "PROPERTY", "INFORMATION");
    const std::string value = trim(required(*child, "VALUE", "INFORMATION"));
    if (!contains(kInformationKeys, key)) {
      unknownKey("INFORMATION", key, kInformationKeys);
      continue;
    }
    if (!information_.emplace(key, value).second) fail("INFORMATION " + key + " is given twice");
  }
}

void Reader::readParameters(const XmlElement& section) {
  std::set<std::string> seen;
  for (const auto& child : section.children) {
    if (child->name != "P") {
      notice("unknown element <" + excerpt(child->name) + "> in PARAMETERS is ignored");
      continue;
    }
    const std::string key = required(*child, "PARAM", "PARAMETERS");
    const std::string value = required(*child, "VALUE", "PARAMETERS");
    const bool numberKey = contains(kNumberKeys, key);
    const bool blKey = contains(kBoundaryLayerKeys, key);
    if (!numberKey && !blKey) {
      auto known = kNumberKeys;
      known.insert(known.end(), kBoundaryLayerKeys.begin(), kBoundaryLayerKeys.end());
      unknownKey("PARAMETERS", key, known);
      continue;
    }
    if (!seen.insert(key).second) fail("PARAMETERS " + key + " is given twice");
    const std::string where = "PARAMETERS " + key;
    if (blKey) {
      if (trim(value).empty()) fail(where + " is empty");
      case_.boundaryLayer[key] = trim(value);
      if (key == "BndLayerLayers") {
        const auto layers = toInt(value);
        if (!layers || *layers < 1)
          fail(where + " must be a positive integer, got '" + excerpt(trim(value)) + "'");
        case_.boundaryLayerLayers = *layers;
      } else if (key == "BndLayerProgression") {
        const double r = number(value, where);
        if (!(r > 0.0)) fail(where + " must be positive, got " + formatNumber(r));
        case_.boundaryLayerProgression = r;
      }
    } else if (key == "Order") {
      const auto order = toInt(value);
      if (!order) fail(where + " must be an integer, got '" + excerpt(trim(value)) + "'");
      if (*order < 1 || *order > 10)
        fail(where + " must be between 1 and 10, got " + std::to_string(*order));
      case_.order = *order;
    } else {
      const double v = number(value, where);
      if (key == "MinDelta" || key == "MaxDelta" || key == "EPS") {
        if (v <= 0.0) fail(where + " must be positive, got " + formatNumber(v));
        if (key == "EPS" && v > 1.0)
          fail(where + " must be at most 1 (a fraction of the curvature radius), got " +
               formatNumber(v));
      }
      std::optional<double>* slot = key == "MinDelta"   ? &case_.minDelta
                                    : key == "MaxDelta" ? &case_.maxDelta
                                    : key == "EPS"      ? &case_.eps
                                    : key == "Xmin"     ? &case_.xmin
                                    : key == "Ymin"     ? &case_.ymin
                                    : key == "Xmax"     ? &case_.xmax
                                    : key == "Ymax"     ? &case_.ymax
                                                        : &case_.aoa;
      *slot = v;
    }
  }
}

void Reader::readBoolParameters(const XmlElement& section) {
  for (const auto& child : section.children) {
    if (child->name != "P") {
      notice("unknown element <" + excerpt(child->name) + "> in BOOLPARAMETERS is ignored");
      continue;
    }
    const std::string key = trim(required(*child, "VALUE", "BOOLPARAMETERS"));
    if (key.empty()) fail("BOOLPARAMETERS: a <P> has an empty VALUE");
    if (!case_.boolParameters.insert(key).second) continue;  // harmless repetition
    if (contains(kUnsupportedBoolKeys, key))
      notice("BOOLPARAMETERS " + key + " is not supported yet and is ignored");
    else
      unknownKey("BOOLPARAMETERS", key, kUnsupportedBoolKeys);
  }
}

RefinementLine Reader::readLine(const XmlElement& line, const std::string& where) {
  static const std::vector<std::string> kCompact = {"X1", "X2", "R", "D"};
  static const std::vector<std::string> kSplit = {"X1", "Y1", "Z1", "X2", "Y2", "Z2", "R", "D"};
  const bool split = line.child("Y1") != nullptr || line.child("Z1") != nullptr ||
                     line.child("Y2") != nullptr || line.child("Z2") != nullptr;
  const auto& tags = split ? kSplit : kCompact;
  for (const auto& child : line.children) {
    if (!contains(kSplit, child->name))
      notice("unknown element <" + excerpt(child->name) + "> in " + where + " is ignored");
    else if (line.childrenNamed(child->name).size() > 1)
      fail(where + " has more than one <" + child->name + ">");
  }
  std::map<std::string, std::string> text;
  for (const auto& tag : tags) {
    const XmlElement* e = line.child(tag);
    if (e == nullptr) fail(cat({where, " has no <", tag, ">"}));
    text[tag] = e->text;
  }
  RefinementLine r;
  if (split) {
    for (int k = 0; k < 3; ++k) {
      const std::string a = std::string(1, "XYZ"[k]);
      r.x1[k] = number(text[a + "1"], cat({where, " ", a, "1"}));
      r.x2[k] = number(text[a + "2"], cat({where, " ", a, "2"}));
    }
  } else {
    for (const char* tag : {"X1", "X2"}) {
      const auto v = toNumbers(text[tag]);
      if (!v || v->size() != 3)
        fail(where + " " + tag + " must be three numbers (x y z), got '" +
             excerpt(trim(text[tag])) + "'");
      (std::string(tag) == "X1" ? r.x1 : r.x2) = Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
    }
  }
  r.radius = number(text["R"], where + " R");
  r.delta = number(text["D"], where + " D");
  if (r.radius <= 0.0) fail(where + " R must be positive, got " + formatNumber(r.radius));
  if (r.delta <= 0.0) fail(where + " D must be positive, got " + formatNumber(r.delta));
  return r;
}

void Reader::readRefinement(const XmlElement& section) {
  for (const auto& child : section.children) {
    if (child->name != "LINE") {
      notice("unknown element <" + excerpt(child->name) + "> in REFINEMENT is ignored");
      continue;
    }
    const std::string where = "REFINEMENT LINE " + std::to_string(case_.refinementLines.size() + 1);
    case_.refinementLines.push_back(readLine(*child, where));
  }
  if (case_.refinementLines.empty()) notice("REFINEMENT has no <LINE> and is ignored");
}

void Reader::validate() {
  const auto cad = information_.find("CADFile");
  if (cad == information_.end() || cad->second.empty()) fail("INFORMATION CADFile is missing");
  const auto type = information_.find("MeshType");
  if (type == information_.end() || type->second.empty()) fail("INFORMATION MeshType is missing");
  case_.meshType = type->second;
  if (!contains(kMeshTypes, case_.meshType)) {
    fail("INFORMATION MeshType must be 3D, 2D, 3DBndLayer or 2DBndLayer, got '" +
         excerpt(case_.meshType) + "'" +
         (case_.meshType == "Manifold" ? " (surface-only meshes are not supported yet)" : ""));
  }

  const std::string& cadFile = cad->second;
  const bool fourDigits =
      cadFile.size() == 4 && std::all_of(cadFile.begin(), cadFile.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c)) != 0;
      });
  if (fourDigits) {
    if (!case_.is2D())
      fail("INFORMATION CADFile '" + cadFile + "' names a NACA aerofoil, which needs MeshType 2D " +
           "or 2DBndLayer, not " + case_.meshType);
    case_.nacaDigits = cadFile;
    const std::array<const std::optional<double>*, 5> values = {
        &case_.xmin, &case_.ymin, &case_.xmax, &case_.ymax, &case_.aoa};
    for (std::size_t k = 0; k < kNacaKeys.size(); ++k)
      if (!values[k]->has_value())
        fail("PARAMETERS " + kNacaKeys[k] + " is missing (needed by the NACA " + cadFile +
             " domain)");
    if (*case_.xmin >= *case_.xmax)
      fail("PARAMETERS Xmin (" + formatNumber(*case_.xmin) + ") must be below Xmax (" +
           formatNumber(*case_.xmax) + ")");
    if (*case_.ymin >= *case_.ymax)
      fail("PARAMETERS Ymin (" + formatNumber(*case_.ymin) + ") must be below Ymax (" +
           formatNumber(*case_.ymax) + ")");
  } else {
    if (case_.is2D() && cadFile.find('.') == std::string::npos)
      fail("INFORMATION CADFile '" + excerpt(cadFile) +
           "' has no extension, so it is read as a NACA code, which must be exactly 4 digits");
    case_.cadFile = (fs::path(case_.path).parent_path() / cadFile).lexically_normal().string();
    const std::array<const std::optional<double>*, 5> values = {
        &case_.xmin, &case_.ymin, &case_.xmax, &case_.ymax, &case_.aoa};
    for (std::size_t k = 0; k < kNacaKeys.size(); ++k)
      if (values[k]->has_value())
        notice("PARAMETERS " + kNacaKeys[k] +
               " is ignored: only a NACA case (CADFile NNNN) uses it");
  }

  if (case_.hasBoundaryLayer()) {
    for (const char* key : {"BndLayerSurfaces", "BndLayerThickness"})
      if (case_.boundaryLayer.count(key) == 0)
        fail("PARAMETERS " + std::string(key) + " is missing (needed by MeshType " +
             case_.meshType + ")");
  } else {
    for (const auto& [key, value] : case_.boundaryLayer)
      notice("PARAMETERS " + key + " is ignored: MeshType " + case_.meshType +
             " makes no boundary layer");
  }
  if (case_.minDelta && case_.maxDelta && *case_.minDelta > *case_.maxDelta)
    fail("PARAMETERS MinDelta (" + formatNumber(*case_.minDelta) + ") must not exceed MaxDelta (" +
         formatNumber(*case_.maxDelta) + ")");
}

McfCase Reader::read() {
  const std::string& path = case_.path;
  requireRegularFile(path, "mesh configuration file");
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  if (in) buffer << in.rdbuf();
  if (!in || in.bad()) throw IoError("mesh configuration file '" + path + "' cannot be read");

  const auto root = parseXml(buffer.str(), path);
  if (root->name != "NEKTAR")
    fail("the root element is <" + excerpt(root->name) + ">, not <NEKTAR>");
  const XmlElement* meshing = nullptr;
  for (const auto& child : root->children) {
    if (child->name == "MESHING" && meshing == nullptr)
      meshing = child.get();
    else
      notice("element <" + excerpt(child->name) + "> in NEKTAR is ignored");
  }
  if (meshing == nullptr) fail("no <MESHING> in <NEKTAR>");

  const std::vector<std::string> sections = {"INFORMATION", "PARAMETERS", "BOOLPARAMETERS",
                                             "REFINEMENT"};
  for (const auto& child : meshing->children) {
    const std::string& name = child->name;
    if (contains(sections, name)) {
      if (meshing->childrenNamed(name).size() > 1) fail("MESHING has more than one <" + name + ">");
    } else if (contains(kUnsupportedSections, name)) {
      notice("section " + name + " is not supported yet and is ignored");
    } else {
      notice("unknown section <" + excerpt(name) + "> in MESHING is ignored");
    }
  }
  const XmlElement* information = meshing->child("INFORMATION");
  if (information == nullptr) fail("no <INFORMATION> in <MESHING>");
  readInformation(*information);
  if (const XmlElement* p = meshing->child("PARAMETERS")) readParameters(*p);
  if (const XmlElement* b = meshing->child("BOOLPARAMETERS")) readBoolParameters(*b);
  if (const XmlElement* r = meshing->child("REFINEMENT")) readRefinement(*r);
  validate();
  return std::move(case_);
}

}  // namespace

McfCase readMcfFile(const std::string& path) {
  return Reader(path).read();
}

}  // namespace homesh

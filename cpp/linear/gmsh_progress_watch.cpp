#include "linear/gmsh_progress_watch.hpp"

#include <cstdio>
#include <sstream>

namespace homesh {
namespace {

constexpr const char* kEntityPrefix = "homesh-gmsh-entity ";

// Gmsh's terminal prefixes (Gmsh 4.8 pads the level to eight characters) and the level each
// is shown at.
struct Level {
  const char* prefix;
  const char* name;
  int verbosity;
};
constexpr Level kLevels[] = {{"Info    : ", "Info", 2},
                             {"Debug   : ", "Debug", 2},
                             {"Warning : ", "Warning", 1},
                             {"Error   : ", "Error", 1}};

bool startsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

// The number after `key` in `message` (from `from`), or -1.
long numberAfter(const std::string& message, const std::string& key, std::size_t from = 0) {
  const std::size_t at = message.find(key, from);
  if (at == std::string::npos) return -1;
  std::istringstream in(message.substr(at + key.size()));
  long n = -1;
  return (in >> n) ? n : -1;
}

}  // namespace

std::string gmshEntityLine(int dim, int tag, int cadIndex) {
  return kEntityPrefix + std::to_string(dim) + " " + std::to_string(tag) + " " +
         std::to_string(cadIndex);
}

std::string GmshProgressWatch::name(int dim, int tag) const {
  static const char* const kGmsh[] = {"point", "curve", "surface", "volume"};
  static const char* const kCad[] = {"vertex", "edge", "face", "solid"};
  std::string text = std::string("Gmsh's ") + kGmsh[dim] + " " + std::to_string(tag);
  const auto it = cad_.find({dim, tag});
  if (it == cad_.end()) return text;
  text += std::string(" (CAD ") + kCad[dim] + " " + std::to_string(it->second);
  const std::string given = givenNames_ ? givenNames_(dim, it->second) : std::string();
  return text + (given.empty() ? ")" : "; as given: " + given + ")");
}

std::string GmshProgressWatch::operator()(const std::string& line) {
  if (startsWith(line, kEntityPrefix)) {
    std::istringstream in(line.substr(std::string(kEntityPrefix).size()));
    int dim = 0, tag = 0, index = 0;
    if (in >> dim >> tag >> index && dim >= 0 && dim <= 3) cad_[{dim, tag}] = index;
    return {};
  }
  for (const Level& level : kLevels) {
    if (!startsWith(line, level.prefix)) continue;
    const std::string message = line.substr(std::string(level.prefix).size());
    if (verbosity_ >= level.verbosity)
      std::fprintf(stderr, "gmsh: %s: %s\n", level.name, message.c_str());
    if (std::string(level.name) == "Error") lastError_ = message;
    return seeMessage(message);
  }
  if (verbosity_ >= 1 && !line.empty()) std::fprintf(stderr, "%s\n", line.c_str());
  return {};
}

std::string GmshProgressWatch::lastActivity() const {
  std::string text;
  if (current_.first >= 0) text = "while meshing " + name(current_.first, current_.second);
  if (!lastError_.empty())
    text += (text.empty() ? "after Gmsh's error: " : ", after its error: ") + lastError_;
  return text;
}

std::string GmshProgressWatch::seeMessage(const std::string& message) {
  static const char* const kEntered[] = {"Meshing curve ", "Meshing surface ", "Meshing volume "};
  long enteredSurface = 0;
  for (int dim = 1; dim <= 3; ++dim) {
    const long tag = numberAfter(message, kEntered[dim - 1]);
    if (tag > 0) {
      current_ = {dim, static_cast<int>(tag)};
      lastError_.clear();  // an error said before is not this entity's
      if (dim == 2) enteredSurface = tag;
    }
  }
  // Between entities ("Done meshing 2D", "Meshing 3D...", the optimisation): none is current,
  // and an error said before is not what a crash from here on met.
  if (startsWith(message, "Done meshing") || startsWith(message, "Meshing 3D") ||
      startsWith(message, "Optimizing")) {
    current_ = {-1, 0};
    lastError_.clear();
  }
  if (enteredSurface > 0 && ++entries_[static_cast<int>(enteredSurface)] >= kStallEntries)
    return name(2, static_cast<int>(enteredSurface)) + ": Gmsh meshed it " +
           std::to_string(kStallEntries) + " times without finishing it";
  // "16 elements remain invalid in surface 1", "1 element remain invalid in surface 1"
  const std::string key = " remain invalid in surface ";
  const std::size_t at = message.find(key);
  if (at == std::string::npos) return {};
  const long surface = numberAfter(message, key);
  long count = -1;
  std::istringstream(message.substr(0, at)) >> count;
  if (surface <= 0 || count < 0) return {};
  std::vector<long>& counts = invalid_[static_cast<int>(surface)];
  counts.push_back(count);
  const std::size_t n = counts.size();
  if (n < 3 || !(counts[n - 1] > counts[n - 2] && counts[n - 2] > counts[n - 3])) return {};
  return name(2, static_cast<int>(surface)) + ": its invalid elements rose from " +
         std::to_string(counts[n - 3]) + " to " + std::to_string(counts[n - 2]) + " to " +
         std::to_string(counts[n - 1]) + " as Gmsh refined its edges";
}

}  // namespace homesh

// Command-line parsing for `homesh`, separate from main() so that tests can exercise it.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace homesh {

// Thrown for malformed command lines; main() prints it with the usage hint and exits 2.
struct UsageError {
  std::string message;
};

struct MeshCommand {
  std::string input;
  int order = 4;
  std::optional<double> size;
  int threads = 1;
  std::vector<std::string> outputs;
  std::optional<std::string> report;  // "-" is standard output
  int verbosity = 0;                  // -v: 1, -vv: 2
  bool quiet = false;
};

struct ParsedCommand {
  enum class Kind { Help, Version, Mesh } kind = Kind::Help;
  std::string helpTopic;  // "" or a command name
  MeshCommand mesh;
};

// argv without the program name. Throws UsageError.
ParsedCommand parseCommandLine(const std::vector<std::string>& args);

std::string usageText(const std::string& topic);

}  // namespace homesh

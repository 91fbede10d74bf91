#include "cli/arguments.hpp"

#include <charconv>
#include <cmath>

#include "pipeline/mesh_pipeline.hpp"

namespace homesh {
namespace {

// Decimal only (no hexadecimal, no "inf"), and the whole text must be the number.
double parseNumber(const std::string& option, const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v, std::chars_format::general);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(v))
    throw UsageError{option + " expects a number, got '" + text + "'"};
  return v;
}

int parseInteger(const std::string& option, const std::string& text) {
  int v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end)
    throw UsageError{option + " expects an integer, got '" + text + "'"};
  return v;
}

MeshCommand parseMesh(const std::vector<std::string>& args, std::size_t i) {
  MeshCommand cmd;
  auto next = [&](const std::string& option) -> const std::string& {
    if (i + 1 >= args.size()) throw UsageError{option + " needs a value"};
    return args[++i];
  };
  for (; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--order" || a == "-p") {
      cmd.order = parseInteger(a, next(a));
      if (cmd.order < 1 || cmd.order > 10)
        throw UsageError{"--order must be from 1 to 10, got " + args[i]};
    } else if (a == "--size" || a == "-s") {
      cmd.size = parseNumber(a, next(a));
      if (!(*cmd.size > 0.0)) throw UsageError{"--size must be a positive length, got " + args[i]};
    } else if (a == "--threads" || a == "-j") {
      cmd.threads = parseInteger(a, next(a));
      if (cmd.threads < 1 || cmd.threads > kMaxThreads)
        throw UsageError{"--threads must be from 1 to " + std::to_string(kMaxThreads) + ", got " +
                         args[i]};
    } else if (a == "-o" || a == "--output") {
      cmd.outputs.push_back(next(a));
    } else if (a == "--report") {
      cmd.report = next(a);
    } else if (a == "-v" || a == "--verbose") {
      ++cmd.verbosity;
    } else if (a == "-vv") {
      cmd.verbosity += 2;
    } else if (a == "-q" || a == "--quiet") {
      cmd.quiet = true;
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      throw UsageError{"unknown option '" + a + "' for 'homesh mesh'"};
    } else if (cmd.input.empty()) {
      cmd.input = a;
    } else {
      throw UsageError{"unexpected argument '" + a + "' (only one INPUT is allowed)"};
    }
  }
  if (cmd.input.empty()) throw UsageError{"'homesh mesh' needs an INPUT CAD file"};
  return cmd;
}

}  // namespace

ParsedCommand parseCommandLine(const std::vector<std::string>& args) {
  ParsedCommand parsed;
  if (args.empty()) throw UsageError{"no command given"};
  const std::string& first = args[0];
  if (first == "-h" || first == "--help" || first == "help") {
    parsed.kind = ParsedCommand::Kind::Help;
    if (args.size() > 1) parsed.helpTopic = args[1];
    return parsed;
  }
  if (first == "--version" || first == "version") {
    parsed.kind = ParsedCommand::Kind::Version;
    return parsed;
  }
  if (first == "mesh") {
    for (std::size_t i = 1; i < args.size(); ++i)
      if (args[i] == "-h" || args[i] == "--help") {
        parsed.helpTopic = "mesh";
        return parsed;
      }
    parsed.kind = ParsedCommand::Kind::Mesh;
    parsed.mesh = parseMesh(args, 1);
    return parsed;
  }
  throw UsageError{"unknown command '" + first + "'"};
}

std::string usageText(const std::string& topic) {
  if (topic == "mesh")
    return R"(usage: homesh mesh INPUT [options]

Meshes a CAD model (.step .stp .iges .igs .brep .brp) with curved elements of order P:
a linear tetrahedral mesh (triangles for planar faces) whose boundary nodes are then
placed on the CAD at order P.

options:
  -p, --order P       polynomial order, 1..10 (default 4)
  -s, --size H        target element size (default: bounding-box diagonal / 20)
  -o, --output FILE   write the mesh; .msh (Gmsh 4.1) or .vtu (VTK); repeatable
      --report FILE   write the JSON report ("-" for standard output)
  -j, --threads N     threads (default 1)
  -v, --verbose       show Gmsh's warnings (-vv: and its information)
  -q, --quiet         print nothing but errors

exit status: 0 success, 1 failure (file, CAD or meshing), 2 bad command line or parameter
)";
  return R"(usage: homesh COMMAND [options]

commands:
  mesh INPUT     CAD file to curved high-order mesh (homesh mesh --help)
  --version      print the version
  --help         this text
)";
}

}  // namespace homesh

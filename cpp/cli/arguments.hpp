// Command-line parsing for `homesh`, separate from main() so that tests can exercise it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/meshing_options.hpp"
#include "sizing/refinement_source.hpp"

namespace homesh {

// Thrown for malformed command lines; main() prints it with the usage hint and exits 2.
struct UsageError {
  std::string message;
};

// Options several commands share.
struct CommonOptions {
  int threads = defaultOf<int>("threads");
  bool quiet = false;
  std::optional<std::string> report;  // "-" is standard output
  std::vector<std::string> outputs;   // -o, repeatable
  bool binary = false;                // MSH binary, VTU appended raw data
  bool compressed = false;            // Nektar++ XML compressed sections
  // --group NAME=F1,F2,...: named boundary groups (physical groups, Nektar++ composites).
  std::vector<std::pair<std::string, std::vector<int>>> groups;
};

// Sizing flags shared by `mesh` and `predict`: they override a .mcf's values.
struct SizingFlags {
  std::vector<RefinementSource> sources;   // --refine-line, -sphere, -box, -curve
  std::optional<std::string> writeOctree;  // --write-octree FILE.vtu
};

struct MeshCommand {
  std::string input;
  // The parameter table's options given (core/parameters.hpp), by key: "order" (unset: the
  // .mcf's Order, else the table's), "size", "optimise" (--optimise: true, the table's sweeps;
  // --maxiter N: N), "verbosity" (-v, -vv), "heal", ...; MeshingOptions::apply takes them.
  OptionMap options;
  SizingFlags sizing;
  // --bl-faces, --bl-thickness, --bl-layers, --bl-progression: a boundary layer (each
  // overrides the .mcf's BndLayer* key); --bl-solids: the solids it grows into from faces
  // between two.
  std::optional<std::string> blFaces, blThickness, blSolids;
  std::optional<int> blLayers;
  std::optional<double> blProgression;
  CommonOptions common;
};

struct QualityCommand {
  std::string input;
  bool strict = false;  // exit status 3 if an element is invalid or undecided
  std::string cad;      // with --cad: the boundary's distance and normal angle to this CAD
  OptionMap options;    // classify_tolerance (with --cad)
  CommonOptions common;
};

struct PredictCommand {
  std::string input;
  SizingFlags sizing;
  OptionMap options;  // the CAD modes given (--no-heal, --solids-only, --surface, --auto)
  CommonOptions common;
};

struct ConvertCommand {
  std::string input;
  CommonOptions common;
};

struct OptimiseCommand {
  std::string input;
  std::optional<int> order;  // re-interpolate at this order first
  // The optimiser's options keyed as the parameter table (OptimiserOptions::apply checks them).
  OptionMap options;
  CommonOptions common;
};

struct CurveCommand {
  std::string input;  // the linear mesh
  std::string cad;    // --cad: the CAD file it was made from
  // The parameter table's options given, by key ("order", "optimise", ...): MeshingOptions::apply
  // takes them.
  OptionMap options;
  CommonOptions common;
};

struct ParsedCommand {
  enum class Kind {
    Help,
    Version,
    Mesh,
    Predict,
    Quality,
    Convert,
    Optimise,
    Curve
  } kind = Kind::Help;
  std::string helpTopic;  // "" or a command name
  MeshCommand mesh;
  PredictCommand predict;
  QualityCommand quality;
  ConvertCommand convert;
  OptimiseCommand optimise;
  CurveCommand curve;
};

// argv without the program name. Throws UsageError.
ParsedCommand parseCommandLine(const std::vector<std::string>& args);

// The manual page (roff) of every command, from the same texts as --help.
std::string manPage();

std::string usageText(const std::string& topic);

}  // namespace homesh

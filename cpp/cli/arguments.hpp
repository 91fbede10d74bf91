// Command-line parsing for `homesh`, separate from main() so that tests can exercise it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sizing/refinement_source.hpp"

namespace homesh {

// Thrown for malformed command lines; main() prints it with the usage hint and exits 2.
struct UsageError {
  std::string message;
};

// Options several commands share.
struct CommonOptions {
  int threads = 1;
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
  std::optional<double> minDelta, maxDelta, eps;
  std::vector<RefinementSource> sources;   // --refine-line, -sphere, -box, -curve
  std::optional<std::string> writeOctree;  // --write-octree FILE.vtu
  bool anyDelta() const { return minDelta || maxDelta || eps; }
};

struct MeshCommand {
  std::string input;
  std::optional<int> order;  // unset: the .mcf's Order, else 4
  std::optional<double> size;
  SizingFlags sizing;
  int verbosity = 0;               // -v: 1, -vv: 2
  int optimiseIterations = 0;      // --optimise: 100, --maxiter N
  int repairRounds = 8;            // --repair-rounds N, range and default in core/parameters.hpp
  double timeLimit = 0.0;          // --time-limit S: seconds per optimiser run (0: none)
  double facetWeight = 0.0;        // --facet-weight W: the optimiser's boundary-facet term
  bool heal = true;                // --no-heal: the CAD is only checked
  bool solidsOnly = false;         // --solids-only: faces in no solid are left out
  bool surface = false;            // --surface: a model without solids gets a surface mesh
  bool automatic = false;          // --auto: --solids-only or --surface, whichever fits
  double linearTimeLimit = 600.0;  // --linear-time-limit S: seconds per Gmsh run (0: none)
  double jobTimeLimit = 0.0;       // --job-time-limit S: seconds for the whole job (0: none)
  // --bl-faces, --bl-thickness, --bl-layers, --bl-progression: a boundary layer (each
  // overrides the .mcf's BndLayer* key).
  std::optional<std::string> blFaces, blThickness;
  std::optional<int> blLayers;
  std::optional<double> blProgression;
  CommonOptions common;
};

struct QualityCommand {
  std::string input;
  bool strict = false;  // exit status 3 if an element is invalid or undecided
  CommonOptions common;
};

struct PredictCommand {
  std::string input;
  SizingFlags sizing;
  bool heal = true;         // --no-heal, as for mesh
  bool solidsOnly = false;  // --solids-only, as for mesh
  bool surface = false;     // --surface, as for mesh
  bool automatic = false;   // --auto, as for mesh
  CommonOptions common;
};

struct ConvertCommand {
  std::string input;
  CommonOptions common;
};

struct OptimiseCommand {
  std::string input;
  std::string functional = "hyperelastic";
  int maxIterations = 100;
  double tolerance = 1e-6;
  std::optional<int> order;               // re-interpolate at this order first
  std::optional<double> regionThreshold;  // --region Q
  int regionLayers = 2;
  int focusPasses = 2;
  bool freeInterfaces = false;
  CommonOptions common;
};

struct ParsedCommand {
  enum class Kind { Help, Version, Mesh, Predict, Quality, Convert, Optimise } kind = Kind::Help;
  std::string helpTopic;  // "" or a command name
  MeshCommand mesh;
  PredictCommand predict;
  QualityCommand quality;
  ConvertCommand convert;
  OptimiseCommand optimise;
};

// argv without the program name. Throws UsageError.
ParsedCommand parseCommandLine(const std::vector<std::string>& args);

std::string usageText(const std::string& topic);

}  // namespace homesh

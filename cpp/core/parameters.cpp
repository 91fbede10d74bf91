#include "core/parameters.hpp"

#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/error.hpp"
#include "core/format.hpp"

namespace homesh {

namespace {

constexpr double kNoLimit = std::numeric_limits<double>::infinity();

// The rows in the order a panel shows them, in two parts: the mesh's and the CAD's ...
std::vector<ParameterDefinition> meshAndCadRows() {
  return {
      {"order", "Order", "--order", "-p", "order", ParameterKind::Integer, 1, 10, false, 4, false,
       false, "mesh", "Polynomial order of the elements"},
      {"size", "Size", "--size", "-s", "size", ParameterKind::Length, 0, kNoLimit, true, 0, true,
       false, "mesh", "Uniform target element size (0 or none: the sizing octree)"},
      {"optimise", "OptimiserIterations", "--maxiter", "-n", "optimiser iterations",
       ParameterKind::Integer, 0, 10000, false, 100, false, true, "mesh",
       "Most sweeps of the variational optimiser after curving (0: none); it stops earlier "
       "once the mesh is valid and no longer improving"},
      {"optimise_seconds", "OptimiserTimeLimit", "--time-limit", "", "optimiser time limit",
       ParameterKind::Real, 0, kNoLimit, false, 0, false, false, "mesh",
       "Seconds one optimiser run may take (each of a job's runs); it then stops with the best "
       "state so far and the report says \"stopped\": \"time budget\"; 0: no limit"},
      {"facet_weight", "FacetWeight", "--facet-weight", "", "facet weight", ParameterKind::Real, 0,
       100, false, 0, false, false, "mesh",
       "Weight of the boundary facets' distortion within the CAD surface in the optimiser's "
       "energy (3D meshes), added once every element is proven valid: it keeps a facet's nodes "
       "evenly spread "
       "as they slide, so the curved boundary stays on the CAD between them (0: off; 1 is a "
       "good start)"},
      {"fidelity_weight", "FidelityWeight", "--fidelity-weight", "", "fidelity weight",
       ParameterKind::Real, 0, 1000, false, 2, false, false, "mesh",
       "Weight of the boundary's fidelity to the CAD in the optimiser's energy (3D meshes), added "
       "once every element is proven valid: at the boundary facets' quadrature points, the "
       "squared distance off the CAD's tangent plane (relative to the facet) and the squared "
       "sine of the angle between the facet's and the CAD's normals, so that sliding nodes keep "
       "the curved boundary on the CAD between them (0: off; higher follows the CAD closer at "
       "some cost to the worst element). Above 0 the boundary_fit stage also runs once the mesh "
       "is curved: boundary triangles on curved faces fitted to them, no element ending more "
       "than 0.1 % below the lower of its own value and the mesh's worst"},
      {"linear_seconds", "LinearTimeLimit", "--linear-time-limit", "", "linear meshing time limit",
       ParameterKind::Real, 0, kNoLimit, false, 600, false, false, "mesh",
       "Seconds Gmsh's linear meshing may take (each run, in its own process); it is then "
       "stopped and the job fails naming this limit; 0: no limit"},
      {"job_seconds", "JobTimeLimit", "--job-time-limit", "", "job time limit", ParameterKind::Real,
       0, kNoLimit, false, 0, false, false, "mesh",
       "Seconds the whole job may take, from loading the CAD: Gmsh and the optimiser get at most "
       "what is left, a repair round starts only if the last one would still fit, and the best "
       "mesh so far is kept (the report's \"job\" says \"stopped\": \"time budget\"); with no "
       "mesh yet, the job fails naming its stage; 0: no limit"},
      {"repair_rounds", "RepairRounds", "--repair-rounds", "", "repair rounds",
       ParameterKind::Integer, 0, 20, false, 8, false, false, "mesh",
       "Most repair rounds while elements are not proven valid (split, flip, remesh or refine "
       "around them, curve, optimise and check again)"},
      {"classify_tolerance", "", "--classify-tolerance", "", "classification tolerance",
       ParameterKind::Real, 0, 0.01, true, 1e-5, false, false, "mesh",
       "How far a boundary node of a mesh made elsewhere may lie from the CAD vertex, edge or "
       "face it is put on, relative to the CAD's bounding diagonal: homesh curve then moves the "
       "node onto it; homesh quality --cad places boundary cells by their corners"},
      {"threads", "Threads", "--threads", "-j", "threads", ParameterKind::Integer, 1, 1024, false,
       0, true, false, "mesh",
       "Threads the sizing, the optimiser and the quality checks use (0: every core this "
       "process may run on)"},
      {"verbosity", "", "--verbose", "-v", "verbosity", ParameterKind::Integer, 0, 2, false, 0,
       false, false, "mesh",
       "How much of Gmsh's own output to pass on: 0 none, 1 its warnings, 2 also its "
       "information (-v, -vv)"},
      {"heal", "Heal", "--no-heal", "", "heal", ParameterKind::Boolean, 0, 1, false, 1, false,
       false, "cad",
       "Check the shape and, where the check finds a problem (faces not sewn into a solid, "
       "invalid geometry, tiny edges or sliver faces), repair it with OpenCASCADE's shape "
       "healing before meshing; a healed shape's faces are numbered afresh (the report's "
       "\"healing\" says what was found and done); off: check only (touching solids are still "
       "imprinted: Imprint)"},
      {"solids_only", "SolidsOnly", "--solids-only", "", "solids only", ParameterKind::Boolean, 0,
       1, false, 0, false, false, "cad",
       "Mesh the solids and leave out faces in no solid (a loose shell that does not close), "
       "named in the report; off: such a shape is refused, naming those faces"},
      {"surface", "Surface", "--surface", "", "surface", ParameterKind::Boolean, 0, 1, false, 0,
       false, false, "cad",
       "For a shape without solids (a shell, faces that do not close): a surface mesh of its "
       "faces, triangles curved on the CAD, sewn where faces meet (no volume, no optimiser, no "
       "boundary layer); off: such a shape is refused, naming a free edge"},
      {"auto", "AutoMode", "--auto", "", "auto", ParameterKind::Boolean, 0, 1, false, 0, false,
       false, "cad",
       "Choose per shape, for batch runs: with solids, as solids only (faces in no solid left "
       "out and named); without a solid, sewn into solids where every shell closes, else as "
       "surface; the report says which. Not with solids only or surface"},
      {"imprint", "Imprint", "--no-imprint", "", "imprint", ParameterKind::Boolean, 0, 1, false, 1,
       false, false, "cad",
       "Imprint solids that touch on each other (OpenCASCADE's general fuse), so that they share "
       "the faces where they touch and one mesh conforms across them, each solid its own volume "
       "group (solids that overlap are cut where they do, each overlap a solid of its own); the "
       "faces are numbered afresh, and numbers given in the shape's own numbering "
       "(boundary-layer faces, refinement curves, groups) are mapped (the report's "
       "healing.imprint lists the interfaces, healing.numbering the numbers that changed); "
       "done with or without healing; off: each solid is meshed with its own nodes where they "
       "touch"},
  };
}

// ... then the optimiser's, the sizing's and the boundary layer's.
std::vector<ParameterDefinition> optimiserSizingAndLayerRows() {
  return {
      {"functional", "", "--functional", "-f", "functional", ParameterKind::Choice, 0, 3, false, 0,
       false, false, "optimiser", "Energy the optimiser minimises (docs/method.md describes each)",
       "hyperelastic|linearelastic|winslow|distortion"},
      {"tolerance", "", "--tolerance", "", "optimiser tolerance", ParameterKind::Real, 0, kNoLimit,
       false, 1e-6, false, false, "optimiser",
       "The optimiser stops once no node moves by more than this times its smallest element's "
       "size"},
      {"region", "", "--region", "", "region", ParameterKind::Real, 0, 1, false, 0, false, false,
       "optimiser",
       "Move only the nodes near elements whose certified scaled Jacobian is below this (0: "
       "everywhere)"},
      {"region_layers", "", "--layers", "", "region layers", ParameterKind::Integer, 0, 1000, false,
       2, false, false, "optimiser",
       "Layers of neighbouring elements (sharing a node) added around the region"},
      {"focus", "", "--focus", "", "focus passes", ParameterKind::Integer, 0, 1000, false, 2, false,
       false, "optimiser",
       "Extra passes after each sweep over the nodes of the elements within 0.05 of the worst "
       "scaled Jacobian (0: plain sweeps)"},
      {"free_interfaces", "", "--free-interfaces", "", "free interfaces", ParameterKind::Boolean, 0,
       1, false, 0, false, false, "optimiser",
       "Also move the nodes on internal interfaces between volumes of a mesh without CAD (as "
       "NekMesh does; the interface then leaves its geometry)"},
      {"min_delta", "MinDelta", "--min-delta", "", "MinDelta", ParameterKind::Length, 0, kNoLimit,
       true, 0, true, false, "sizing",
       "Smallest element size, at high curvature (0 or none: the smallest size the shape asks "
       "for, from its curvature, thin walls and narrow faces, at most MaxDelta / 20 and at "
       "least MaxDelta / 200, raised where the octree or the element count would exceed "
       "their limits)"},
      {"max_delta", "MaxDelta", "--max-delta", "", "MaxDelta", ParameterKind::Length, 0, kNoLimit,
       true, 0, true, false, "sizing",
       "Largest element size (0 or none: a twentieth of the CAD's bounding-box diagonal)"},
      {"eps", "Eps", "--eps", "", "EPS", ParameterKind::Real, 0, 1, true, 0.05, false, false,
       "sizing",
       "Sagitta ratio: on a surface of curvature radius R the size is 2 R sqrt(eps (2 - eps))"},
      {"layers", "Layers", "--bl-layers", "", "boundary-layer layers", ParameterKind::Integer, 1,
       100, false, 2, false, false, "boundary_layer", "Thin layers the macro layer is split into"},
      {"progression", "Progression", "--bl-progression", "", "boundary-layer progression",
       ParameterKind::Real, 0, 100, true, 2, false, false, "boundary_layer",
       "Height ratio of consecutive layers, from the wall"},
  };
}

}  // namespace

const std::vector<ParameterDefinition>& parameterDefinitions() {
  static const std::vector<ParameterDefinition> table = [] {
    std::vector<ParameterDefinition> rows = meshAndCadRows();
    const std::vector<ParameterDefinition> rest = optimiserSizingAndLayerRows();
    rows.insert(rows.end(), rest.begin(), rest.end());
    return rows;
  }();
  return table;
}

const ParameterDefinition* findParameter(const std::string& key) {
  for (const ParameterDefinition& p : parameterDefinitions())
    if (key == p.key) return &p;
  return nullptr;
}

const ParameterDefinition& parameterDefinition(const std::string& key) {
  for (const ParameterDefinition& p : parameterDefinitions())
    if (key == p.key) return p;
  throw std::out_of_range("no parameter '" + key + "'");
}

std::vector<std::string> choiceNames(const ParameterDefinition& p) {
  std::vector<std::string> names;
  if (p.kind != ParameterKind::Choice) return names;
  std::string name;
  for (const char* c = p.choices;; ++c) {
    if (*c == '|' || *c == '\0') {
      names.push_back(name);
      name.clear();
      if (*c == '\0') break;
    } else {
      name.push_back(*c);
    }
  }
  return names;
}

std::string rangeText(const ParameterDefinition& p) {
  if (p.kind == ParameterKind::Boolean) return "true or false";
  if (p.kind == ParameterKind::Choice) {
    return "one of " + joined(choiceNames(p));
  }
  const bool integer = p.kind == ParameterKind::Integer;
  const std::string what = integer                           ? "an integer"
                           : p.kind == ParameterKind::Length ? "a length"
                                                             : "a number";
  if (std::isinf(p.max)) return what + (p.minExclusive ? " > " : " >= ") + formatNumber(p.min);
  if (integer || !p.minExclusive)
    return what + " from " + formatNumber(p.min) + " to " + formatNumber(p.max);
  return what + " in (" + formatNumber(p.min) + ", " + formatNumber(p.max) + "]";
}

bool inRange(const ParameterDefinition& p, double value) {
  if (std::isnan(value)) return false;
  const bool whole = p.kind == ParameterKind::Integer || p.kind == ParameterKind::Choice;
  if (whole && value != std::floor(value)) return false;
  if (p.minExclusive ? !(value > p.min) : !(value >= p.min)) return false;
  return value <= p.max;
}

namespace {

// How a message shows a value that came from outside.
std::string valueText(const OptionValue& value) {
  if (const double* x = std::get_if<double>(&value)) return formatNumber(*x);
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  return "'" + std::get<std::string>(value) + "'";
}

// The index of `name` among a Choice's names, compared in lower case with '-', '_' and spaces
// left out ("Linear-Elastic" is "linearelastic"); -1 when it is none of them.
int choiceIndex(const ParameterDefinition& p, const std::string& name) {
  std::string key;
  for (const char c : name)
    if (c != '-' && c != '_' && c != ' ')
      key.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  const std::vector<std::string> names = choiceNames(p);
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == key) return static_cast<int>(i);
  return -1;
}

}  // namespace

double checkedOption(const std::string& key, const OptionValue& value) {
  const ParameterDefinition* p = findParameter(key);
  if (p == nullptr)
    throw ParameterError("unknown option '" + key + "' (options: " +
                         joined(tableKeys([](const std::string&) { return true; })) + ")");
  const auto refuse = [&] {
    return ParameterError(std::string(p->label) + " must be " + rangeText(*p) + ", got " +
                          valueText(value));
  };
  if (p->kind == ParameterKind::Choice) {
    const std::string* name = std::get_if<std::string>(&value);
    const int index = name != nullptr ? choiceIndex(*p, *name) : -1;
    if (index < 0) throw refuse();
    return index;
  }
  double number = 0.0;
  if (const bool* b = std::get_if<bool>(&value)) {
    if (p->kind == ParameterKind::Boolean) return *b ? 1.0 : 0.0;
    if (!p->switchable) throw refuse();
    return *b ? p->defaultValue : 0.0;
  }
  if (const double* x = std::get_if<double>(&value)) number = *x;
  if (p->zeroIsAutomatic && number == 0.0 && std::holds_alternative<double>(value)) return 0.0;
  if (std::holds_alternative<std::string>(value) || p->kind == ParameterKind::Boolean ||
      !inRange(*p, number))
    throw refuse();
  return number;
}

double parameterDefault(const std::string& key) {
  return parameterDefinition(key).defaultValue;
}

void checkParameter(const std::string& key, double value) {
  const ParameterDefinition& p = parameterDefinition(key);
  if (!inRange(p, value))
    throw ParameterError(std::string(p.label) + " must be " + rangeText(p) + ", got " +
                         formatNumber(value));
}

std::vector<std::string> tableKeys(const std::function<bool(const std::string&)>& wanted) {
  std::vector<std::string> keys;
  for (const ParameterDefinition& p : parameterDefinitions())
    if (wanted(p.key)) keys.emplace_back(p.key);
  return keys;
}

}  // namespace homesh

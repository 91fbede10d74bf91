#include "cli/arguments.hpp"

#include <charconv>
#include <cmath>
#include <functional>
#include <map>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"
#include "core/version.hpp"
#include "optimise/functional.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {
namespace {

// Decimal only (no hexadecimal, no "inf"), and the whole text must be the number.
double parseNumber(const std::string& option, const std::string& text) {
  double v = 0.0;
  const std::string digits = !text.empty() && text[0] == '+' ? text.substr(1) : text;
  const char* end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, v, std::chars_format::general);
  if (digits.empty() || ec != std::errc() || ptr != end || !std::isfinite(v))
    throw UsageError{option + " expects a number, got '" + text + "'"};
  return v;
}

int parseInteger(const std::string& option, const std::string& text) {
  int v = 0;
  const std::string digits = !text.empty() && text[0] == '+' ? text.substr(1) : text;
  const char* end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, v);
  if (digits.empty() || ec != std::errc() || ptr != end)
    throw UsageError{option + " expects an integer, got '" + text + "'"};
  return v;
}

// `text` parsed as the parameter `key` of core/parameters.hpp and checked against its range.
double parseParameter(const std::string& key, const std::string& option, const std::string& text) {
  const ParameterDefinition& p = parameterDefinition(key);
  const double value =
      p.kind == ParameterKind::Integer ? parseInteger(option, text) : parseNumber(option, text);
  // Named by its long form whatever alias was typed (-j: --threads).
  const std::string name = *p.option != '\0' ? std::string(p.option) : option;
  if (!(p.zeroIsAutomatic && value == 0.0) && !inRange(p, value))  // 0: automatic
    throw UsageError{name + " must be " + rangeText(p) + ", got " + text};
  return value;
}

// Options of one command: flags and options with a value, by every spelling.
class OptionTable {
 public:
  using Handler = std::function<void(const std::string& option, const std::string& value)>;
  void flag(std::initializer_list<const char*> names, const std::function<void()>& handler) {
    for (const char* n : names) flags_[n] = handler;
  }
  void value(std::initializer_list<const char*> names, const Handler& handler) {
    for (const char* n : names) values_[n] = handler;
  }
  // Parses args[first..]; returns the positional arguments.
  std::vector<std::string> parse(const std::vector<std::string>& args, std::size_t first,
                                 const std::string& command) const {
    std::vector<std::string> positional;
    for (std::size_t i = first; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (const auto f = flags_.find(a); f != flags_.end()) {
        f->second();
      } else if (const auto v = values_.find(a); v != values_.end()) {
        if (i + 1 >= args.size()) throw UsageError{a + " needs a value"};
        v->second(a, args[++i]);
      } else if (!a.empty() && a[0] == '-' && a != "-") {
        std::string message = "unknown option '" + a + "' for 'homesh ";
        message += command;
        message += "'";
        throw UsageError{message};
      } else {
        positional.push_back(a);
      }
    }
    return positional;
  }

 private:
  std::map<std::string, std::function<void()>> flags_;
  std::map<std::string, Handler> values_;
};

void addCommon(OptionTable& table, CommonOptions& c, bool outputs, bool report) {
  table.value({"--threads", "-j"}, [&c](const std::string& o, const std::string& v) {
    c.threads = static_cast<int>(parseParameter("threads", o, v));
  });
  table.flag({"--quiet", "-q"}, [&c] { c.quiet = true; });
  if (outputs) {
    table.value({"--output", "-o"},
                [&c](const std::string&, const std::string& v) { c.outputs.push_back(v); });
    table.flag({"--binary"}, [&c] { c.binary = true; });
    table.flag({"--compressed"}, [&c] { c.compressed = true; });
    table.value({"--group"}, [&c](const std::string& o, const std::string& v) {
      const std::size_t eq = v.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == v.size())
        throw UsageError{o +
                         " expects NAME=ENTITY[,ENTITY...] (boundary face numbers; 2D: "
                         "curve numbers), got '" +
                         v + "'"};
      std::vector<int> entities;
      std::size_t start = eq + 1;
      while (start <= v.size()) {
        const std::size_t comma = std::min(v.find(',', start), v.size());
        entities.push_back(parseInteger(o, v.substr(start, comma - start)));
        if (entities.back() < 1)
          throw UsageError{o + ": entity numbers start at 1, got " +
                           std::to_string(entities.back())};
        start = comma + 1;
      }
      c.groups.emplace_back(v.substr(0, eq), std::move(entities));
    });
  }
  if (report)
    table.value({"--report"}, [&c](const std::string&, const std::string& v) { c.report = v; });
}

// "a,b,c,..." as exactly n numbers.
std::vector<double> parseList(const std::string& option, const std::string& text, std::size_t n,
                              const char* layout) {
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    try {
      values.push_back(parseNumber(option, item));
    } catch (const UsageError&) {
      std::string message = option;
      message += " expects ";
      message += layout;
      message += ", got '" + text + "'";
      throw UsageError{message};
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (values.size() != n)
    throw UsageError{option + " expects " + layout + " (" + std::to_string(n) + " numbers), got '" +
                     text + "'"};
  return values;
}

std::string onlyInput(const std::vector<std::string>& positional, const std::string& command,
                      const char* what) {
  if (positional.empty()) throw UsageError{"'homesh " + command + "' needs " + what};
  if (positional.size() > 1)
    throw UsageError{"unexpected argument '" + positional[1] + "' (only one INPUT is allowed)"};
  return positional[0];
}

// The table's options `keys` by their command-line spellings (core/parameters.hpp), into
// `values`: a Boolean's flag turns its default around, the others take a value checked against
// the table's range.
template <class Keys>
void addTableOptions(OptionTable& table, OptionMap& values, const Keys& keys) {
  for (const char* key : keys) {
    const ParameterDefinition& p = parameterDefinition(key);
    const std::string name = p.option;
    const std::string alias = p.shortOption;
    const auto names = [&] {
      std::vector<std::string> n{name};
      if (!alias.empty()) n.push_back(alias);
      return n;
    }();
    for (const std::string& n : names) {
      if (p.kind == ParameterKind::Boolean) {
        const bool on = p.defaultValue == 0.0;
        table.flag({n.c_str()}, [&values, key, on] { values[key] = on; });
      } else if (p.kind == ParameterKind::Choice) {
        table.value({n.c_str()}, [&values, key](const std::string&, const std::string& v) {
          values[key] = v;
          try {
            checkedOption(key, v);
          } catch (const ParameterError& e) {
            throw UsageError{std::string(parameterDefinition(key).option) + ": " + e.what()};
          }
        });
      } else {
        table.value({n.c_str()}, [&values, key](const std::string& o, const std::string& v) {
          values[key] = parseParameter(key, o, v);
        });
      }
    }
  }
}

void addTableOptions(OptionTable& table, OptionMap& values,
                     std::initializer_list<const char*> keys) {
  addTableOptions<std::initializer_list<const char*>>(table, values, keys);
}

// The octree's sizes (rows of the table, into `values`) and its refinement sources and octree
// output (flags of their own).
void addSizing(OptionTable& table, SizingFlags& f, OptionMap& values) {
  addTableOptions(table, values, {"min_delta", "max_delta", "eps"});
  const auto check = [](const std::string& o, const RefinementSource& s) {
    try {
      s.validate(o);
    } catch (const Error& e) {
      throw UsageError{e.what()};
    }
    return s;
  };
  table.value({"--refine-line"}, [&f, check](const std::string& o, const std::string& v) {
    const auto x = parseList(o, v, 8, "X1,Y1,Z1,X2,Y2,Z2,R,D");
    f.sources.push_back(
        check(o, RefinementSource::segment({x[0], x[1], x[2]}, {x[3], x[4], x[5]}, x[6], x[7])));
  });
  table.value({"--refine-sphere"}, [&f, check](const std::string& o, const std::string& v) {
    const auto x = parseList(o, v, 5, "X,Y,Z,R,D");
    f.sources.push_back(check(o, RefinementSource::sphere({x[0], x[1], x[2]}, x[3], x[4])));
  });
  table.value({"--refine-box"}, [&f, check](const std::string& o, const std::string& v) {
    const auto x = parseList(o, v, 7, "X0,Y0,Z0,X1,Y1,Z1,D");
    f.sources.push_back(
        check(o, RefinementSource::box({x[0], x[1], x[2]}, {x[3], x[4], x[5]}, x[6])));
  });
  table.value({"--refine-curve"}, [&f, check](const std::string& o, const std::string& v) {
    const auto x = parseList(o, v, 3, "EDGE,R,D");
    if (x[0] < 1 || x[0] != std::floor(x[0]))
      throw UsageError{o + ": the edge number must be a whole number >= 1, got '" + v + "'"};
    f.sources.push_back(check(o, RefinementSource::curve(static_cast<int>(x[0]), x[1], x[2])));
  });
  table.value({"--write-octree"},
              [&f](const std::string&, const std::string& v) { f.writeOctree = v; });
}

// The options of `homesh optimise` from the table (OptimiserOptions::apply takes them; threads
// come with the common options).
constexpr std::initializer_list<const char*> kOptimiseKeys = {
    "functional",    "optimise", "tolerance",       "region",
    "region_layers", "focus",    "free_interfaces", "optimise_seconds"};

// The CAD modes, which mesh and predict share.
constexpr std::initializer_list<const char*> kCadModes = {"heal", "solids_only", "surface", "auto",
                                                          "imprint"};

// --optimise (mesh and curve): run the optimiser with the table's sweeps.
void addOptimiseSwitch(OptionTable& table, bool& optimise) {
  table.flag({"--optimise", "--optimize"}, [&optimise] { optimise = true; });
}

// The optimiser's options do nothing without --optimise: refused by name (in the table's order).
void checkOptimiseSwitch(bool optimise, OptionMap& values) {
  if (!optimise)
    for (const char* key : {"optimise", "optimise_seconds", "facet_weight", "fidelity_weight"})
      if (values.count(key) != 0)
        throw UsageError{std::string(parameterDefinition(key).option) + " needs --optimise"};
  if (optimise && values.count("optimise") == 0) values["optimise"] = true;  // the table's
}

MeshCommand parseMesh(const std::vector<std::string>& args) {
  MeshCommand cmd;
  OptionTable table;
  addCommon(table, cmd.common, true, true);
  OptionMap& values = cmd.options;
  addSizing(table, cmd.sizing, values);
  addTableOptions(table, values,
                  {"order", "size", "optimise", "repair_rounds", "optimise_seconds", "facet_weight",
                   "fidelity_weight", "linear_seconds", "job_seconds"});
  addTableOptions(table, values, kCadModes);
  bool optimise = false;
  addOptimiseSwitch(table, optimise);
  table.value({"--bl-faces"},
              [&cmd](const std::string&, const std::string& v) { cmd.blFaces = v; });
  table.value({"--bl-solids"},
              [&cmd](const std::string&, const std::string& v) { cmd.blSolids = v; });
  table.value({"--bl-thickness"},
              [&cmd](const std::string&, const std::string& v) { cmd.blThickness = v; });
  table.value({"--bl-layers"}, [&cmd](const std::string& o, const std::string& v) {
    cmd.blLayers = static_cast<int>(parseParameter("layers", o, v));
  });
  table.value({"--bl-progression"}, [&cmd](const std::string& o, const std::string& v) {
    cmd.blProgression = parseParameter("progression", o, v);
  });
  int verbosity = 0;
  table.flag({"--verbose", "-v"}, [&verbosity] { ++verbosity; });
  table.flag({"-vv"}, [&verbosity] { verbosity += 2; });
  cmd.input = onlyInput(table.parse(args, 1, "mesh"), "mesh", "an INPUT CAD or .mcf file");
  if (verbosity > 0)
    values["verbosity"] = static_cast<double>(
        std::min(verbosity, static_cast<int>(parameterDefinition("verbosity").max)));
  checkOptimiseSwitch(optimise, values);
  return cmd;
}

PredictCommand parsePredict(const std::vector<std::string>& args) {
  PredictCommand cmd;
  OptionTable table;
  addCommon(table, cmd.common, false, true);
  addSizing(table, cmd.sizing, cmd.options);
  addTableOptions(table, cmd.options, kCadModes);
  cmd.input = onlyInput(table.parse(args, 1, "predict"), "predict", "an INPUT CAD or .mcf file");
  return cmd;
}

QualityCommand parseQuality(const std::vector<std::string>& args) {
  QualityCommand cmd;
  OptionTable table;
  addCommon(table, cmd.common, false, true);
  table.flag({"--strict"}, [&cmd] { cmd.strict = true; });
  table.value({"--cad"}, [&cmd](const std::string&, const std::string& v) { cmd.cad = v; });
  addTableOptions(table, cmd.options, {"classify_tolerance"});
  cmd.input = onlyInput(table.parse(args, 1, "quality"), "quality", "an INPUT mesh file");
  if (cmd.cad.empty() && !cmd.options.empty())
    throw UsageError{"'homesh quality': --classify-tolerance needs --cad CAD"};
  return cmd;
}

ConvertCommand parseConvert(const std::vector<std::string>& args) {
  ConvertCommand cmd;
  OptionTable table;
  addCommon(table, cmd.common, true, false);
  cmd.input = onlyInput(table.parse(args, 1, "convert"), "convert", "an INPUT mesh file");
  if (cmd.common.outputs.empty()) throw UsageError{"'homesh convert' needs -o OUTPUT"};
  return cmd;
}

OptimiseCommand parseOptimise(const std::vector<std::string>& args) {
  OptimiseCommand cmd;
  OptionTable table;
  addCommon(table, cmd.common, true, true);
  addTableOptions(table, cmd.options, kOptimiseKeys);
  table.value({"--order", "-p"}, [&cmd](const std::string& o, const std::string& v) {
    cmd.order = static_cast<int>(parseParameter("order", o, v));
  });
  cmd.input = onlyInput(table.parse(args, 1, "optimise"), "optimise", "an INPUT mesh file");
  return cmd;
}

CurveCommand parseCurve(const std::vector<std::string>& args) {
  CurveCommand cmd;
  OptionTable table;
  addCommon(table, cmd.common, true, true);
  addTableOptions(table, cmd.options, kCurveOptionKeys);
  bool optimise = false;
  addOptimiseSwitch(table, optimise);
  table.value({"--cad"}, [&cmd](const std::string&, const std::string& v) { cmd.cad = v; });
  cmd.input = onlyInput(table.parse(args, 1, "curve"), "curve", "an INPUT mesh file");
  if (cmd.cad.empty())
    throw UsageError{"'homesh curve' needs --cad CAD, the CAD file the mesh was made from"};
  checkOptimiseSwitch(optimise, cmd.options);
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
  if (first == "--man") {  // the manual page, from the same help texts (CMake installs it)
    parsed.kind = ParsedCommand::Kind::Help;
    parsed.helpTopic = "--man";
    return parsed;
  }
  if (first == "--version" || first == "version") {
    parsed.kind = ParsedCommand::Kind::Version;
    return parsed;
  }
  const bool optimise = first == "optimise" || first == "optimize";
  if (first != "mesh" && first != "predict" && first != "quality" && first != "convert" &&
      first != "curve" && !optimise)
    throw UsageError{"unknown command '" + first + "'"};
  for (std::size_t i = 1; i < args.size(); ++i)
    if (args[i] == "-h" || args[i] == "--help") {
      parsed.helpTopic = optimise ? "optimise" : first;
      return parsed;
    }
  if (first == "mesh") {
    parsed.kind = ParsedCommand::Kind::Mesh;
    parsed.mesh = parseMesh(args);
  } else if (first == "predict") {
    parsed.kind = ParsedCommand::Kind::Predict;
    parsed.predict = parsePredict(args);
  } else if (first == "quality") {
    parsed.kind = ParsedCommand::Kind::Quality;
    parsed.quality = parseQuality(args);
  } else if (optimise) {
    parsed.kind = ParsedCommand::Kind::Optimise;
    parsed.optimise = parseOptimise(args);
  } else if (first == "curve") {
    parsed.kind = ParsedCommand::Kind::Curve;
    parsed.curve = parseCurve(args);
  } else {
    parsed.kind = ParsedCommand::Kind::Convert;
    parsed.convert = parseConvert(args);
  }
  return parsed;
}

namespace {

// `text` wrapped at `width` columns after a first line that starts at column `first`, every
// later line indented by `indent`.
std::string wrapped(const std::string& text, std::size_t first, std::size_t indent,
                    std::size_t width) {
  std::string out, line;
  std::size_t column = first;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && column + line.size() + 1 + word.size() > width) {
      out += line + "\n" + std::string(indent, ' ');
      line.clear();
      column = indent;
    }
    line += (line.empty() ? "" : " ") + word;
    start = end + 1;
  }
  return out + line + "\n";
}

// The help lines of the table's options `keys` (core/parameters.hpp): spellings, meaning, range
// and default, as the table states them.
template <class Keys>
std::string tableHelp(const Keys& keys) {
  constexpr std::size_t kColumn = 22;
  std::string out;
  for (const char* key : keys) {
    const ParameterDefinition& p = parameterDefinition(key);
    std::string head =
        *p.shortOption != '\0' ? std::string("  ") + p.shortOption + ", " : std::string(6, ' ');
    head += p.option;
    std::string text = p.doc;
    if (p.kind == ParameterKind::Choice) {
      head += " NAME";
      text += "; " + rangeText(p) + ", default " +
              choiceNames(p).at(static_cast<std::size_t>(p.defaultValue));
    } else if (p.kind == ParameterKind::Boolean) {
      // The flag turns the default around: say which way.
      if (p.defaultValue != 0.0)
        text.insert(0, "turns off what is on unless given: ");
      else
        text += " (off unless given)";
    } else {
      const bool seconds = std::string(key).find("_seconds") != std::string::npos;
      head += p.kind == ParameterKind::Integer ? " N" : seconds ? " S" : " X";
      text += "; " + rangeText(p) + ", default " +
              (p.zeroIsAutomatic && p.defaultValue == 0.0 ? std::string("automatic")
                                                          : formatNumber(p.defaultValue));
    }
    head += head.size() + 2 <= kColumn ? std::string(kColumn - head.size(), ' ') : "  ";
    out += head + wrapped(text, head.size(), kColumn, 92);
  }
  return out;
}

std::string tableHelp(std::initializer_list<const char*> keys) {
  return tableHelp<std::initializer_list<const char*>>(keys);
}

// The output options of the commands that write meshes.
std::string outputHelp() {
  return R"(  -o, --output FILE   write the mesh: .msh (Gmsh 4.1), .vtu (VTK), .xml (Nektar++),
                      .cgns (CGNS, orders 1 to 4); repeatable
      --binary        binary MSH, raw appended VTU data
      --compressed    compressed Nektar++ XML (B64Z-LittleEndian)
      --group NAME=F1,F2  a named boundary group (faces; 2D: curves) written as one physical
                      group (MSH) / composite (Nektar++ XML) / boundary condition (CGNS) called
                      NAME; repeatable (convert and optimise keep a CGNS input's conditions)
)";
}

// Threads and --quiet, which every command takes.
std::string commonHelp() {
  return tableHelp({"threads"}) + "  -q, --quiet         print nothing but errors\n";
}

std::string meshHelp() {
  return R"(usage: homesh mesh INPUT [options]

Meshes a CAD model (.step .stp .iges .igs .brep .brp) with curved elements of order P:
a linear tetrahedral mesh (triangles for planar faces) whose boundary nodes are then
placed on the CAD at order P. INPUT may be a NekMesh case (.mcf): its CAD (read in metres,
as NekMesh does, or the NACA aerofoil of CADFile "NNNN"), MinDelta, MaxDelta, EPS,
REFINEMENT lines and Order are used; the options below override them.

Sizes come from the sizing octree: curvature-driven (a chord deviates from the CAD by at
most EPS x the radius of curvature), between MinDelta and MaxDelta, graded by 0.2 per unit
length away from curved boundaries. Without sizes: MaxDelta = bounding-box diagonal / 20,
MinDelta = the smallest size the shape asks for (at most MaxDelta / 20; the report's
sizing.min_delta_set_by names it), EPS = )" +
         formatNumber(parameterDefault("eps")) + R"(.

options (the parameter table's, which Python and FreeCAD read too):
)" + tableHelp({"order", "size", "min_delta", "max_delta", "eps"}) +
         R"(      --optimise      run the variational optimiser after curving (hyperelastic),
                      boundary nodes sliding on the CAD curves and faces
)" +
         tableHelp({"optimise", "optimise_seconds", "facet_weight", "fidelity_weight",
                    "repair_rounds", "linear_seconds", "job_seconds", "heal", "solids_only",
                    "surface", "auto", "imprint"}) +
         R"(
refinement of the sizing octree:
      --refine-line X1,Y1,Z1,X2,Y2,Z2,R,D    size at most D within R of a segment
      --refine-sphere X,Y,Z,R,D             size at most D within a sphere
      --refine-box X0,Y0,Z0,X1,Y1,Z1,D      size at most D within a box
      --refine-curve N,R,D                  size at most D within R of CAD edge N
      --write-octree FILE.vtu               the octree's leaves with their sizes

boundary layer (the macro layer is curved and optimised with the rest, then split):
      --bl-faces LIST     on these CAD faces (FaceN numbers: 1,8 or 11-12)
      --bl-thickness T    its total thickness: a number or an expression of x, y, z
      --bl-solids LIST    where a layer face lies between two solids, the one it grows
                          into (SolidN numbers)
)" + tableHelp({"layers", "progression"}) +
         "\noutput:\n" + outputHelp() +
         R"(      --report FILE   write the JSON report ("-" for standard output)
)" + tableHelp({"threads"}) +
         R"(  -v, --verbose       show Gmsh's warnings (-vv: and its information)
  -q, --quiet         print nothing but errors

exit status: 0 success, 1 failure (file, CAD or meshing), 2 bad command line or parameter,
4 the mesh was made (and written) but elements are still not proven valid (the report's
flagged_elements lists them)
)";
}

std::string predictHelp() {
  return R"(usage: homesh predict INPUT [options]

Builds the sizing octree of a CAD model or NekMesh case (.mcf) and prints the number of
elements (tetrahedra, or triangles for planar faces) the linear mesh will have, with the
octree's statistics, without making the mesh.

options:
      --max-delta D, --min-delta D, --eps E, --refine-line ..., --refine-sphere ...,
      --refine-box ..., --refine-curve ...   as for 'homesh mesh'
      --write-octree FILE.vtu   the octree's leaves with their sizes (ParaView)
      --no-heal, --no-imprint, --solids-only, --surface, --auto   as for 'homesh mesh'
      --report FILE   write the JSON report ("-" for standard output)
)" + commonHelp();
}

std::string qualityHelp() {
  return R"(usage: homesh quality INPUT [options]

Prints the quality of a mesh (.msh 2.2 or 4.1, ASCII or binary; .xml Nektar++; .cgns; FreeCAD
FEM's .unv, .vtk and .vtu, linear or quadratic): per element type, the certified scaled Jacobian
(Bezier bounds, as Gmsh's AnalyseMeshQuality) and the distortion against the straight-sided
elements, worst, mean and histogram, and the number of invalid elements.

With --cad, also how closely the mesh's boundary follows the CAD it was made from, measured as
'homesh mesh' measures its own (the report's "geometry"): each boundary cell the file holds is
put on the CAD face or curve its corners lie on, and sampled at quadrature points for its
distance to the CAD and the angle between its normal and the CAD's. Meshes from Gmsh, NekMesh or
HOMesh compare on one measure.

options:
      --report FILE   write the JSON report ("-" for standard output)
      --strict        exit with status 3 if any element is invalid or not proven valid
      --cad CAD       the CAD file (STEP, IGES, BRep; a NekMesh .mcf reads its CAD in metres)
)" + tableHelp({"classify_tolerance"}) +
         commonHelp();
}

std::string convertHelp() {
  return R"(usage: homesh convert INPUT -o OUTPUT [options]

Converts a mesh between Gmsh MSH (2.2/4.1 in, 4.1 out), VTU, Nektar++ XML, CGNS, and from UNV
and legacy VTK, with the quality fields.

options:
)" + outputHelp() +
         commonHelp();
}

std::string optimiseHelp() {
  return R"(usage: homesh optimise INPUT [-o OUTPUT] [options]

Curves the interior of a high-order mesh (.msh 2.2 or 4.1, .xml Nektar++, .cgns, .unv, .vtk,
.vtu) by minimising a variational energy node by node (Newton steps, parallel by node colours).
Nodes on the boundary, on interfaces between volumes and on the file's boundary cells stay
fixed. Prints the worst certified scaled Jacobian and the invalid count after every sweep; the
mesh returned is never worse than the input in either.

options (the parameter table's, which Python's HighOrderMesh.optimise reads too):
)" + tableHelp(kOptimiseKeys) +
         "  -p, --order P       first re-interpolate the mesh at order P (" +
         rangeText(parameterDefinition("order")) + R"();
                      "never worse" then compares with the re-interpolated mesh
)" + outputHelp() +
         R"(      --report FILE   write the JSON report with "optimiser" ("-" for standard output)
)" + commonHelp();
}

std::string curveHelp() {
  return R"(usage: homesh curve INPUT --cad CAD [-o OUTPUT] [options]

Curves a linear volume mesh made by another tool (tetrahedra, prisms, pyramids, hexahedra from
Gmsh, Netgen, FreeCAD FEM, an industrial mesher; .msh, .unv, .vtk, .vtu, .xml, .cgns) on the CAD
it was made from (.step .stp .iges .igs .brep .brp, one solid), or a planar 2D mesh (triangles,
quadrilaterals) on its faces: each boundary node is put on the CAD vertex, edge or face it lies
on (within --classify-tolerance of the CAD's bounding diagonal; a node that lies on none is an
error naming it, its position and its distance to the nearest face (in 2D, edge), and nothing
is written; so is a cell that cannot be curved valid), prisms and hexahedra stacked on the wall
(a boundary layer) are joined into one macro cell per column, the mesh is raised to order P with
its new boundary nodes on the CAD and, with --optimise, optimised with them sliding on it, the
elements left invalid are straightened off the CAD, and the macro layer is split back into the
given layers. A quadratic mesh is curved from its corners (its mid-edge nodes are dropped, with
a note).

options (the parameter table's, which Python's homesh.curve reads too):
)" + tableHelp(kCurveOptionKeys) +
         R"(      --optimise      run the variational optimiser after curving (hyperelastic),
                      boundary nodes sliding on the CAD curves and faces
)" + outputHelp() +
         R"(      --report FILE   write the JSON report ("-" for standard output)
)" + commonHelp();
}

std::string commandsHelp() {
  return R"(usage: homesh COMMAND [options]

commands:
  mesh INPUT      CAD file or NekMesh .mcf to curved high-order mesh (homesh mesh --help)
  predict INPUT   predicted element count and sizing octree (homesh predict --help)
  quality INPUT   certified quality of a mesh file (homesh quality --help)
  convert INPUT   mesh file to another format (homesh convert --help)
  optimise INPUT  curve the interior of a mesh file (homesh optimise --help)
  curve INPUT     curve another tool's linear mesh on its CAD (homesh curve --help)
  --version       print the version
  --help          this text
)";
}

}  // namespace

std::string usageText(const std::string& topic) {
  if (topic == "mesh") return meshHelp();
  if (topic == "predict") return predictHelp();
  if (topic == "quality") return qualityHelp();
  if (topic == "convert") return convertHelp();
  if (topic == "optimise" || topic == "optimize") return optimiseHelp();
  if (topic == "curve") return curveHelp();
  return commandsHelp();
}

// `text` with what roff would take as its own escaped: backslashes, and a leading dot or quote.
std::string roffText(const std::string& text) {
  std::string out;
  bool lineStart = true;
  for (const char c : text) {
    if (lineStart && (c == '.' || c == '\'')) out += "\\&";
    if (c == '\\')
      out += "\\e";
    else if (c == '-')
      out += "\\-";
    else
      out += c;
    lineStart = c == '\n';
  }
  return out;
}

std::string manPage() {
  std::string out = R"(.TH HOMESH 1 "" "homesh )";
  out += kVersion;
  out +=
      "\" \"User Commands\"\n"
      ".SH NAME\nhomesh \\- curved (high-order) meshes from CAD for high-order "
      "CFD\n.SH SYNOPSIS\n.nf\n";
  out += roffText(usageText(""));
  out += ".fi\n";
  for (const char* topic : {"mesh", "predict", "quality", "convert", "optimise", "curve"}) {
    out +=
        std::string(".SH \"HOMESH ") + topic + "\"\n.nf\n" + roffText(usageText(topic)) + ".fi\n";
  }
  out +=
      ".SH \"SEE ALSO\"\nThe manual in the docs/ folder of the HOMesh sources; the Python "
      "module's help(homesh.mesh), whose options are the same table's.\n";
  return out;
}

}  // namespace homesh

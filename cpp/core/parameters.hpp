// One definition of every user-facing meshing parameter: its Python keyword (also the report's
// key), FreeCAD property, command-line option, kind, range, default, unit and meaning. The
// core's option checks, the Python module (homesh.parameters()), the FreeCAD properties and
// task panels all read this table, so a range is written once.
#pragma once

#include <string>
#include <vector>

namespace homesh {

enum class ParameterKind {
  Integer,  // a whole number in [min, max]
  Real,     // a number in (min, max] when minExclusive, else [min, max]
  Length,   // a length in the model's units, same range rules as Real
};

struct ParameterDefinition {
  const char* key;       // Python keyword: "order"
  const char* property;  // FreeCAD property: "Order"
  const char* option;    // command line: "--order" ("" when the CLI has none)
  const char* label;     // how messages name it: "order"
  ParameterKind kind;
  double min, max;    // max = infinity: no upper bound
  bool minExclusive;  // (min, max] instead of [min, max]
  double defaultValue;
  bool zeroIsAutomatic;  // 0 stands for "choose automatically" (a size from the model)
  const char* group;     // "mesh", "sizing", "boundary_layer"
  const char* doc;
};

// Every parameter, in the order a panel shows them.
const std::vector<ParameterDefinition>& parameterDefinitions();

// The definition of `key`; throws std::out_of_range for a key that is not in the table (a
// programming error, not a user's).
const ParameterDefinition& parameterDefinition(const std::string& key);

// "an integer from 1 to 10", "a number in (0, 1]", "a length > 0", "an integer >= 0".
std::string rangeText(const ParameterDefinition& p);

// Whether `value` is allowed (an Integer must also be whole; NaN never is).
bool inRange(const ParameterDefinition& p, double value);

// Throws ParameterError "<label> must be <rangeText>, got <value>" when `value` is not in range.
void checkParameter(const std::string& key, double value);

}  // namespace homesh

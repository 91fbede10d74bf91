// One definition of every user-facing meshing parameter: its Python keyword (also the report's
// key and the key of an options mapping), FreeCAD property, command-line option, kind, range,
// default, unit and meaning. The core's option checks (pipeline/meshing_options.hpp), the Python
// module (homesh.parameters(), the keywords of homesh.mesh), the FreeCAD properties and task
// panels all read this table, so a default or a range is written once.
#pragma once

#include <algorithm>
#include <functional>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "core/format.hpp"

namespace homesh {

enum class ParameterKind {
  Integer,  // a whole number in [min, max]
  Real,     // a number in (min, max] when minExclusive, else [min, max]
  Length,   // a length in the model's units, same range rules as Real
  Boolean,  // on or off (range [0, 1] as numbers)
  Choice,   // one of the names in `choices`, held as its index (range [0, count - 1])
};

struct ParameterDefinition {
  const char* key;          // Python keyword: "order"
  const char* property;     // FreeCAD property: "Order" ("" when FreeCAD has none)
  const char* option;       // command line: "--order" ("" when the CLI has none); for a Boolean,
                            // the flag that turns its default around ("--no-heal", "--surface")
  const char* shortOption;  // its one-letter alias on the command line: "-p" ("" for none)
  const char* label;        // how messages name it: "order"
  ParameterKind kind;
  double min, max;    // max = infinity: no upper bound
  bool minExclusive;  // (min, max] instead of [min, max]
  double defaultValue;
  bool zeroIsAutomatic;  // 0 stands for "choose automatically" (a size from the model)
  // An Integer that may also be given as on/off: on stands for the default, off for 0 (the
  // optimiser: `optimise=True` in Python asks for the default number of sweeps).
  bool switchable;
  const char* group;  // "mesh", "cad", "sizing", "boundary_layer", "optimiser"
  const char* doc;
  // A Choice's names, '|' between them, in the order of the enum the code keeps them in
  // ("hyperelastic|linearelastic|..."); the default is an index into them.
  const char* choices = "";
};

// Every parameter, in the order a panel shows them.
const std::vector<ParameterDefinition>& parameterDefinitions();

// The definition of `key`, or nullptr when the table has none.
const ParameterDefinition* findParameter(const std::string& key);

// The definition of `key`; throws std::out_of_range for a key that is not in the table (a
// programming error, not a user's).
const ParameterDefinition& parameterDefinition(const std::string& key);

// A Choice's names, in order (empty for other kinds).
std::vector<std::string> choiceNames(const ParameterDefinition& p);

// "an integer from 1 to 10", "a number in (0, 1]", "a length > 0", "an integer >= 0",
// "one of hyperelastic, linearelastic, winslow, distortion".
std::string rangeText(const ParameterDefinition& p);

// Whether `value` is allowed (an Integer must also be whole; NaN never is).
bool inRange(const ParameterDefinition& p, double value);

// Throws ParameterError "<label> must be <rangeText>, got <value>" when `value` is not in range.
void checkParameter(const std::string& key, double value);

// The table's default of `key` (throws std::out_of_range for a key not in it).
double parameterDefault(const std::string& key);

// The table's default of `key` as a field's type.
template <class T>
T defaultOf(const char* key) {
  return static_cast<T>(parameterDefault(key));
}

// A value as it comes from outside (a Python keyword, a mapping): a number, on/off or text.
using OptionValue = std::variant<double, bool, std::string>;

// Options keyed as the parameter table: {"order": 4.0, "heal": false, ...}.
using OptionMap = std::map<std::string, OptionValue>;

// `value` as the number parameter `key` stands for (a Boolean: 1 or 0; a switchable Integer
// given on/off: its default or 0; a Choice given by name, in any case, '-' and '_' ignored: its
// index), checked against the kind and range; throws ParameterError
// "<label> must be <rangeText>, got <value>" for a value of the wrong kind or out of range, and
// "unknown option '<key>'" for a key the table does not have.
double checkedOption(const std::string& key, const OptionValue& value);

// The table's keys, in its order, that `wanted` accepts.
std::vector<std::string> tableKeys(const std::function<bool(const std::string&)>& wanted);

// Where each key of the table goes in a front end's options struct T, given its checked number.
template <class T>
using OptionSetters = std::map<std::string, std::function<void(T&, double)>>;

// The keys applyOptions takes: those of `allowed` or, when it is empty, those with a setter; in
// the table's order.
template <class T>
std::vector<std::string> optionKeys(const OptionSetters<T>& setters,
                                    const std::vector<std::string>& allowed = {}) {
  return tableKeys([&](const std::string& key) {
    return allowed.empty() ? setters.count(key) != 0
                           : std::find(allowed.begin(), allowed.end(), key) != allowed.end();
  });
}

// Gives each of `values`, checked by checkedOption (which names unknown keys and bad values), to
// its setter. A key without a setter, or one `allowed` (when not empty) leaves out, is refused:
// "option '<key>' does not apply <where> (options: <optionKeys>)".
template <class T>
void applyOptions(T& target, const OptionMap& values, const OptionSetters<T>& setters,
                  const std::vector<std::string>& allowed, const std::string& where) {
  for (const auto& [key, value] : values) {
    const double number = checkedOption(key, value);
    const auto setter = setters.find(key);
    const bool wanted =
        allowed.empty() || std::find(allowed.begin(), allowed.end(), key) != allowed.end();
    if (setter == setters.end() || !wanted) {
      std::string message = "option '" + key + "' does not apply ";
      message += where;
      message += " (options: ";
      message += joined(optionKeys(setters, allowed));
      throw ParameterError(message + ")");
    }
    setter->second(target, number);
  }
}

}  // namespace homesh

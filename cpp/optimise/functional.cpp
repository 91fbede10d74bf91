#include "optimise/functional.hpp"

#include <algorithm>
#include <cctype>

#include "core/error.hpp"

namespace homesh {

Functional parseFunctional(const std::string& name) {
  std::string key;
  for (const char c : name)
    if (c != '-' && c != '_' && c != ' ')
      key.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  if (key == "linearelastic") return Functional::LinearElastic;
  if (key == "hyperelastic") return Functional::Hyperelastic;
  if (key == "winslow") return Functional::Winslow;
  if (key == "distortion" || key == "roca") return Functional::Distortion;
  throw ParameterError("unknown functional '" + name +
                       "' (expected linearelastic, hyperelastic, winslow or distortion)");
}

std::string functionalName(Functional f) {
  switch (f) {
    case Functional::LinearElastic:
      return "linearelastic";
    case Functional::Hyperelastic:
      return "hyperelastic";
    case Functional::Winslow:
      return "winslow";
    case Functional::Distortion:
      return "distortion";
  }
  return "hyperelastic";
}

}  // namespace homesh

#include "optimise/functional.hpp"

#include "core/parameters.hpp"

namespace homesh {

Functional parseFunctional(const std::string& name) {
  return static_cast<Functional>(checkedOption("functional", name));
}

std::string functionalName(Functional f) {
  return choiceNames(parameterDefinition("functional")).at(static_cast<std::size_t>(f));
}

}  // namespace homesh

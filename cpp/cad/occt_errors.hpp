// Implementation of withOcctErrors (included by occt_access.hpp).
#pragma once

#include <Standard_Failure.hxx>
#include <string>

#include "core/error.hpp"

namespace homesh {

template <class F>
auto withOcctErrors(const std::string& what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const Standard_Failure& failure) {
    const char* message = failure.GetMessageString();
    throw CadError(what + ": OpenCASCADE failed (" + failure.DynamicType()->Name() +
                   (message && *message ? std::string(": ") + message : std::string()) + ")");
  }
}

}  // namespace homesh

// One error channel for the whole core.
//
// Every failure a user can cause (bad parameter, unreadable file, CAD the mesher cannot handle)
// is thrown as a subclass of homesh::Error with a message that names the culprit (the file, the
// parameter, the CAD face). Third-party exceptions (OCCT's Standard_Failure, Gmsh's std::string
// throws) are converted at the boundary of the component that calls them, so nothing above the
// CAD and linear-mesh layers ever sees a foreign exception type.
#pragma once

#include <stdexcept>
#include <string>

namespace homesh {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A parameter is out of range or inconsistent (order 0, negative size, ...).
class ParameterError : public Error {
 public:
  using Error::Error;
};

// A file cannot be read or written, or its format is wrong.
class IoError : public Error {
 public:
  using Error::Error;
};

// The CAD model cannot be loaded or queried (no solid, null shape, failed projection).
class CadError : public Error {
 public:
  using Error::Error;
};

// The linear or high-order mesher failed.
class MeshingError : public Error {
 public:
  using Error::Error;
};

// The user cancelled a long operation through the progress callback.
class CancelledError : public Error {
 public:
  using Error::Error;
};

}  // namespace homesh

// Exclusive, exception-safe use of the in-process Gmsh library.
//
// Gmsh keeps global state, so one GmshSession at a time may exist in the process (others wait).
// The constructor initialises Gmsh without reading the user's configuration files; the destructor
// finalises it, also when a job fails. withGmshErrors converts Gmsh's throws (std::string in
// Gmsh 4.8, sometimes int) and OCCT failures raised inside Gmsh into MeshingError.
#pragma once

#include <mutex>
#include <string>

#include <Standard_Failure.hxx>

#include "core/error.hpp"
#include "core/parameters.hpp"

namespace homesh {

// Where Gmsh's messages go. Collected: Gmsh's own terminal output (stdout) stays off; its
// messages are collected and written to stderr when the session ends, so that stdout stays
// clean for a report. Terminal: every message, information included, is written as Gmsh writes
// it (information on stdout, warnings and errors on stderr) and nothing when the session ends,
// for a child process whose output its caller watches (GmshProgressWatch) and filters.
enum class GmshOutput { Collected, Terminal };

class GmshSession {
 public:
  // verbosity 0: silent; 1: Gmsh's errors and warnings; 2: and its information.
  explicit GmshSession(int verbosity = defaultOf<int>("verbosity"),
                       int threads = defaultOf<int>("threads"));
  // The same with the exclusive right to Gmsh already held (holdGmsh), as in a child process
  // forked while its parent held it.
  GmshSession(std::unique_lock<std::mutex> held, int verbosity, int threads,
              GmshOutput output = GmshOutput::Collected);
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  std::unique_lock<std::mutex> lock_;
  int verbosity_;
  GmshOutput output_;
};

// The exclusive right to use Gmsh in this process, without starting it.
std::unique_lock<std::mutex> holdGmsh();

// The last error Gmsh logged, or "" (to explain a failure that produced no exception).
std::string gmshLastError();

template <class F>
auto withGmshErrors(const std::string& what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::string& message) {
    throw MeshingError(what + ": Gmsh failed: " + message);
  } catch (const Standard_Failure& failure) {
    throw MeshingError(what + ": Gmsh failed in OpenCASCADE: " + failure.DynamicType()->Name());
  } catch (int code) {
    const std::string last = gmshLastError();
    throw MeshingError(what + ": Gmsh failed (code " + std::to_string(code) + ")" +
                       (last.empty() ? "" : ": " + last));
  }
}

}  // namespace homesh

// Runs a piece of work in a child process, so that a crash, a hang or a runaway allocation in
// third-party code (Gmsh) ends that child and not the caller: a FreeCAD session survives what
// would otherwise take it down.
//
// The child is a fork() of the caller: the work sees the caller's memory as it was (a copy),
// runs on the child's single thread and hands back its result as bytes through a pipe. What it
// changes in memory is lost; only the returned bytes come back. Stdout and stderr are shared.
//
// The work must not need other threads of the caller (their locks may be held forever in the
// child) and must not start an OpenMP team of more than one thread. Where the work needs a lock
// of a library that other threads of the caller may be inside at the moment of the fork (and
// that the caller cannot hold across it: OpenCASCADE's error-handler mutex, which every OCCT
// algorithm on every thread takes), `startProbe` takes that lock once in the child before the
// work: a child whose probe has not returned within `startSeconds` is stuck on a copy of a lock
// that no thread will ever release, and is killed and started again.
#pragma once

#include <cstddef>
#include <exception>
#include <functional>
#include <string>

#include "core/error.hpp"

namespace homesh {

struct IsolationLimits {
  double seconds = 0.0;  // wall-time budget; 0: none
  // The budget a message names when `seconds` is what is left of it (a retry's share); 0:
  // `seconds` itself.
  double statedSeconds = 0.0;
  std::string budgetName;           // how a message names the setting: "--linear-time-limit"
  std::function<bool()> cancelled;  // asked about every 50 ms while the child runs
  // Address space the child may add to the caller's (its allocations beyond fail with
  // std::bad_alloc); 0: the memory available on the machine when the child starts.
  std::size_t extraBytes = 0;
  // Run first in the child; the child counts as started once it returns. None: no probe.
  std::function<void()> startProbe;
  // With a probe: how long a child may take to start, and how many children are started at
  // most; the last one is given the whole budget. A wrong guess on a slow machine costs a
  // start, never a result.
  double startSeconds = 5.0;
  int startAttempts = 3;
  // Told, in the caller, of each child given up before it started (its number, from 1).
  std::function<void(int)> restarted;
  // With a watch: what the child writes on its standard output and error comes to the caller
  // instead, and each line (without its newline) is given to `watch` as it arrives, which
  // passes on what the user should see. An answer that is not empty says the work makes no
  // progress: the child is killed and Stalled thrown with that answer as its message.
  std::function<std::string(const std::string& line)> watch;
};

// Runs `work` in a child process and returns the bytes it returned.
// - work throws a homesh::Error: the same kind of error (ParameterError, IoError, CadError,
//   MeshingError, CancelledError) is thrown here with its message;
// - the child runs out of memory, dies of a signal or exits otherwise: MeshingError
//   OutOfMemory "<what> ran out of memory (...)", or ChildCrashed "<what> crashed
//   (Segmentation fault)";
// - the budget runs out: the child is killed, BudgetExceeded "<what> stopped at its time budget
//   of S s (<budgetName>)";
// - the watch says the work stalls: the child is killed, Stalled with the watch's message;
// - cancelled: the child is killed, CancelledError.
// If the child cannot be started: Error.
std::string runIsolated(const std::string& what, const IsolationLimits& limits,
                        const std::function<std::string()>& work);

// The child ran out of memory (an allocation failed at its limit, or the system killed it).
class OutOfMemory : public MeshingError {
 public:
  using MeshingError::MeshingError;
};

// The child ran out of its time budget (and was killed).
class BudgetExceeded : public MeshingError {
 public:
  using MeshingError::MeshingError;
};

// The child died (a signal, or an exit without a result): the work may be retried another way.
class ChildCrashed : public MeshingError {
 public:
  using MeshingError::MeshingError;
};

// The child's output showed that its work makes no progress (and it was killed): the work may
// be retried another way.
class Stalled : public MeshingError {
 public:
  using MeshingError::MeshingError;
};

// Whether a failure ends the job as it is, whatever another way of doing the work would do: its
// time budget is spent (BudgetExceeded) or memory is exhausted (OutOfMemory). Callers that try
// again another way rethrow these.
inline bool endsTheJob(const std::exception& failure) {
  return dynamic_cast<const BudgetExceeded*>(&failure) != nullptr ||
         dynamic_cast<const OutOfMemory*>(&failure) != nullptr;
}

}  // namespace homesh

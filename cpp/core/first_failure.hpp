// Carries an exception out of an OpenMP parallel region.
//
// An exception must not leave an OpenMP region: that terminates the process (and FreeCAD with
// it). Inside the region, catch (...) and call capture(); after it, call rethrow(), which
// rethrows the first exception captured, if any.
#pragma once

#include <exception>

namespace homesh {

class FirstFailure {
 public:
  // Call from a catch block (uses std::current_exception()); thread-safe.
  void capture() {
#pragma omp critical(homesh_first_failure)
    if (!failure_) failure_ = std::current_exception();
  }
  void rethrow() const {
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  std::exception_ptr failure_;
};

}  // namespace homesh

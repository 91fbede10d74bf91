#include "core/job_budget.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"

namespace homesh {

JobBudget::JobBudget(double seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds))
    throw ParameterError(std::string(parameterDefinition("job_seconds").label) +
                         " must be a finite number of seconds >= 0, got " + formatNumber(seconds));
}

double JobBudget::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double JobBudget::left() const {
  if (!limited()) return std::numeric_limits<double>::infinity();
  return seconds_ - elapsed();
}

bool JobBudget::binds(double own) const {
  if (!limited()) return false;
  return own <= 0.0 || available() < own;
}

double JobBudget::stageLimit(double own) const {
  if (!binds(own)) return own;
  return std::max(available(), kFloorSeconds);
}

}  // namespace homesh

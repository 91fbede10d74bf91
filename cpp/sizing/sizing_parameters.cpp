#include "sizing/sizing_parameters.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"

namespace homesh {
namespace {

bool positive(double x) {
  return x > 0.0 && std::isfinite(x);
}

}  // namespace

void SizingParameters::validate() const {
  if (minDelta != 0.0) checkParameter("min_delta", minDelta);  // 0: automatic
  checkParameter("max_delta", maxDelta);
  if (minDelta > maxDelta)
    throw ParameterError("MinDelta (" + formatNumber(minDelta) + ") must not exceed MaxDelta (" +
                         formatNumber(maxDelta) + ")");
  checkParameter("eps", eps);
  if (!(thinWall >= 0.0 && thinWall <= 1.0))
    throw ParameterError("the thin-wall sagitta ratio must lie in [0, 1], got " +
                         formatNumber(thinWall));
  if (!(narrowFace >= 0.0 && narrowFace <= 1.0))
    throw ParameterError("the narrow-face sagitta ratio must lie in [0, 1], got " +
                         formatNumber(narrowFace));
  if (!positive(gradation))
    throw ParameterError("the gradation must be a positive number, got " + formatNumber(gradation));
  for (std::size_t i = 0; i < sources.size(); ++i)
    sources[i].validate("refinement source " + std::to_string(i + 1));
}

double chordSize(double radius, double eps) {
  return 2.0 * radius * std::sqrt(eps * (2.0 - eps));
}

}  // namespace homesh

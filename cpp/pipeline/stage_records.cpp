#include "pipeline/stage_records.hpp"

namespace homesh {

void StageTimings::add(const std::string& stage, double s) {
  seconds.emplace_back(stage, s);
}

double StageTimings::total() const {
  double t = 0.0;
  for (const auto& [stage, s] : seconds) t += s;
  return t;
}

}  // namespace homesh

#include "pipeline/job_messages.hpp"

#include <cstdio>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/isolated_call.hpp"
#include "core/parameters.hpp"

namespace homesh {

std::string settingsOf(const char* key) {
  const ParameterDefinition& p = parameterDefinition(key);
  return std::string(p.option) + ", Python " + p.key + ", FreeCAD " + p.property;
}

std::string limitName(const char* key) {
  return std::string(parameterDefinition(key).label) + ": " + settingsOf(key);
}

std::string parameterText(const char* key) {
  return std::string(parameterDefinition(key).label) + " (" + settingsOf(key) + ")";
}

std::string formatSeconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", s);
  return buf;
}

std::string jobLimitName(const JobBudget& budget) {
  return std::string(parameterDefinition("job_seconds").label) + " of " +
         formatNumber(budget.seconds()) + " s";
}

std::string jobLimitSettings() {
  return settingsOf("job_seconds");
}

std::string jobLimitText(const JobBudget& budget) {
  return "the " + jobLimitName(budget) + " (" + jobLimitSettings() + ")";
}

void checkBudgetLeft(const JobBudget& budget, const std::string& stage,
                     const StageTimings& timings) {
  if (!budget.spent()) return;
  std::string spent;
  for (const auto& [name, s] : timings.seconds)
    spent += (spent.empty() ? "" : ", ") + name + " " + formatSeconds(s) + " s";
  throw BudgetExceeded(jobLimitText(budget) + " was spent before the " + stage + " stage (" +
                       spent + "): no mesh was made");
}

}  // namespace homesh

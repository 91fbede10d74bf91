// How the pipeline's messages name its parameters and the job's time budget, so that every
// note and error says the same words and tells how to change the setting (the command-line
// option, the Python keyword and the FreeCAD property, from core/parameters.hpp).
#pragma once

#include <string>

#include "core/job_budget.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

// How to set a parameter: "--job-time-limit, Python job_seconds, FreeCAD JobTimeLimit".
std::string settingsOf(const char* key);

// How messages name a time-limit parameter: "linear meshing time limit: --linear-time-limit,
// Python linear_seconds, FreeCAD LinearTimeLimit".
std::string limitName(const char* key);

// "repair rounds (--repair-rounds, Python repair_rounds, FreeCAD RepairRounds)".
std::string parameterText(const char* key);

// Seconds in messages: three digits are enough ("3.19 s").
std::string formatSeconds(double s);

// "job time limit of 120 s"; jobLimitSettings: how to set it ("--job-time-limit, Python
// job_seconds, FreeCAD JobTimeLimit").
std::string jobLimitName(const JobBudget& budget);
std::string jobLimitSettings();

// "the job time limit of 120 s (--job-time-limit, Python job_seconds, FreeCAD JobTimeLimit)".
std::string jobLimitText(const JobBudget& budget);

// Before a stage that makes the first mesh: with the budget spent there is no mesh to keep, so
// this throws BudgetExceeded naming the stage it did not reach and where the time went.
void checkBudgetLeft(const JobBudget& budget, const std::string& stage,
                     const StageTimings& timings);

}  // namespace homesh

// A job's wall-time budget (issue 15: every stage bounded). The clock starts when the budget is
// made; each stage with a limit of its own runs under the smaller of that limit and what is left
// of the budget, stages that are optional (the optimiser, repair rounds, the geometry check) are
// skipped once it is spent, and the budget remembers what it stopped or skipped, for the report.
#pragma once

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

namespace homesh {

class JobBudget {
 public:
  // `seconds` > 0: the budget; 0: none (every stage keeps its own limit, nothing is skipped).
  // Throws ParameterError naming the job time limit when `seconds` is negative or not finite.
  explicit JobBudget(double seconds = 0.0);

  bool limited() const { return seconds_ > 0.0; }
  double seconds() const { return seconds_; }
  double elapsed() const;
  // Seconds left: infinity without a budget; 0 or less once the budget's time is over.
  double left() const;

  // Seconds kept back for the stages that run whatever is left (the quality check and the
  // output after an optimiser run), so that the job still ends within its budget. 0 until set;
  // negative values count as 0.
  void reserve(double seconds) { reserve_ = std::max(seconds, 0.0); }
  double reserved() const { return reserve_; }
  // What optional stages may use: left() less the reserve (infinity without a budget).
  double available() const { return left() - reserve_; }
  // Nothing available: the optional stages (the optimiser, repair rounds, the geometry check)
  // are left out.
  bool spent() const { return limited() && available() <= 0.0; }

  // Whether what is available is less than `own` (a stage's own limit; 0: none): the budget,
  // not the stage's limit, then decides when the stage stops.
  bool binds(double own) const;
  // The limit a stage whose own limit is `own` (0: none) runs under: `own`, or what is
  // available when binds(own), at least kFloorSeconds (a limit of 0 would mean none); 0 when
  // neither limits.
  double stageLimit(double own) const;
  static constexpr double kFloorSeconds = 1e-3;

  // What the budget changed, in stage names ("optimise", "repair 2"), in order.
  void cut(const std::string& stage) { cut_.push_back(stage); }       // stopped early
  void skip(const std::string& stage) { skipped_.push_back(stage); }  // not run at all
  const std::vector<std::string>& cutStages() const { return cut_; }
  const std::vector<std::string>& skippedStages() const { return skipped_; }

 private:
  double seconds_;
  double reserve_ = 0.0;
  std::chrono::steady_clock::time_point start_;
  std::vector<std::string> cut_, skipped_;
};

}  // namespace homesh

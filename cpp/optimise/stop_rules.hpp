// When the optimiser stops and which state it keeps (OptimiserOptions lists the rules; the
// result's stopReason names the one that ended a run). Every rule is a pure function of the
// sweeps' records and the options, so each can be made to fire alone (tests/cpp/optimise/
// test_stop_rules.cpp):
//  - before a sweep: a cancel request ("cancelled") and the time limit ("time budget", which is
//    also how a pipeline's job budget stops a run: its stage limit is the run's timeLimit);
//  - after a sweep, in this order: "displacement", "energy", "stalled", "stuck" (stopRule);
//  - the loop's own ends: maxIterations sweeps ("iterations"), no free node ("no free nodes").
// acceptable() and better() decide which state is kept: never worse than the input.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "optimise/optimiser.hpp"

namespace homesh::optimiser {

// The names of the rules, as OptimiserResult::stopReason gives them.
namespace stop {
inline const std::string kDisplacement = "displacement";
inline const std::string kEnergy = "energy";
inline const std::string kStalled = "stalled";
inline const std::string kStuck = "stuck";
inline const std::string kIterations = "iterations";
inline const std::string kTimeBudget = "time budget";
inline const std::string kCancelled = "cancelled";
inline const std::string kNoFreeNodes = "no free nodes";
}  // namespace stop

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The run's time limit (OptimiserOptions::timeLimit; 0: none), from the run's start.
class TimeBudget {
 public:
  TimeBudget() = default;  // no limit
  TimeBudget(double limit, Clock::time_point start) : limit_(limit), start_(start) {}
  // Whether the run has taken the limit (never, without one); once true, stays true.
  bool overBudget() {
    if (limit_ > 0.0 && since(start_) >= limit_) spent_ = true;
    return spent_;
  }
  // What the last overBudget() found (read after the threads that asked it joined).
  bool spent() const { return spent_; }
  bool limited() const { return limit_ > 0.0; }

 private:
  double limit_ = 0.0;
  Clock::time_point start_;
  bool spent_ = false;
};

// The energy's relative fall over the last sweep: (previous - r) / |r| (against 1e-300 for 0).
double energyFall(const IterationRecord& r, const IterationRecord& previous);

// Each rule after a sweep whose record is `r`, the last entry of `history` (the sweeps so far);
// `previous` is the state before it, `input` the state before the first sweep.
// "displacement": no node moved by more than `tolerance` times its element size.
bool displacementRule(const IterationRecord& r, const OptimiserOptions& options);
// "energy": proven valid, and the energy fell by less than energyTolerance of it (with
// stall > 0: and the worst rose by less than `stall`).
bool energyRule(const IterationRecord& r, const IterationRecord& previous,
                const OptimiserOptions& options);
// "stalled" (stall > 0): proven valid, the energy fell by less than stallEnergy, and the worst
// rose by less than `stall` above its lowest in the state before the last stallWindow sweeps
// and those sweeps.
bool stalledRule(const std::vector<IterationRecord>& history, const IterationRecord& previous,
                 const IterationRecord& input, const OptimiserOptions& options);
// "stuck" (stall > 0): not proven valid, the energy fell by less than stallEnergy, and over the
// last stuckWindow sweeps the count of elements not proven valid did not fall and the worst
// rose by less than `stall`.
bool stuckRule(const std::vector<IterationRecord>& history, const IterationRecord& previous,
               const OptimiserOptions& options);

// The first of the rules above that holds after the sweep history.back() (OptimiserOptions),
// or "".
std::string stopRule(const std::vector<IterationRecord>& history, const IterationRecord& previous,
                     const IterationRecord& input, const OptimiserOptions& options);

// Whether a rule's stop counts as converged (OptimiserResult::converged): all but "stuck".
inline bool converges(const std::string& reason) {
  return reason != stop::kStuck;
}

// No worse than the input in worst value and in invalid count.
bool acceptable(const IterationRecord& r, const IterationRecord& input);

// Fewer elements not proven valid first, then the better worst value, then, with the worst
// value unchanged to the last bit (the worst element's nodes did not move: fixed, or not
// reached before the time limit), the lower energy: the rest of the mesh improved. Two such
// records have the facet term alike: it joins the total energy at the first proven-valid record,
// and every record before it has elements not proven valid.
bool better(const IterationRecord& r, const IterationRecord& than);

}  // namespace homesh::optimiser

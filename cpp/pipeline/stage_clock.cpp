#include "pipeline/stage_clock.hpp"

#include "core/error.hpp"

namespace homesh {

StageClock::StageClock(const std::string& stage, StageTimings& timings, PipelineObserver* observer)
    : stage_(stage), timings_(timings), observer_(observer) {
  if (observer_ != nullptr) {
    if (observer_->cancelRequested()) throw CancelledError("cancelled before " + stage);
    observer_->stageStarted(stage);
  }
  start_ = std::chrono::steady_clock::now();
}

void StageClock::done() {
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  timings_.add(stage_, s);
  if (observer_ != nullptr) {
    observer_->stageFinished(stage_, s);
    if (observer_->cancelRequested()) throw CancelledError("cancelled after " + stage_);
  }
}

}  // namespace homesh

// The timing of one pipeline stage: started when made, recorded (StageTimings) and reported
// (PipelineObserver) by done(), with the observer's cancel request honoured at both ends.
#pragma once

#include <chrono>
#include <string>

#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

class StageClock {
 public:
  // Throws CancelledError when the observer asks to stop before the stage.
  StageClock(const std::string& stage, StageTimings& timings, PipelineObserver* observer);
  // Records the stage's seconds; throws CancelledError when the observer asks to stop after it.
  void done();

 private:
  std::string stage_;
  StageTimings& timings_;
  PipelineObserver* observer_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace homesh

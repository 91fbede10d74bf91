// TeamBarrier: every thread's writes before a phase's barrier are seen by all after it, the
// completion runs once per phase before anyone leaves, and a team larger than the machine's
// cores (threads that must sleep, not spin, to let the others run) still gets through. Also
// built under ThreadSanitizer (tests/cpp/CMakeLists.txt), which checks the release / acquire
// publication itself rather than what x86's ordering happens to give.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/team_barrier.hpp"

namespace homesh {
namespace {

// Each phase, thread t writes slot[t] = phase; after the barrier it reads every slot, which
// must hold that phase, and the value the completion wrote for it.
void runPhases(int threads, int phases, std::chrono::nanoseconds spin) {
  TeamBarrier barrier(threads, spin);
  std::vector<int> slot(static_cast<std::size_t>(threads), -1);
  int completed = 0;  // written by the completion only
  std::vector<int> wrong(static_cast<std::size_t>(threads), 0);
  std::vector<std::thread> team;
  team.reserve(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t)
    team.emplace_back([&, t] {
      for (int phase = 0; phase < phases; ++phase) {
        slot[static_cast<std::size_t>(t)] = phase;
        barrier.arriveAndWait([&] { ++completed; });
        for (int u = 0; u < threads; ++u)
          if (slot[static_cast<std::size_t>(u)] != phase) ++wrong[static_cast<std::size_t>(t)];
        if (completed != phase + 1) ++wrong[static_cast<std::size_t>(t)];
        // A second barrier before the slots are written again: the reads above are done.
        barrier.arriveAndWait();
      }
    });
  for (std::thread& th : team) th.join();
  for (int t = 0; t < threads; ++t) EXPECT_EQ(wrong[static_cast<std::size_t>(t)], 0) << t;
  EXPECT_EQ(completed, phases);
}

TEST(TeamBarrier, EveryThreadSeesThePhasesWritesAndTheCompletion) {
  runPhases(2, 2000, std::chrono::microseconds(50));
  runPhases(3, 500, std::chrono::microseconds(50));
}

// No spin at all: every waiting thread goes to sleep, so each phase exercises the wake-up.
TEST(TeamBarrier, SleepingThreadsAreWokenEveryPhase) {
  runPhases(2, 500, std::chrono::nanoseconds(0));
  runPhases(4, 200, std::chrono::nanoseconds(0));
}

// More threads than this machine has cores: the waiting ones must give their cores up.
TEST(TeamBarrier, ATeamLargerThanTheMachineGetsThrough) {
  const auto cores = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  runPhases(2 * cores + 1, 100, std::chrono::microseconds(50));
}

TEST(TeamBarrier, OneThreadNeverWaitsAndAnEmptyTeamIsRefused) {
  TeamBarrier one(1);
  int completed = 0;
  for (int i = 0; i < 3; ++i) one.arriveAndWait([&] { ++completed; });
  EXPECT_EQ(completed, 3);
  EXPECT_THROW(TeamBarrier(0), std::invalid_argument);
}

}  // namespace
}  // namespace homesh

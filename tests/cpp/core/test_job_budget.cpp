// A job's time budget: what a stage runs under, and what it says once spent. Only coarse
// timing: a budget of 1000 s is far from spent within a test, one of 1 ns is spent at once.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/job_budget.hpp"

namespace homesh {
namespace {

TEST(JobBudget, WithoutABudgetEveryStageKeepsItsOwnLimit) {
  const JobBudget none;
  EXPECT_FALSE(none.limited());
  EXPECT_FALSE(none.spent());
  EXPECT_TRUE(std::isinf(none.left()));
  for (const double own : {0.0, 1e-3, 600.0}) {
    EXPECT_FALSE(none.binds(own)) << own;
    EXPECT_EQ(none.stageLimit(own), own) << own;
  }
}

TEST(JobBudget, AStageGetsTheSmallerOfItsLimitAndWhatIsLeft) {
  const JobBudget budget(1000.0);
  EXPECT_TRUE(budget.limited());
  EXPECT_FALSE(budget.spent());
  EXPECT_GT(budget.left(), 900.0);  // (a test does not take 100 s before this line)
  EXPECT_LE(budget.left(), 1000.0);
  // A stage limit below what is left stays; above, or none (0), becomes what is left.
  EXPECT_FALSE(budget.binds(600.0));
  EXPECT_EQ(budget.stageLimit(600.0), 600.0);
  for (const double own : {0.0, 5000.0}) {
    EXPECT_TRUE(budget.binds(own)) << own;
    const double limit = budget.stageLimit(own);
    EXPECT_GT(limit, 900.0) << own;
    EXPECT_LE(limit, 1000.0) << own;
  }
}

// The reserve (for the quality check and output that follow a stage) comes off what a stage
// the budget stops may take and off what the optional stages may use; what is left stays.
TEST(JobBudget, TheReserveComesOffWhatAStageMayTake) {
  JobBudget budget(1000.0);
  EXPECT_EQ(budget.reserved(), 0.0);
  budget.reserve(300.0);
  EXPECT_EQ(budget.reserved(), 300.0);
  EXPECT_GT(budget.left(), 900.0);
  EXPECT_FALSE(budget.spent());
  EXPECT_FALSE(budget.binds(600.0));  // 600 s fits in 1000 - 300
  EXPECT_EQ(budget.stageLimit(600.0), 600.0);
  EXPECT_TRUE(budget.binds(800.0));  // 800 s does not
  const double limit = budget.stageLimit(800.0);
  EXPECT_GT(limit, 600.0);
  EXPECT_LE(limit, 700.0);
  EXPECT_GT(budget.available(), 600.0);
  EXPECT_LE(budget.available(), 700.0);
  // More than the budget: nothing is available, so the optional stages are left out (spent),
  // and a stage that runs anyway gets the floor, never 0 (no limit).
  budget.reserve(5000.0);
  EXPECT_TRUE(budget.spent());
  EXPECT_GT(budget.left(), 900.0);
  EXPECT_EQ(budget.stageLimit(0.0), JobBudget::kFloorSeconds);
  budget.reserve(-1.0);
  EXPECT_EQ(budget.reserved(), 0.0);
}

TEST(JobBudget, ASpentBudgetGivesTheFloorNeverZero) {
  const JobBudget budget(1e-9);
  while (budget.left() > 0.0) {
  }
  EXPECT_TRUE(budget.spent());
  EXPECT_LE(budget.left(), 0.0);
  EXPECT_GE(budget.elapsed(), 1e-9);
  // 0 would mean "no limit" to the optimiser and the isolated call: the floor stands in.
  EXPECT_EQ(budget.stageLimit(0.0), JobBudget::kFloorSeconds);
  EXPECT_EQ(budget.stageLimit(600.0), JobBudget::kFloorSeconds);
}

TEST(JobBudget, RemembersWhatItCutAndSkippedInOrder) {
  JobBudget budget(10.0);
  budget.cut("optimise");
  budget.skip("repair 1");
  budget.skip("geometry");
  EXPECT_EQ(budget.cutStages(), std::vector<std::string>{"optimise"});
  EXPECT_EQ(budget.skippedStages(), (std::vector<std::string>{"repair 1", "geometry"}));
}

TEST(JobBudget, RefusesNegativeAndNonFiniteBudgets) {
  for (const double bad : {-1.0, -1e-300, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(JobBudget{bad}, ParameterError) << bad;
  }
  EXPECT_NO_THROW(JobBudget{0.0});
}

}  // namespace
}  // namespace homesh

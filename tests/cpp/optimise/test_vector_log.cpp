// vectorLog (optimise/vector_log.hpp), the optimiser's branch-free ln, against std::log over the
// whole range of positive doubles. Each is within about one unit in the last place (ulp) of ln x
// (glibc documents at most 1 ulp for log; vectorLog's remainders lie below the last place, so
// its own error is the final additions' rounding): they may differ by 2 ulp of ln x at most.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "optimise/vector_log.hpp"

namespace homesh {
namespace {

// |vectorLog(x) - std::log(x)| in ulps of std::log(x) (0 where both are 0).
double ulpsOff(double x) {
  const double a = vectorLog(x), b = std::log(x);
  if (a == b) return 0.0;
  const double magnitude = std::abs(b);
  const double ulp = std::nextafter(magnitude, std::numeric_limits<double>::infinity()) - magnitude;
  return std::abs(a - b) / ulp;
}

TEST(VectorLog, WithinTwoUlpsOfStdLogFromTheSmallestSubnormalToTheLargestDouble) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> exponent(-1074.0, 1023.99);
  std::uniform_real_distribution<double> nearOne(-1e-6, 1e-6);
  std::uniform_real_distribution<double> octave(0.5, 2.0);
  double worst = 0.0;
  for (int i = 0; i < 300000; ++i) {
    worst = std::max(worst, ulpsOff(std::exp2(exponent(random))));
    worst = std::max(worst, ulpsOff(1.0 + nearOne(random)));  // ln x ~ x - 1: relative accuracy
    worst = std::max(worst, ulpsOff(octave(random)));         // both sides of sqrt(2), sqrt(1/2)
  }
  for (const double x :
       {std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::min(),
        std::numeric_limits<double>::max(), std::nextafter(1.0, 0.0), std::nextafter(1.0, 2.0),
        std::sqrt(2.0), std::sqrt(0.5), 1e-10, 1e10})
    worst = std::max(worst, ulpsOff(x));
  EXPECT_LE(worst, 2.0);
}

TEST(VectorLog, ExactWhereLnIsAndInfiniteAtInfinity) {
  EXPECT_EQ(vectorLog(1.0), 0.0);
  EXPECT_EQ(vectorLog(std::numeric_limits<double>::infinity()),
            std::numeric_limits<double>::infinity());
  // ln 2^k = k ln 2: the first part of ln 2 times k is exact, the second rounds once.
  for (int k = -1074; k <= 1023; k += 7) EXPECT_LE(ulpsOff(std::ldexp(1.0, k)), 1.0) << "2^" << k;
}

}  // namespace
}  // namespace homesh

#include "optimise/work_partition.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>

namespace homesh {
namespace {

std::vector<std::array<double, 3>> randomPoints(std::size_t n, std::array<double, 3> extent,
                                                unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::array<double, 3>> p(n);
  for (auto& x : p)
    for (int c = 0; c < 3; ++c) x[c] = extent[c] * unit(rng);
  return p;
}

TEST(WorkPartition, BisectionBalancesTheWeights) {
  const auto points = randomPoints(1000, {4.0, 1.0, 2.0}, 1);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> w(1.0, 3.0);
  std::vector<double> weights(points.size());
  for (double& x : weights) x = w(rng);
  double total = 0.0;
  for (const double x : weights) total += x;
  for (int parts = 1; parts <= 7; ++parts) {
    const std::vector<int> part = bisectByCoordinates(points, weights, parts);
    std::vector<double> sum(static_cast<std::size_t>(parts), 0.0);
    for (std::size_t i = 0; i < part.size(); ++i) {
      ASSERT_GE(part[i], 0);
      ASSERT_LT(part[i], parts);
      sum[static_cast<std::size_t>(part[i])] += weights[i];
    }
    // Each cut misses its share by at most half the largest weight (1.5), and a part lies under
    // ceil(log2(parts)) cuts, each of whose errors the deeper cuts scale by at most 1 (they
    // share a set's error among its parts); 1e-9 covers the rounding of sums of 1000 weights.
    // (Cutting by count instead of weight misses by 4 to 12 here.)
    const double levels = std::ceil(std::log2(parts));
    for (const double s : sum) EXPECT_NEAR(s, total / parts, 1.5 * levels + 1e-9) << parts;
  }
}

TEST(WorkPartition, TwoPartsAreCutAcrossTheLongestExtent) {
  const auto points = randomPoints(500, {1.0, 1.0, 10.0}, 3);
  const std::vector<double> weights(points.size(), 1.0);
  const std::vector<int> part = bisectByCoordinates(points, weights, 2);
  double maxLow = -1.0, minHigh = 11.0;
  std::size_t low = 0;
  for (std::size_t i = 0; i < part.size(); ++i) {
    if (part[i] == 0) {
      maxLow = std::max(maxLow, points[i][2]);
      ++low;
    } else {
      minHigh = std::min(minHigh, points[i][2]);
    }
  }
  EXPECT_LE(maxLow, minHigh);  // the two halves are separated by a plane z = const
  EXPECT_EQ(low, 250U);
  EXPECT_EQ(part, bisectByCoordinates(points, weights, 2));  // deterministic
}

TEST(WorkPartition, WeightlessPointsDoNotUnbalanceTheParts) {
  auto points = randomPoints(400, {1.0, 1.0, 1.0}, 4);
  std::vector<double> weights(points.size(), 0.0);
  for (std::size_t i = 0; i < 100; ++i) weights[i] = 1.0;  // a quarter of them do any work
  const std::vector<int> part = bisectByCoordinates(points, weights, 4);
  std::vector<double> sum(4, 0.0);
  for (std::size_t i = 0; i < part.size(); ++i)
    sum[static_cast<std::size_t>(part[i])] += weights[i];
  for (const double s : sum) EXPECT_NEAR(s, 25.0, 2.0);
}

TEST(WorkPartition, BadArgumentsAreRefused) {
  EXPECT_THROW(bisectByCoordinates({}, {}, 0), std::invalid_argument);
  EXPECT_THROW(bisectByCoordinates({{0.0, 0.0, 0.0}}, {}, 2), std::invalid_argument);
  EXPECT_THROW(OwnerFirstQueue({0}, 4), std::invalid_argument);
}

TEST(WorkPartition, ANodeBelongsToThePartOfMostOfItsElements) {
  const std::vector<std::vector<int>> parts = {{1, 1, 0}, {0, 1}, {2}, {}};
  const std::vector<int> owner = nodeOwners(parts.size(), 3, [&](std::size_t n, auto add) {
    for (const int p : parts[n]) add(p);
  });
  EXPECT_EQ(owner, (std::vector<int>{1, 0, 2, 0}));  // a tie goes to the lowest part
}

TEST(WorkPartition, GroupingByPartIsStable) {
  const std::vector<int> items = {5, 2, 8, 1, 4, 7};
  std::vector<std::size_t> begin;
  const std::vector<int> grouped = groupByPart(
      items, 3, [](int x) { return x % 3; }, begin);
  EXPECT_EQ(grouped, (std::vector<int>{1, 4, 7, 5, 2, 8}));
  EXPECT_EQ(begin, (std::vector<std::size_t>{0, 0, 3, 6}));
}

TEST(WorkPartition, AThreadTakesItsOwnChunksFirstThenHelpsFromTheBack) {
  OwnerFirstQueue queue({0, 100, 130}, 4);
  std::size_t lo = 0, hi = 0;
  ASSERT_TRUE(queue.next(0, lo, hi));  // part 0's thread starts its own, from the front
  EXPECT_EQ(lo, 0U);
  EXPECT_EQ(hi, 4U);  // a full chunk while more than 8 chunks are left
  std::vector<std::pair<std::size_t, std::size_t>> taken;
  while (queue.next(1, lo, hi)) taken.emplace_back(lo, hi);  // part 1's, then helps part 0
  // Part 1's items from the front, then part 0's from the back, every chunk of 1 to 4 items,
  // an eighth of what is left near the end: the last ones single items.
  std::size_t expectOwn = 100, expectHelp = 100, k = 0;
  for (; k < taken.size() && taken[k].first >= 100; ++k) {
    EXPECT_EQ(taken[k].first, expectOwn) << k;
    expectOwn = taken[k].second;
  }
  EXPECT_EQ(expectOwn, 130U);
  for (; k < taken.size(); ++k) {
    EXPECT_EQ(taken[k].second, expectHelp) << k;
    expectHelp = taken[k].first;
  }
  EXPECT_EQ(expectHelp, 4U);
  for (const auto& [a, b] : taken) {
    EXPECT_GE(b - a, 1U);
    EXPECT_LE(b - a, 4U);
  }
  EXPECT_EQ(taken.back().second - taken.back().first, 1U);
  EXPECT_FALSE(queue.next(0, lo, hi));
}

TEST(WorkPartition, EveryItemIsHandedOutOnceAcrossThreads) {
  // Uneven parts (one empty, one holding nearly everything): the others must help.
  const std::vector<std::size_t> begin = {0, 0, 5000, 5003, 5400};
  OwnerFirstQueue queue(begin, 7);
  std::vector<std::atomic<int>> count(begin.back());
  for (auto& c : count) c.store(0);
#pragma omp parallel num_threads(2)  // parts 2 and 3 have no thread of their own
  {
    std::size_t lo = 0, hi = 0;
    while (queue.next(omp_get_thread_num(), lo, hi))
      for (std::size_t i = lo; i < hi; ++i) count[i].fetch_add(1);
  }
  for (std::size_t i = 0; i < count.size(); ++i) ASSERT_EQ(count[i].load(), 1) << i;
}

}  // namespace
}  // namespace homesh

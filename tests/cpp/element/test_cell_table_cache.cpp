#include "element/cell_table_cache.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

namespace homesh {
namespace {

struct Table {
  CellType type;
  int order;
};

TEST(CellTableCache, BuildsEachTableOnceForAllThreads) {
  CellTableCache<Table, 2> cache;
  std::atomic<int> builds{0};
  const auto get = [&](CellType type, int order, int variant) -> const Table& {
    return cache.get(
        type, order,
        [&] {
          ++builds;
          return std::make_unique<Table>(Table{type, order});
        },
        variant);
  };
  // Eight threads ask for the same four tables many times at once, and read each table as they
  // get it: a table published without release / acquire would be a data race that
  // ThreadSanitizer reports (CellTableCache.UnderThreadSanitizer runs this test so built), though
  // x86 itself would not show it.
  std::vector<std::vector<const Table*>> seen(8);
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  threads.reserve(seen.size());
  for (std::vector<const Table*>& mine : seen)
    threads.emplace_back([&get, &wrong, target = &mine] {
      for (int i = 0; i < 2000; ++i)
        for (const int order : {1, kMaxOrder})
          for (const int variant : {0, 1}) {
            const Table& table = get(CellType::Prism, order, variant);
            if (table.type != CellType::Prism || table.order != order) ++wrong;
            target->push_back(&table);
          }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_EQ(builds.load(), 4);
  for (const auto& s : seen) {
    ASSERT_EQ(s.size(), seen[0].size());
    for (std::size_t i = 0; i < s.size(); ++i) EXPECT_EQ(s[i], seen[0][i]);
  }
  EXPECT_EQ(seen[0][0]->order, 1);
  EXPECT_EQ(seen[0][2]->order, kMaxOrder);
  EXPECT_NE(seen[0][0], seen[0][1]);  // the variants are separate tables
  // Keys outside the direct slots (order 12, variant 5) are kept too.
  const Table& far = get(CellType::Hexahedron, 12, 0);
  EXPECT_EQ(&get(CellType::Hexahedron, 12, 0), &far);
  EXPECT_EQ(&get(CellType::Hexahedron, 2, 5), &get(CellType::Hexahedron, 2, 5));
  EXPECT_EQ(builds.load(), 6);
}

TEST(CellTableCache, AFailedBuildKeepsNothing) {
  CellTableCache<Table> cache;
  int calls = 0;
  const auto failing = [&]() -> std::unique_ptr<Table> {
    ++calls;
    throw std::runtime_error("no table");
  };
  EXPECT_THROW(cache.get(CellType::Tetrahedron, 3, failing), std::runtime_error);
  EXPECT_THROW(cache.get(CellType::Tetrahedron, -1, failing), std::runtime_error);
  const Table& t = cache.get(CellType::Tetrahedron, 3, [&] {
    ++calls;
    return std::make_unique<Table>(Table{CellType::Tetrahedron, 3});
  });
  EXPECT_EQ(t.order, 3);
  EXPECT_EQ(calls, 3);
}

}  // namespace
}  // namespace homesh

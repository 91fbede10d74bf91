#include "optimise/work_partition.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace homesh {
namespace {

struct Bisection {
  const std::vector<std::array<double, 3>>& points;
  const std::vector<double>& weights;
  std::vector<std::size_t> order;  // the points, reordered so that each set is a range
  std::vector<int> part;

  void split(std::size_t lo, std::size_t hi, int first, int parts) {
    if (parts == 1 || hi - lo == 0) {
      for (std::size_t i = lo; i < hi; ++i) part[order[i]] = first;
      return;
    }
    std::array<double, 3> low, high;
    low.fill(std::numeric_limits<double>::infinity());
    high.fill(-std::numeric_limits<double>::infinity());
    double total = 0.0;
    for (std::size_t i = lo; i < hi; ++i) {
      for (int c = 0; c < 3; ++c) {
        low[c] = std::min(low[c], points[order[i]][c]);
        high[c] = std::max(high[c], points[order[i]][c]);
      }
      total += weights[order[i]];
    }
    int axis = 0;
    for (int c = 1; c < 3; ++c)
      if (high[c] - low[c] > high[axis] - low[axis]) axis = c;
    const auto begin = order.begin() + static_cast<std::ptrdiff_t>(lo);
    const auto end = order.begin() + static_cast<std::ptrdiff_t>(hi);
    std::sort(begin, end, [&](std::size_t a, std::size_t b) {
      const double pa = points[a][axis], pb = points[b][axis];
      return pa < pb || (pa == pb && a < b);
    });
    // The cut: the points whose weight's midpoint falls below the left parts' share go left.
    const int left = parts / 2;
    const double target = total * left / parts;
    std::size_t cut = lo;
    double sum = 0.0;
    while (cut < hi && sum + 0.5 * weights[order[cut]] < target) sum += weights[order[cut++]];
    split(lo, cut, first, left);
    split(cut, hi, first + left, parts - left);
  }
};

}  // namespace

std::vector<int> bisectByCoordinates(const std::vector<std::array<double, 3>>& points,
                                     const std::vector<double>& weights, int parts) {
  if (parts < 1)
    throw std::invalid_argument("parts must be at least 1, got " + std::to_string(parts));
  if (weights.size() != points.size())
    throw std::invalid_argument("bisectByCoordinates: " + std::to_string(points.size()) +
                                " points but " + std::to_string(weights.size()) + " weights");
  Bisection b{points, weights, std::vector<std::size_t>(points.size()),
              std::vector<int>(points.size(), 0)};
  std::iota(b.order.begin(), b.order.end(), std::size_t{0});
  b.split(0, points.size(), 0, parts);
  return b.part;
}

OwnerFirstQueue::OwnerFirstQueue(std::vector<std::size_t> begin, std::size_t chunk)
    : begin_(std::move(begin)),
      chunk_(std::max<std::size_t>(chunk, 1)),
      cursors_(std::make_unique<Cursor[]>(begin_.size() < 2 ? 0 : begin_.size() - 1)) {
  if (begin_.size() < 2) throw std::invalid_argument("OwnerFirstQueue needs at least one part");
  for (std::size_t p = 0; p + 1 < begin_.size(); ++p) {
    const std::size_t size = begin_[p + 1] - begin_[p];
    if (size > std::numeric_limits<std::uint32_t>::max())
      throw std::invalid_argument("OwnerFirstQueue: part " + std::to_string(p) + " holds " +
                                  std::to_string(size) + " items, more than 2^32 - 1");
    cursors_[p].range.store(size, std::memory_order_relaxed);  // front 0, back size
  }
}

bool OwnerFirstQueue::take(std::size_t part, bool front, std::size_t& lo, std::size_t& hi) {
  std::atomic<std::uint64_t>& range = cursors_[part].range;
  std::uint64_t current = range.load(std::memory_order_relaxed);
  for (;;) {
    const std::uint64_t a = current >> 32, b = current & 0xffffffffU;
    if (a >= b) return false;  // a done part is only read
    // An eighth of what is left, at most a chunk: small chunks at the end, so that the threads
    // reach the barrier after a part's items within about one item of each other.
    const std::uint64_t n = std::clamp<std::uint64_t>((b - a) / 8, 1, chunk_);
    const std::uint64_t next = front ? ((a + n) << 32 | b) : (a << 32 | (b - n));
    if (range.compare_exchange_weak(current, next, std::memory_order_relaxed)) {
      lo = begin_[part] + static_cast<std::size_t>(front ? a : b - n);
      hi = lo + static_cast<std::size_t>(n);
      return true;
    }
  }
}

bool OwnerFirstQueue::next(int part, std::size_t& lo, std::size_t& hi) {
  const std::size_t parts = begin_.size() - 1;
  const auto own = static_cast<std::size_t>(part) % parts;
  for (std::size_t k = 0; k < parts; ++k)
    if (take((own + k) % parts, k == 0, lo, hi)) return true;
  return false;
}

}  // namespace homesh

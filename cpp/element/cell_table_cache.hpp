// Tables built once per cell type and order (and a small variant number, such as the node set),
// on first use, and read without a lock afterwards. The quality measures and the optimiser ask
// for them once per element from every thread; behind a mutex, each call moved the mutex's cache
// line between the CPUs, and the certified quality of an order-2 mesh got 1.46x out of two
// threads (bench/README.md).
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <vector>

#include "core/cell_type.hpp"
#include "element/reference_element.hpp"

namespace homesh {

template <class T, int kVariants = 1>
class CellTableCache {
 public:
  // The table of (type, order, variant): build() (returning std::unique_ptr<T>) makes it on the
  // first call, under a lock, and the table lives as long as the cache. Safe to call from any
  // thread; an exception from build() propagates and nothing is kept, so a later call tries
  // again. build() runs under the cache's lock: it must not ask the same cache for a table
  // (other caches are fine). Orders outside 0..kMaxOrder (which the builders refuse), variants
  // outside 0..kVariants - 1 and types after Hexahedron are looked up under the lock.
  template <class Build>
  const T& get(CellType type, int order, Build build, int variant = 0) {
    const bool direct = static_cast<std::size_t>(type) <= kLastType && order >= 0 &&
                        order <= kMaxOrder && variant >= 0 && variant < kVariants;
    std::atomic<const T*>* slot = nullptr;
    if (direct) {
      slot = &slots_[(static_cast<std::size_t>(type) * (kMaxOrder + 1) +
                      static_cast<std::size_t>(order)) *
                         kVariants +
                     static_cast<std::size_t>(variant)];
      if (const T* table = slot->load(std::memory_order_acquire)) return *table;
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    const std::tuple<int, int, int> key{static_cast<int>(type), order, variant};
    if (direct) {
      if (const T* table = slot->load(std::memory_order_relaxed)) return *table;
    } else if (const auto it = others_.find(key); it != others_.end()) {
      return *it->second;
    }
    std::unique_ptr<T> made = build();
    const T* table = made.get();
    owned_.push_back(std::move(made));
    if (direct)
      slot->store(table, std::memory_order_release);
    else
      others_.emplace(key, table);
    return *table;
  }

 private:
  static constexpr std::size_t kLastType = static_cast<std::size_t>(CellType::Hexahedron);
  static constexpr std::size_t kSlots = (kLastType + 1) * (kMaxOrder + 1) * kVariants;
  std::atomic<const T*> slots_[kSlots] = {};
  std::mutex mutex_;
  std::vector<std::unique_ptr<T>> owned_;
  std::map<std::tuple<int, int, int>, const T*> others_;
};

}  // namespace homesh

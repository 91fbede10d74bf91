// A barrier for a fixed team of threads that spins only briefly and then sleeps.
//
// Why not OpenMP's own: libgomp's barrier waits by spinning (300,000 pause instructions, 6 ms on
// the development machine's EPYC, before it sleeps). On a machine whose cores are also busy with
// other work (a second job, FreeCAD's own threads), a thread spinning at a barrier holds a core
// that the thread it waits for needs: the optimiser's colour groups, a barrier each, then ran
// slower on two threads than on one (3d_bl_cyl at order 4 beside two other processes on the
// 2-core machine: 18.6 s against 5.7 s; bench/README.md, "A busy machine"). The spin here is
// bounded in time, long enough to cover the usual gap between threads finishing a balanced step,
// and then the thread sleeps on a condition variable until the last one arrives.
//
// Memory: everything a thread wrote before arriveAndWait() is visible to every thread after it
// returns (the counter and the phase are acquire/release), as with an OpenMP barrier.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <stdexcept>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace homesh {

class TeamBarrier {
 public:
  // `threads`: how many call arriveAndWait() each phase (>= 1). `spin`: how long a waiting thread
  // spins before it sleeps.
  explicit TeamBarrier(int threads, std::chrono::nanoseconds spin = std::chrono::microseconds(50))
      : spin_(spin), threads_(threads) {
    if (threads < 1) throw std::invalid_argument("TeamBarrier: a team needs at least 1 thread");
  }
  TeamBarrier(const TeamBarrier&) = delete;
  TeamBarrier& operator=(const TeamBarrier&) = delete;

  int threads() const { return threads_; }

  // Waits until all `threads` have arrived. The last to arrive runs `completion()` first, before
  // any thread is released: what it writes is seen by all of them (a shared flag such as "stop
  // now", decided once for the team). `completion` must not throw.
  template <class Completion>
  void arriveAndWait(Completion completion) {
    const unsigned phase = phase_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == threads_) {
      completion();
      arrived_.store(0, std::memory_order_relaxed);
      phase_.store(phase + 1, std::memory_order_seq_cst);  // releases the phase's writes
      // A thread that decided to sleep counted itself first, under the lock: it is either
      // seen here or saw the new phase before waiting (both sides are sequentially consistent).
      if (sleepers_.load(std::memory_order_seq_cst) > 0) {
        const std::lock_guard<std::mutex> lock(mutex_);
        wake_.notify_all();
      }
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    for (unsigned n = 1;; ++n) {
      if (phase_.load(std::memory_order_acquire) != phase) return;
      pause();
      if (n % 64 == 0 && std::chrono::steady_clock::now() - start > spin_) break;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    sleepers_.fetch_add(1, std::memory_order_seq_cst);
    wake_.wait(lock, [&] { return phase_.load(std::memory_order_seq_cst) != phase; });
    sleepers_.fetch_sub(1, std::memory_order_relaxed);
  }

  void arriveAndWait() {
    arriveAndWait([] {});
  }

 private:
  static void pause() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#endif
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  const std::chrono::nanoseconds spin_;
  const int threads_;
  std::atomic<int> arrived_{0};
  std::atomic<unsigned> phase_{0};
  std::atomic<int> sleepers_{0};
};

}  // namespace homesh

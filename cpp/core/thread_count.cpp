#include "core/thread_count.hpp"

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

namespace homesh {

namespace {

// OMP_NUM_THREADS as a positive count (its first entry: a list gives nested levels); 0 where it
// is unset or not one.
int ompNumThreads() {
  const char* text = std::getenv("OMP_NUM_THREADS");
  if (text == nullptr) return 0;
  char* end = nullptr;
  const long n = std::strtol(text, &end, 10);
  return end != text && n > 0 && n < 1 << 20 ? static_cast<int>(n) : 0;
}

// The cgroup v2 CPU quota in cores, rounded up ("max": none, 0).
int quotaCores() {
  std::ifstream file("/sys/fs/cgroup/cpu.max");
  std::string quota;
  double period = 0.0;
  if (!(file >> quota >> period) || quota == "max" || period <= 0.0) return 0;
  char* end = nullptr;
  const double q = std::strtod(quota.c_str(), &end);
  return end != quota.c_str() && q > 0.0 ? static_cast<int>(std::ceil(q / period)) : 0;
}

int affinityCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

int usableCores() {
  static const int cores = [] {
    if (const int n = ompNumThreads(); n > 0) return n;
    const int affinity = affinityCores(), quota = quotaCores();
    return quota > 0 ? std::max(1, std::min(affinity, quota)) : affinity;
  }();
  return cores;
}

int threadsToUse(int requested) {
  return requested > 0 ? requested : usableCores();
}

}  // namespace homesh

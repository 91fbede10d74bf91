// How many threads a parallel stage runs. The "threads" option (core/parameters.hpp) is a
// request: a positive count is used as it is; 0, its default, means every core this process
// may run on. Every stage that starts threads asks threadsToUse(), so the default is resolved
// the same way everywhere (the command line, Python, FreeCAD and the library's own defaults).
#pragma once

namespace homesh {

// The cores this process may run on: OMP_NUM_THREADS where it is set to a positive count (the
// usual way to bound an OpenMP program); else its CPU affinity (what `taskset`, a batch
// scheduler or a container's cpuset allows), capped by a CPU quota (cgroup v2 cpu.max, as
// `docker --cpus` and Kubernetes limits set it), rounded up; at least 1.
int usableCores();

// `requested` when positive, else usableCores().
int threadsToUse(int requested);

}  // namespace homesh

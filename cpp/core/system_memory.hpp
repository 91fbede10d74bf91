// What the machine can give: memory available now, and this process's own use. Linux (/proc).
#pragma once

#include <cstddef>

namespace homesh {

// MemAvailable: what can still be allocated without swapping (the kernel's estimate); 0 when
// it cannot be read.
std::size_t availableMemoryBytes();

// This process's virtual address space (what RLIMIT_AS counts).
std::size_t addressSpaceBytes();

}  // namespace homesh

// One libFuzzer entry point per reader: the input bytes go to a scratch file with the reader's
// extension (the readers take paths, as the CLI and FreeCAD give them), and the reader runs.
// Any homesh::Error is the expected answer to bad bytes; anything else escaping (another
// exception type, a crash, a sanitizer report, a leak) is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/error.hpp"

namespace homesh::fuzz {

// A file of this process's own, rewritten for every input.
inline const std::string& scratchFile(const char* extension) {
  static const std::string path =
      "/tmp/homesh-fuzz-" + std::to_string(getpid()) + "-input" + extension;
  return path;
}

template <class Reader>
int readBytes(const std::uint8_t* data, std::size_t size, const char* extension, Reader&& read) {
  const std::string& path = scratchFile(extension);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return 0;
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    read(path);
  } catch (const homesh::Error&) {  // a clear error: the expected outcome
  }
  return 0;
}

}  // namespace homesh::fuzz

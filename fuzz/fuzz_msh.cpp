// Gmsh MSH 2.2 / 4.1, ASCII and binary.
#include "fuzz_target.hpp"
#include "io/msh_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".msh",
                                 [](const std::string& path) { homesh::readMsh(path); });
}

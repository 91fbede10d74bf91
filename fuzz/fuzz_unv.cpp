// I-DEAS universal files (.unv), as FreeCAD FEM writes them.
#include "fuzz_target.hpp"
#include "io/unv_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".unv",
                                 [](const std::string& path) { homesh::readUnv(path); });
}

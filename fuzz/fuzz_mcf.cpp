// NekMesh .mcf case files.
#include "fuzz_target.hpp"
#include "io/mcf_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".mcf",
                                 [](const std::string& path) { homesh::readMcfFile(path); });
}

// VTK XML unstructured grids (.vtu): ascii, base64, appended raw or base64, zlib.
#include "fuzz_target.hpp"
#include "io/vtk_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".vtu",
                                 [](const std::string& path) { homesh::readVtu(path); });
}

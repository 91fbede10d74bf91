// Legacy VTK unstructured grids (.vtk), ASCII and binary, versions 2 to 5.1.
#include "fuzz_target.hpp"
#include "io/vtk_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".vtk",
                                 [](const std::string& path) { homesh::readLegacyVtk(path); });
}

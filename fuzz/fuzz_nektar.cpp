// Nektar++ XML, plain and compressed (base64 + zlib) sections.
#include "fuzz_target.hpp"
#include "io/nektar_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".xml",
                                 [](const std::string& path) { homesh::readNektarXml(path); });
}
